//! One layup job as a library call, for the command line and a server alike.
//!
//! A [`LayupRequest`] holds everything a job needs (surface, design direction, method, band,
//! boundary, coverage rule, units, limits). [`run`] checks it in one place
//! ([`LayupRequest::validate`], typed [`LayupError`]s in the request's own terms, never a
//! command-line flag), builds the mesh, estimates the work from the ply's size and the course
//! width before anything large is allocated, plans the ply under the limits and returns a
//! [`LayupResult`]: the mesh, the ply (courses and quality) and the [`Warning`]s about anything
//! that looks wrong (implausible sizes, poor coverage, large overlaps).
//!
//! Lengths in a request are in its [`Units`]; results are in millimetres.

use std::time::{Duration, Instant};

use glam::DVec3;
use serde::Serialize;
use towpath_geom::surface::{tessellate_analytic_within, tessellate_within, Analytic, Nurbs, Tessellation};
use towpath_geom::surface::{TessellationError, TessellationLimits};
use towpath_geom::{BuildOptions, Mesh, MeshError, RepairReport, Soup};

use crate::boundary::Region;
use crate::field::{DirectionField, Guides, Polyline, Rosette, Samples};
use crate::ply::{self, Method, Ply, PlyError, PlySpec, Progress};
use crate::section::Coverage;
use crate::units::Units;

/// Where the surface comes from.
#[derive(Debug, Clone)]
pub enum SurfaceSource {
    /// Triangles as read from a mesh file.
    Soup(Soup),
    /// An analytic surface (tessellated).
    Analytic(Analytic),
    /// A NURBS patch (tessellated).
    Nurbs(Nurbs),
}

/// The mold surface of a request.
#[derive(Debug, Clone)]
pub struct SurfaceRequest {
    /// Triangles, or a surface to tessellate.
    pub source: SurfaceSource,
    /// How finely to tessellate an analytic or NURBS surface (tolerances in the request's units).
    pub tessellation: Tessellation,
    /// Vertices closer than this are welded (request units); `None`: 1e-7 of the bounding-box
    /// diagonal.
    pub weld_tolerance: Option<f64>,
}

/// Where the design direction comes from.
#[derive(Debug, Clone)]
pub enum DirectionSource {
    /// A reference axis (rosette): the 0° direction projected onto the surface.
    Axis(DVec3),
    /// Guide curves, given in order across the surface (Xiao et al. 2020, Algorithm 5).
    Guides(Vec<Vec<DVec3>>),
    /// Orientation samples (point, direction), blended within one course width.
    Orientations(Vec<(DVec3, DVec3)>),
}

impl DirectionSource {
    /// A short description for summaries (`axis 1,0,0`, `2 guide curves`).
    pub fn describe(&self) -> String {
        match self {
            DirectionSource::Axis(a) => format!("axis {},{},{}", a.x, a.y, a.z),
            DirectionSource::Guides(g) => format!("{} guide curve{}", g.len(), if g.len() == 1 { "" } else { "s" }),
            DirectionSource::Orientations(s) => {
                format!("{} orientation sample{}", s.len(), if s.len() == 1 { "" } else { "s" })
            }
        }
    }
}

/// Bounds on a request's work. A request whose estimated work exceeds them is refused before
/// the work starts; a run that reaches its deadline stops with [`LayupError::TimeLimit`].
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Give up at this instant (`None`: no deadline).
    pub deadline: Option<Instant>,
    /// Most triangles of a tessellated surface.
    pub max_triangles: usize,
    /// Most courses in a ply.
    pub max_courses: usize,
    /// Most trimming stations over all courses (course length / station spacing).
    pub max_stations: usize,
}

impl Limits {
    /// The default time limit of a request (5 minutes).
    pub const DEFAULT_TIME_LIMIT: Duration = Duration::from_secs(300);

    /// Default limits with a deadline `time_limit` from now.
    pub fn with_time_limit(time_limit: Duration) -> Limits {
        Limits { deadline: Instant::now().checked_add(time_limit), ..Limits::default() }
    }

    fn past_deadline(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

impl Default for Limits {
    /// 4 million triangles, 20,000 courses, 5 million trimming stations (about a minute of
    /// trimming), no deadline.
    fn default() -> Self {
        Limits { deadline: None, max_triangles: 4_000_000, max_courses: 20_000, max_stations: 5_000_000 }
    }
}

/// A layup job.
#[derive(Debug, Clone)]
pub struct LayupRequest {
    /// The mold surface.
    pub surface: SurfaceRequest,
    /// Units of the surface and of every length in the request.
    pub units: Units,
    /// Ply angle (degrees), counter-clockwise about the outward normal from the datum.
    pub angle_deg: f64,
    /// The design direction.
    pub direction: DirectionSource,
    /// Course method.
    pub method: Method,
    /// Tow width.
    pub tow_width: f64,
    /// Tows per course (1 to 64).
    pub tows: usize,
    /// Coverage rule at the ply boundary.
    pub coverage: Coverage,
    /// Ply boundary: a closed curve near the surface (`None`: the whole surface).
    pub boundary: Option<Vec<DVec3>>,
    /// Start point of the reference course (`None`: nearest the ply's centroid).
    pub start: Option<DVec3>,
    /// Steering radius below which points are flagged (`None`: 100 tow widths).
    pub min_steering_radius: Option<f64>,
    /// Bounds on the work.
    pub limits: Limits,
}

/// Smallest and largest tow widths accepted (mm): no tow or tape is narrower than a hundredth
/// of a millimetre or wider than a metre, and outside these numbers are a slip of units.
pub const TOW_WIDTH_RANGE_MM: [f64; 2] = [0.01, 1000.0];

/// Largest coordinate accepted (mm): a thousand kilometres.
pub const MAX_COORDINATE_MM: f64 = 1e9;

/// Why a request cannot be run.
#[derive(Debug, thiserror::Error)]
pub enum LayupError {
    /// A number that must be finite is not.
    #[error("the {0} must be a finite number")]
    NotFinite(&'static str),
    /// A length that must be positive is not.
    #[error("the {what} must be positive, got {}", sig(*value))]
    NotPositive {
        /// What it is.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A length that must not be negative is.
    #[error("the {what} must not be negative, got {}", sig(*value))]
    Negative {
        /// What it is.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The tow width is outside what any tow or tape measures.
    #[error(
        "a tow width of {} mm is outside {} to {} mm (are the units right?)",
        sig(*mm),
        TOW_WIDTH_RANGE_MM[0],
        TOW_WIDTH_RANGE_MM[1]
    )]
    TowWidth {
        /// The width in millimetres.
        mm: f64,
    },
    /// Tows per course out of range.
    #[error("the tows per course must be 1 to 64, got {0}")]
    Tows(usize),
    /// The ply angle is not a usable angle.
    #[error("the ply angle must be a finite number of degrees within ±360, got {}", sig(*degrees))]
    Angle {
        /// The angle given.
        degrees: f64,
    },
    /// The reference axis is zero or not finite.
    #[error("the reference axis must be a finite, non-zero vector")]
    Axis,
    /// A point or size lies beyond [`MAX_COORDINATE_MM`].
    #[error("the {what} lies {mm:.3e} mm from the origin, beyond towpath's {MAX_COORDINATE_MM:.0e} mm")]
    TooFar {
        /// What it is.
        what: String,
        /// Its distance (mm).
        mm: f64,
    },
    /// The start point is far from the surface.
    #[error("the start point is {distance:.4} mm from the surface (the surface is {size:.4} mm across): is it in the right units and frame?")]
    StartOffSurface {
        /// Distance to the surface (mm).
        distance: f64,
        /// Bounding-box diagonal of the surface (mm).
        size: f64,
    },
    /// A guide curve has no length.
    #[error("guide curve {0} has no length")]
    Guide(usize),
    /// No orientation sample can be used.
    #[error("no usable orientation sample (each needs a non-zero direction)")]
    Orientations,
    /// The boundary curve is not a closed curve on the surface.
    #[error("the boundary needs at least 3 distinct points on the surface")]
    Boundary,
    /// A limit is zero.
    #[error("the limit on {0} must be positive")]
    Limit(&'static str),
    /// The estimated work exceeds a limit.
    #[error("the ply would need about {estimate:.3e} {what}, more than the limit of {limit}: the tows are too narrow for a surface this size ({area_mm2:.4e} mm² with {course_mm} mm courses); check the units and the tow width")]
    TooMuchWork {
        /// What is counted (`courses`, `trimming stations`).
        what: &'static str,
        /// The estimate.
        estimate: f64,
        /// The limit.
        limit: usize,
        /// Surface area (mm²).
        area_mm2: f64,
        /// Course width (mm).
        course_mm: f64,
    },
    /// No course lays any tow.
    #[error("no course lays a tow on the ply ({courses_tried} traced): is the ply narrower than the tows, or outside the surface?")]
    NoCourses {
        /// Courses traced before trimming.
        courses_tried: usize,
    },
    /// The deadline passed.
    #[error("the time limit was reached while {0}; nothing was written")]
    TimeLimit(&'static str),
    /// The tessellation could not be made.
    #[error(transparent)]
    Tessellation(#[from] TessellationError),
    /// The mesh could not be built.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The ply could not be planned.
    #[error(transparent)]
    Ply(#[from] PlyError),
}

/// Something that looks wrong in a finished run (the run itself succeeded).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Warning {
    /// The surface is implausibly small or large for a mold: likely given in other units.
    SurfaceSize {
        /// Bounding-box diagonal (mm).
        diagonal_mm: f64,
        /// The units the surface was read in.
        units: Units,
    },
    /// The tow width is implausible for AFP tows or ATL tape (below 1 mm or above 12 in).
    TowWidth {
        /// Tow width (mm).
        mm: f64,
    },
    /// One course is wider than the whole ply across the fibers.
    CourseWiderThanPly {
        /// Course width (mm).
        course_mm: f64,
        /// The ply's width across the fibers at the reference course (mm).
        ply_mm: f64,
    },
    /// Laid tows cover little of the ply.
    LowCoverage {
        /// Covered share (%).
        percent: f64,
        /// The coverage rule (0, 50, 100).
        rule: u32,
    },
    /// Overlaps between courses are a large share of the ply.
    LargeOverlap {
        /// Overlap area (mm²).
        overlap_mm2: f64,
        /// Ply area (mm²).
        ply_mm2: f64,
    },
    /// Gaps between courses are a large share of the ply.
    LargeGaps {
        /// Gap area (mm²).
        gap_mm2: f64,
        /// Ply area (mm²).
        ply_mm2: f64,
    },
    /// The number of courses is far from the section estimate (Wang et al. 2011: N₁ + N₂ + 1).
    CourseCount {
        /// Courses laid.
        courses: usize,
        /// Courses the sections across the reference course suggest.
        estimate: usize,
    },
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Warning::SurfaceSize { diagonal_mm, units } => {
                write!(f, "the surface is {} across as read in {units}", length(diagonal_mm))?;
                let others: Vec<String> = Units::ALL
                    .iter()
                    .filter(|&&u| u != units)
                    .map(|&u| format!("{u}: {}", length(diagonal_mm / units.mm() * u.mm())))
                    .collect();
                write!(f, ", implausible for a mold; read in other units it would be {}", others.join(", "))
            }
            Warning::TowWidth { mm } => write!(
                f,
                "a tow width of {} mm is unusual (AFP tows are 3–13 mm, tape up to 300 mm): are the units right?",
                sig(mm)
            ),
            Warning::CourseWiderThanPly { course_mm, ply_mm } => write!(
                f,
                "one course ({} mm) is wider than the whole ply ({} across the fibers)",
                sig(course_mm),
                length(ply_mm)
            ),
            Warning::LowCoverage { percent, rule } => {
                write!(f, "the laid tows cover only {percent:.1} % of the ply (coverage rule {rule} %): the ply is not covered")
            }
            Warning::LargeOverlap { overlap_mm2, ply_mm2 } => write!(
                f,
                "courses overlap on {} mm² of a {} mm² ply ({:.0} %)",
                sig(overlap_mm2),
                sig(ply_mm2),
                100.0 * overlap_mm2 / ply_mm2.max(f64::MIN_POSITIVE)
            ),
            Warning::LargeGaps { gap_mm2, ply_mm2 } => write!(
                f,
                "gaps between courses cover {} mm² of a {} mm² ply ({:.0} %)",
                sig(gap_mm2),
                sig(ply_mm2),
                100.0 * gap_mm2 / ply_mm2.max(f64::MIN_POSITIVE)
            ),
            Warning::CourseCount { courses, estimate } => write!(
                f,
                "{courses} course{} laid against a section estimate of {estimate}: check the ply boundary and the start point",
                if courses == 1 { "" } else { "s" }
            ),
        }
    }
}

/// A number to four significant digits without trailing zeros, and without an exponent for
/// everyday sizes (`0.02135`, `21.35`, `6.35`, `1885000`).
pub fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = 4i32;
    let mag = x.abs().log10().floor() as i32;
    if !(-6..=12).contains(&mag) {
        return format!("{x:.3e}");
    }
    let decimals = (digits - 1 - mag).max(0) as usize;
    let scale = 10f64.powi(mag - digits + 1);
    let rounded = (x / scale).round() * scale;
    let text = format!("{rounded:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// A length in millimetres written in mm, or in m above 10 m.
fn length(mm: f64) -> String {
    if mm.abs() >= 10_000.0 {
        format!("{} m", sig(mm / 1000.0))
    } else {
        format!("{} mm", sig(mm))
    }
}

/// What a run produced.
#[derive(Debug)]
pub struct LayupResult {
    /// The mesh the courses lie on (millimetres).
    pub mesh: Mesh,
    /// What welding and repair did to it.
    pub repair: RepairReport,
    /// The courses and their quality (millimetres).
    pub ply: Ply,
    /// Anything that looks wrong.
    pub warnings: Vec<Warning>,
    /// The tow width used (mm).
    pub tow_width_mm: f64,
    /// The minimum steering radius used (mm).
    pub min_steering_radius_mm: f64,
    /// Seconds spent making the mesh (tessellation, welding, topology).
    pub load_seconds: f64,
}

impl LayupRequest {
    /// Checks every number and point of the request (before any work).
    pub fn validate(&self) -> Result<(), LayupError> {
        let f = self.units.mm();
        if !self.tow_width.is_finite() {
            return Err(LayupError::NotFinite("tow width"));
        }
        if !(self.tow_width > 0.0) {
            return Err(LayupError::NotPositive { what: "tow width", value: self.tow_width });
        }
        let tw = self.tow_width * f;
        if !(TOW_WIDTH_RANGE_MM[0]..=TOW_WIDTH_RANGE_MM[1]).contains(&tw) {
            return Err(LayupError::TowWidth { mm: tw });
        }
        if self.tows == 0 || self.tows > 64 {
            return Err(LayupError::Tows(self.tows));
        }
        if !(self.angle_deg.is_finite() && self.angle_deg.abs() <= 360.0) {
            return Err(LayupError::Angle { degrees: self.angle_deg });
        }
        if let Some(r) = self.min_steering_radius {
            positive("minimum steering radius", r)?;
        }
        if let Some(t) = self.surface.weld_tolerance {
            if !t.is_finite() {
                return Err(LayupError::NotFinite("weld tolerance"));
            }
            if t < 0.0 {
                return Err(LayupError::Negative { what: "weld tolerance", value: t });
            }
        }
        match self.surface.tessellation {
            Tessellation::Chord { d_l2s, l_seg } => {
                positive("chord tolerance D_l2s", d_l2s)?;
                positive("maximum edge length L_seg", l_seg)?;
            }
            Tessellation::Triangles(n) => {
                if n > self.limits.max_triangles {
                    return Err(TessellationError::TooMany(n, self.limits.max_triangles).into());
                }
                if n < 2 {
                    return Err(TessellationError::TooFew(n).into());
                }
            }
        }
        self.validate_limits()?;
        self.validate_direction()?;
        self.validate_points()
    }

    fn validate_limits(&self) -> Result<(), LayupError> {
        for (what, v) in [
            ("triangles", self.limits.max_triangles),
            ("courses", self.limits.max_courses),
            ("trimming stations", self.limits.max_stations),
        ] {
            if v == 0 {
                return Err(LayupError::Limit(what));
            }
        }
        Ok(())
    }

    /// The axis, guide curves or orientation samples.
    fn validate_direction(&self) -> Result<(), LayupError> {
        match &self.direction {
            DirectionSource::Axis(a) => {
                if !(a.is_finite() && a.length() > 0.0 && a.length().is_finite()) {
                    return Err(LayupError::Axis);
                }
            }
            DirectionSource::Guides(curves) => {
                for (i, c) in curves.iter().enumerate() {
                    for p in c {
                        self.near("guide curve point", *p)?;
                    }
                    if Polyline::new(c.clone()).is_none() {
                        return Err(LayupError::Guide(i + 1));
                    }
                }
            }
            DirectionSource::Orientations(samples) => {
                for (p, d) in samples {
                    self.near("orientation sample", *p)?;
                    if !d.is_finite() {
                        return Err(LayupError::NotFinite("orientation sample direction"));
                    }
                }
            }
        }
        Ok(())
    }

    /// Boundary, start point and the surface's own coordinates: finite and within reach.
    fn validate_points(&self) -> Result<(), LayupError> {
        let f = self.units.mm();
        for p in self.boundary.iter().flatten() {
            self.near("boundary point", *p)?;
        }
        if let Some(p) = self.start {
            self.near("start point", p)?;
        }
        match &self.surface.source {
            SurfaceSource::Analytic(a) => {
                let size = a.size() * f;
                if !(size <= MAX_COORDINATE_MM) {
                    return Err(LayupError::TooFar { what: "surface".into(), mm: size });
                }
            }
            SurfaceSource::Nurbs(n) => {
                for c in &n.control {
                    self.near("NURBS control point", DVec3::from(*c))?;
                }
            }
            SurfaceSource::Soup(s) => {
                // Non-finite coordinates are the mesh build's to name (by vertex).
                if let Some(p) =
                    s.positions.iter().find(|p| p.is_finite() && p.abs().max_element() * f > MAX_COORDINATE_MM)
                {
                    return Err(LayupError::TooFar { what: "mesh vertex".into(), mm: p.length() * f });
                }
            }
        }
        Ok(())
    }

    /// A point of the request: finite and within [`MAX_COORDINATE_MM`].
    fn near(&self, what: &'static str, p: DVec3) -> Result<(), LayupError> {
        if !p.is_finite() {
            return Err(LayupError::NotFinite(what));
        }
        let mm = p.abs().max_element() * self.units.mm();
        if mm > MAX_COORDINATE_MM {
            return Err(LayupError::TooFar { what: what.into(), mm });
        }
        Ok(())
    }

    /// The tow width in millimetres.
    pub fn tow_width_mm(&self) -> f64 {
        self.tow_width * self.units.mm()
    }

    /// The surface as triangles in millimetres: a mesh's triangles scaled, or the analytic or
    /// NURBS surface tessellated within the limits.
    fn soup(&mut self) -> Result<Soup, LayupError> {
        let f = self.units.mm();
        let tess = match self.surface.tessellation {
            Tessellation::Chord { d_l2s, l_seg } => Tessellation::Chord { d_l2s: d_l2s * f, l_seg: l_seg * f },
            t => t,
        };
        let limits = TessellationLimits { max_triangles: self.limits.max_triangles, deadline: self.limits.deadline };
        let soup = match &mut self.surface.source {
            SurfaceSource::Soup(s) => {
                let mut soup = std::mem::take(s);
                if f != 1.0 {
                    for p in &mut soup.positions {
                        *p *= f;
                    }
                }
                soup
            }
            SurfaceSource::Analytic(a) => tessellate_analytic_within(&a.scaled(f), &tess, &limits)?,
            SurfaceSource::Nurbs(n) => {
                let mut n = n.clone();
                for c in &mut n.control {
                    *c = (DVec3::from(*c) * f).to_array();
                }
                tessellate_within(&n, &tess, &limits)?
            }
        };
        Ok(soup)
    }

    /// The design direction field (positions in mm, `width` the course width in mm).
    fn field(&self, width: f64) -> Result<Box<dyn DirectionField>, LayupError> {
        let f = self.units.mm();
        let angle = self.angle_deg.to_radians();
        Ok(match &self.direction {
            DirectionSource::Axis(a) => Box::new(Rosette { axis: a.normalize(), angle }),
            DirectionSource::Guides(curves) => {
                let mut lines = Vec::with_capacity(curves.len());
                for (i, c) in curves.iter().enumerate() {
                    let pts = c.iter().map(|p| *p * f).collect();
                    lines.push(Polyline::new(pts).ok_or(LayupError::Guide(i + 1))?);
                }
                Box::new(Guides { curves: lines, angle })
            }
            DirectionSource::Orientations(samples) => {
                let pts = samples.iter().map(|&(p, d)| (p * f, d)).collect();
                Box::new(Samples::new(pts, width, angle).ok_or(LayupError::Orientations)?)
            }
        })
    }
}

fn positive(what: &'static str, x: f64) -> Result<(), LayupError> {
    if !x.is_finite() {
        return Err(LayupError::NotFinite(what));
    }
    if !(x > 0.0) {
        return Err(LayupError::NotPositive { what, value: x });
    }
    Ok(())
}

/// Runs a request: validate, build the mesh, estimate the work, plan the ply, and look for
/// anything wrong in the result. `progress` is told the number of courses traced so far.
pub fn run(mut request: LayupRequest, progress: Progress<'_>) -> Result<LayupResult, LayupError> {
    request.validate()?;
    let limits = request.limits;
    let f = request.units.mm();
    let tl = Instant::now();
    let soup = match request.soup() {
        Err(LayupError::Tessellation(TessellationError::TimeLimit)) => {
            return Err(LayupError::TimeLimit("tessellating the surface"))
        }
        other => other?,
    };
    if limits.past_deadline() {
        return Err(LayupError::TimeLimit("tessellating the surface"));
    }
    let weld_tolerance = request.surface.weld_tolerance.map(|t| t * f);
    let (mesh, repair) = Mesh::build(&soup, &BuildOptions { weld_tolerance, ..BuildOptions::default() })?;
    drop(soup);
    if limits.past_deadline() {
        return Err(LayupError::TimeLimit("building the mesh"));
    }
    let load_seconds = tl.elapsed().as_secs_f64();
    let tow_width_mm = request.tow_width_mm();
    let width = tow_width_mm * request.tows as f64;
    let (lo, hi) = mesh.bounds();
    let size = (hi - lo).length();
    let start = request.start.map(|p| p * f);
    if let Some(p) = start {
        let distance = mesh.closest_point(p).map_or(f64::INFINITY, |sp| mesh.point(sp).distance(p));
        if distance > size {
            return Err(LayupError::StartOffSurface { distance, size });
        }
    }
    let region = match &request.boundary {
        Some(points) => {
            let pts: Vec<DVec3> = points.iter().map(|p| *p * f).collect();
            Region::curve(&mesh, &pts, (0.5 * tow_width_mm).max(1.0), start).ok_or(LayupError::Boundary)?
        }
        None => Region::whole(&mesh),
    };
    let ply_size = ply_extent(&region, size);
    let station_step = tow_width_mm.min(5.0);
    check_work(&mesh, &region, width, station_step, ply_size, &limits)?;
    let field = request.field(width)?;
    let mut spec = PlySpec::new(tow_width_mm, request.tows);
    spec.coverage = request.coverage;
    spec.method = request.method;
    spec.start = start;
    spec.station_step = station_step;
    spec.max_courses = limits.max_courses;
    spec.deadline = limits.deadline;
    if let Some(r) = request.min_steering_radius {
        spec.min_steering_radius = r * f;
    }
    let ply = match ply::plan(&mesh, field.as_ref(), &region, &spec, progress) {
        Err(PlyError::TimeLimit { .. }) => return Err(LayupError::TimeLimit("planning the ply")),
        other => other?,
    };
    if ply.courses.is_empty() {
        return Err(LayupError::NoCourses { courses_tried: ply.n1 + ply.n2 + 1 });
    }
    let warnings = warnings(&request, &ply, size, ply_size, width);
    Ok(LayupResult {
        mesh,
        repair,
        ply,
        warnings,
        tow_width_mm,
        min_steering_radius_mm: spec.min_steering_radius,
        load_seconds,
    })
}

/// The ply's largest extent (mm): the boundary curve's bounding-box diagonal, else the mesh's.
fn ply_extent(region: &Region, mesh_size: f64) -> f64 {
    if region.curve_points.is_empty() {
        return mesh_size;
    }
    let lo = region.curve_points.iter().fold(DVec3::splat(f64::INFINITY), |a, &p| a.min(p));
    let hi = region.curve_points.iter().fold(DVec3::splat(f64::NEG_INFINITY), |a, &p| a.max(p));
    (hi - lo).length().min(mesh_size)
}

/// Refuses a ply whose work would exceed the limits, from the surface's area and the course
/// width: courses laid side by side cover the area once, so their total length is about
/// area / width and each course is at most a few extents long (a helix round a tube).
fn check_work(
    mesh: &Mesh,
    region: &Region,
    width: f64,
    station_step: f64,
    ply_size: f64,
    limits: &Limits,
) -> Result<(), LayupError> {
    let area = if region.has_curve() { mesh.area().min(ply_size * ply_size) } else { mesh.area() };
    let total_length = area / width;
    // Each course at most π extents long: the fewest courses the area can take.
    let courses = total_length / (std::f64::consts::PI * ply_size.max(f64::MIN_POSITIVE));
    if courses > limits.max_courses as f64 {
        return Err(LayupError::TooMuchWork {
            what: "courses",
            estimate: courses,
            limit: limits.max_courses,
            area_mm2: area,
            course_mm: width,
        });
    }
    // Trimming stations along the courses and their run-outs (one course width at each end).
    let stations = (total_length + 2.0 * width * courses.max(1.0)) / station_step;
    if stations > limits.max_stations as f64 {
        return Err(LayupError::TooMuchWork {
            what: "trimming stations",
            estimate: stations,
            limit: limits.max_stations,
            area_mm2: area,
            course_mm: width,
        });
    }
    Ok(())
}

/// What looks wrong in a finished ply.
fn warnings(request: &LayupRequest, ply: &Ply, size: f64, ply_size: f64, width: f64) -> Vec<Warning> {
    let mut out = Vec::new();
    // A mold between 2 cm and 100 m across.
    if !(20.0..=100_000.0).contains(&size) {
        out.push(Warning::SurfaceSize { diagonal_mm: size, units: request.units });
    }
    let tw = request.tow_width_mm();
    if !(1.0..=305.0).contains(&tw) {
        out.push(Warning::TowWidth { mm: tw });
    }
    if width > ply.section_width.min(ply_size) {
        out.push(Warning::CourseWiderThanPly { course_mm: width, ply_mm: ply.section_width.min(ply_size) });
    }
    let q = &ply.quality;
    if q.coverage_percent < 95.0 {
        out.push(Warning::LowCoverage { percent: q.coverage_percent, rule: request.coverage.percent() });
    }
    if q.overlap_area > 0.1 * q.ply_area {
        out.push(Warning::LargeOverlap { overlap_mm2: q.overlap_area, ply_mm2: q.ply_area });
    }
    if q.gap_area > 0.05 * q.ply_area {
        out.push(Warning::LargeGaps { gap_mm2: q.gap_area, ply_mm2: q.ply_area });
    }
    // Round a tube the sections on both sides run round the same surface: either side alone
    // counts the courses.
    let [left, right] = ply.n_estimate;
    let estimate = if ply.wraps { left.max(right) + 1 } else { left + right + 1 };
    let courses = ply.courses.len();
    if courses.abs_diff(estimate) > 2 && (2 * courses < estimate || courses > 2 * estimate) {
        out.push(Warning::CourseCount { courses, estimate });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.021349), "0.02135");
        assert_eq!(sig(21.349), "21.35");
        assert_eq!(sig(1_884_790.0), "1885000");
        assert_eq!(sig(0.0), "0");
        assert_eq!(sig(6.35), "6.35");
        assert_eq!(sig(-1.0), "-1");
        assert_eq!(sig(101.6), "101.6");
        assert_eq!(sig(1e-9), "1.000e-9");
    }
}
