//! Course generation on a mold surface: the surface (analytic or an uploaded mesh), the design
//! direction, the ply, and the outputs. Every call into `towpath-layup` and `towpath-geom` is
//! here. The library has no request type yet, so this module assembles the field, region and
//! ply spec the way `towpath layup` does.

use serde::{Deserialize, Serialize};
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{io, BuildOptions, DVec3, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::field::{DirectionField, Guides, Polyline, Rosette};
use towpath_layup::input::read_curve;
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::{self, Method, PlySpec};
use towpath_layup::section::Coverage;

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
    let format = io::Format::from_path(std::path::Path::new(name))
        .ok_or_else(|| ApiError::in_file(name, None, "a mesh must be a .stl, .obj or .ply file"))?;
    let soup = io::read_bytes(bytes, format).map_err(|e| ApiError::in_file(name, None, e.to_string()))?;
    let (mesh, _) =
        Mesh::build(&soup, &BuildOptions::default()).map_err(|e| ApiError::in_file(name, None, e.to_string()))?;
    Ok(mesh)
}

/// Builds the surface of a request: an analytic description or the uploaded mesh's bytes.
pub fn surface_mesh(req: &LayupRequest, mesh_bytes: Option<&[u8]>) -> Result<Mesh, ApiError> {
    if let (Some(name), Some(bytes)) = (&req.mesh, mesh_bytes) {
        return read_mesh(name, bytes);
    }
    let s = Analytic::parse(&req.surface).map_err(|e| ApiError::bad(format!("surface {:?}: {e}", req.surface)))?;
    let tess = match req.triangles {
        Some(n) => Tessellation::Triangles(n),
        None => Tessellation::Chord { d_l2s: 0.05, l_seg: 20.0 },
    };
    let soup = tessellate_analytic(&s, &tess).map_err(|e| ApiError::bad(format!("surface {:?}: {e}", req.surface)))?;
    let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).map_err(|e| ApiError::bad(e.to_string()))?;
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

/// Generates the ply. `progress` gets the number of courses traced so far.
pub fn generate(req: &LayupRequest, mesh: &Mesh, progress: &mut dyn FnMut(usize)) -> Result<LayupOutcome, ApiError> {
    validate(req)?;
    let angle = req.angle.to_radians();
    let (field, source): (Box<dyn DirectionField>, String) = if !req.guides.is_empty() {
        let mut curves = Vec::new();
        for (i, g) in req.guides.iter().enumerate() {
            let file = format!("guide curve {}", i + 1);
            let pts = read_curve(g).map_err(|e| ApiError::in_file(&file, None, e.to_string()))?;
            curves.push(Polyline::new(pts).ok_or_else(|| ApiError::in_file(&file, None, "the curve has no length"))?);
        }
        (Box::new(Guides { curves, angle }), format!("{} guide curve(s)", req.guides.len()))
    } else {
        let axis = DVec3::from(req.axis);
        if !axis.is_finite() || axis.length() <= 0.0 {
            return Err(ApiError::bad("axis: must not be zero"));
        }
        (Box::new(Rosette { axis: axis.normalize(), angle }), format!("axis {},{},{}", axis.x, axis.y, axis.z))
    };
    let mut spec = PlySpec::new(req.tow_width, req.tows);
    spec.coverage = Coverage::from_percent(req.coverage).unwrap_or(Coverage::Half);
    spec.method = method(&req.method)?;
    spec.start = req.start.map(DVec3::from);
    let region = Region::whole(mesh);
    let ply = ply::plan(mesh, field.as_ref(), &region, &spec, progress).map_err(|e| ApiError::bad(e.to_string()))?;
    let meta = Meta {
        surface: req.mesh.clone().unwrap_or_else(|| req.surface.clone()),
        angle_deg: req.angle,
        direction_source: source,
        tow_width: req.tow_width,
        tows: req.tows,
        coverage_percent: spec.coverage.percent(),
        method: spec.method,
        ply_number: 1,
        input_units: Default::default(),
    };
    let courses_json = output::to_json(&ply, &meta).to_string();
    let gcode = output::to_gcode(&ply, &meta, &Post::default());
    let mut summary = output::summary(&ply);
    if let Some(o) = summary.as_object_mut() {
        o.insert("mesh_triangles".into(), mesh.num_faces().into());
    }
    Ok(LayupOutcome { courses_json, gcode, mesh: mesh_blob(mesh), summary })
}
