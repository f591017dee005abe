//! Course generation on a mold surface: the surface (analytic or an uploaded mesh), the design
//! direction, the ply, and the outputs. Every call into `towpath-layup` and `towpath-geom` is
//! here. A surface-view request becomes the library's [`towpath_layup::request::LayupRequest`], so
//! the app gets the same checks, work limits and warnings as `towpath layup`.

use serde::{Deserialize, Serialize};
use towpath_geom::surface::{Analytic, Tessellation};
use towpath_geom::{BuildOptions, DVec3, Mesh};
use towpath_layup::input::read_curve;
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::Method;
use towpath_layup::request::{self as layup, DirectionSource, LayupError, Limits, SurfaceRequest, SurfaceSource};
use towpath_layup::section::Coverage;
use towpath_layup::units::Units;

use crate::error::ApiError;
use crate::geometry::Blob;

/// What the surface view asks for.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct LayupRequest {
    /// An analytic surface (`cylinder:r=300,l=1000`, `cone:…`, `sphere:…`, `plane:a=…,b=…`);
    /// ignored when `mesh` is given.
    pub surface: String,
    /// An uploaded mesh's name.
    pub mesh: Option<String>,
    /// Ply angle, degrees.
    pub angle: f64,
    /// Reference axis (rosette).
    pub axis: [f64; 3],
    /// Guide curves as CSV text (x,y,z per line), used instead of the axis when given.
    pub guides: Vec<String>,
    /// Tow width, mm.
    pub tow_width: f64,
    /// Tows per course.
    pub tows: usize,
    /// Coverage rule: 0, 50 or 100.
    pub coverage: u32,
    /// `field`, `parallel` or `natural`.
    pub method: String,
    /// Start point of the reference course.
    pub start: Option<[f64; 3]>,
    /// Tessellate analytic surfaces into about this many triangles.
    pub triangles: Option<usize>,
    /// Units of the surface and of every length in the request (`mm`, `in`, `m`, `ft`; default mm).
    pub units: Option<String>,
}

impl Default for LayupRequest {
    fn default() -> Self {
        LayupRequest {
            surface: "cylinder:r=300,l=1000".into(),
            mesh: None,
            angle: 45.0,
            axis: [0.0, 0.0, 1.0],
            guides: Vec::new(),
            tow_width: 6.35,
            tows: 16,
            coverage: 50,
            method: "field".into(),
            start: None,
            triangles: Some(20_000),
            units: None,
        }
    }
}

/// The outputs of a generated ply.
pub struct LayupOutcome {
    /// Courses JSON (the `towpath layup -o` document).
    pub courses_json: String,
    /// G-code in the reference dialect.
    pub gcode: String,
    /// The mesh as typed arrays (`positions`, `triangles`).
    pub mesh: Blob,
    /// Summary figures.
    pub summary: serde_json::Value,
}

/// Checks a request's numbers before any work.
pub fn validate(req: &LayupRequest) -> Result<(), ApiError> {
    if !(req.tow_width.is_finite() && req.tow_width > 0.0) {
        return Err(ApiError::bad(format!("tow_width {}: give a width in mm > 0", req.tow_width)));
    }
    if req.tows == 0 || req.tows > 64 {
        return Err(ApiError::bad(format!("tows {}: between 1 and 64", req.tows)));
    }
    if !req.angle.is_finite() {
        return Err(ApiError::bad("angle: a number of degrees"));
    }
    if Coverage::from_percent(req.coverage).is_none() {
        return Err(ApiError::bad(format!("coverage {}: 0, 50 or 100", req.coverage)));
    }
    method(&req.method)?;
    units(req)?;
    if req.triangles.is_some_and(|t| !(100..=2_000_000).contains(&t)) {
        return Err(ApiError::bad("triangles: between 100 and 2,000,000"));
    }
    Ok(())
}

fn method(m: &str) -> Result<Method, ApiError> {
    match m {
        "field" => Ok(Method::Field),
        "parallel" => Ok(Method::Parallel),
        "natural" => Ok(Method::Natural),
        _ => Err(ApiError::bad(format!("method {m:?}: field, parallel or natural"))),
    }
}

/// Reads an uploaded mesh's bytes into a mesh; errors name the file.
pub fn read_mesh(name: &str, bytes: &[u8]) -> Result<Mesh, ApiError> {
    let soup = super::read_soup(name, bytes)?;
    let (mesh, _) =
        Mesh::build(&soup, &BuildOptions::default()).map_err(|e| ApiError::in_file(name, None, e.to_string()))?;
    Ok(mesh)
}

/// The mesh as typed arrays.
pub fn mesh_blob(mesh: &Mesh) -> Blob {
    let mut b = Blob::new();
    let pos: Vec<f32> = mesh.positions().iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
    let tri: Vec<u32> = mesh.triangles().iter().flat_map(|t| *t).collect();
    b.f32("positions", &pos);
    b.u32("triangles", &tri);
    b
}

/// Generates the ply through the library's own request ([`towpath_layup::request::run`]): the
/// same checks, limits and warnings as `towpath layup`. `mesh_bytes` are the uploaded mesh's, when
/// the request names one. `progress` gets the number of courses traced so far.
pub fn generate(
    req: &LayupRequest,
    mesh_bytes: Option<&[u8]>,
    progress: &mut dyn FnMut(usize),
) -> Result<LayupOutcome, ApiError> {
    validate(req)?;
    let units = units(req)?;
    let source = match (&req.mesh, mesh_bytes) {
        (Some(name), Some(bytes)) => SurfaceSource::Soup(super::read_soup(name, bytes)?),
        _ => SurfaceSource::Analytic(
            Analytic::parse(&req.surface).map_err(|e| ApiError::bad(format!("surface {:?}: {e}", req.surface)))?,
        ),
    };
    let direction = if !req.guides.is_empty() {
        let mut curves = Vec::new();
        for (i, g) in req.guides.iter().enumerate() {
            let file = format!("guide curve {}", i + 1);
            curves.push(read_curve(g).map_err(|e| ApiError::in_file(&file, None, e.to_string()))?);
        }
        DirectionSource::Guides(curves)
    } else {
        DirectionSource::Axis(DVec3::from(req.axis))
    };
    let tessellation = match req.triangles {
        Some(n) => Tessellation::Triangles(n),
        None => Tessellation::Chord { d_l2s: 0.05 / units.mm(), l_seg: 20.0 / units.mm() },
    };
    let request = layup::LayupRequest {
        surface: SurfaceRequest { source, tessellation, weld_tolerance: None },
        units,
        angle_deg: req.angle,
        direction: direction.clone(),
        method: method(&req.method)?,
        tow_width: req.tow_width,
        tows: req.tows,
        coverage: Coverage::from_percent(req.coverage).unwrap_or(Coverage::Half),
        boundary: None,
        start: req.start.map(DVec3::from),
        min_steering_radius: None,
        limits: Limits::with_time_limit(Limits::DEFAULT_TIME_LIMIT),
    };
    let result = layup::run(request, progress).map_err(|e| refused(req, e))?;
    let meta = Meta {
        surface: req.mesh.clone().unwrap_or_else(|| req.surface.clone()),
        angle_deg: req.angle,
        direction_source: direction.describe(),
        tow_width: result.tow_width_mm,
        tows: req.tows,
        coverage_percent: req.coverage,
        method: method(&req.method)?,
        ply_number: 1,
        input_units: units,
    };
    let courses_json = output::to_json(&result.ply, &meta).to_string();
    let gcode = output::to_gcode(&result.ply, &meta, &Post::default());
    let mut summary = output::summary(&result.ply);
    if let Some(o) = summary.as_object_mut() {
        o.insert("mesh_triangles".into(), result.mesh.num_faces().into());
        o.insert("units".into(), units.name().into());
        o.insert("warnings".into(), result.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>().into());
    }
    Ok(LayupOutcome { courses_json, gcode, mesh: mesh_blob(&result.mesh), summary })
}

/// The request's units (`mm` when not given).
fn units(req: &LayupRequest) -> Result<Units, ApiError> {
    match &req.units {
        None => Ok(Units::Mm),
        Some(u) => Units::parse(u).ok_or_else(|| ApiError::bad(format!("units {u:?}: mm, in, m or ft"))),
    }
}

/// A library refusal in the request's terms; mesh problems name the uploaded file.
fn refused(req: &LayupRequest, e: LayupError) -> ApiError {
    match (&req.mesh, &e) {
        (Some(name), LayupError::Mesh(_)) => ApiError::in_file(name, None, e.to_string()),
        _ => ApiError::bad(e.to_string()),
    }
}
