//! `towpath layup`: fiber courses of one ply on a mold surface.
//!
//! The surface is a mesh file (STL, OBJ, PLY) or an analytic description tessellated on the fly
//! (`cylinder:r=300,l=1000`, `cone:r0=..,r1=..,l=..`, `sphere:r=..`, `plane:a=..,b=..`,
//! `nurbs:PATCH.json`). The design direction comes from a reference axis, guide curves or
//! orientation samples; the ply from the whole mesh or a boundary curve. This module reads the
//! files and fills in a [`LayupRequest`]; the library checks, bounds and runs it.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context};
use towpath_geom::surface::Tessellation;
use towpath_geom::{io, DVec3};
use towpath_layup::input::{read_curve, read_orientations};
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::Method;
use towpath_layup::request::{
    self as layup, sig, DirectionSource, LayupError, LayupRequest, LayupResult, Limits, SurfaceRequest, Warning,
};
use towpath_layup::section::Coverage;
use towpath_layup::units::Units;

use super::layup_report;
use super::surface_arg::surface_source;
use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath layup`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  towpath layup cylinder:r=300,l=1000 --angle 45 --axis 0,0,1 --tow-width 6.35 --tows 16 -o courses.json\n  towpath layup mold.stl --angle 0 --guide spine.csv --boundary ply1.csv --tow-width 6.35 --tows 8 --coverage 100 -o ply1.json --gcode ply1.nc --report ply1.html\n  towpath layup wing.stl --units ft --tow-width 0.25in --tows 16 --angle 45 -o wing.json\n\nLengths (surface, curves, points, tolerances, radii) are in --units (default mm); --tow-width may carry its own unit. Outputs are in mm.\nThe run stops with an error at --time-limit (default 300 s); nothing is written then. Warnings (implausible sizes or units, poor coverage, large overlaps) go to standard error."
)]
pub struct Args {
    /// Mold surface: a mesh file (.stl, .obj, .ply) or an analytic description such as
    /// `cylinder:r=300,l=1000`, `cone:r0=300,r1=150,l=600`, `sphere:r=500`, `plane:a=1000,b=800`
    /// or `nurbs:PATCH.json`.
    pub surface: String,
    /// Ply angle θ in degrees, counter-clockwise about the outward normal from the datum.
    #[arg(long, allow_hyphen_values = true)]
    pub angle: f64,
    /// Reference axis (rosette) X,Y,Z: the 0° direction projected onto the surface. Default 1,0,0.
    #[arg(long, value_parser = parse_vec3, conflicts_with_all = ["guide", "orientations"], allow_hyphen_values = true)]
    pub axis: Option<DVec3>,
    /// Guide curve CSV (x,y,z per line); repeat for several guides, given in order across the
    /// surface (Xiao et al. 2020, Algorithm 5).
    #[arg(long, conflicts_with = "orientations")]
    pub guide: Vec<PathBuf>,
    /// Orientation samples CSV (x,y,z,dx,dy,dz per line), blended within one course width.
    #[arg(long)]
    pub orientations: Option<PathBuf>,
    /// Tow width, in --units unless it carries its own unit (`6.35`, `0.25in`, `6.35mm`).
    #[arg(long, value_parser = parse_tow_width, allow_hyphen_values = true)]
    pub tow_width: (f64, Option<Units>),
    /// Tows per course.
    #[arg(long)]
    pub tows: usize,
    /// Start point X,Y,Z of the reference course (projected onto the surface). Default: the point
    /// nearest the ply's centroid.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub start: Option<DVec3>,
    /// Ply boundary: a closed curve CSV (x,y,z per line) near the surface. Default: the mesh
    /// boundary.
    #[arg(long)]
    pub boundary: Option<PathBuf>,
    /// Coverage rule at the boundary: 0 (cut at first touch), 50 (at the tow centre) or 100 (at
    /// full exit).
    #[arg(long, default_value_t = 50)]
    pub coverage: u32,
    /// Minimum steering radius (points below it are flagged). Default: 100 tow widths.
    #[arg(long, allow_hyphen_values = true)]
    pub min_steering_radius: Option<f64>,
    /// Course method: field (follow the design direction), parallel (geodesic parallels of a
    /// geodesic reference course), natural (geodesic courses seeded across the ply).
    #[arg(long, value_enum, default_value_t = MethodArg::Field)]
    pub method: MethodArg,
    /// Chord tolerance D_l2s for analytic and NURBS surfaces.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.05)]
    pub d_l2s: f64,
    /// Maximum edge length L_seg for analytic and NURBS surfaces.
    #[arg(long, allow_hyphen_values = true, default_value_t = 20.0)]
    pub l_seg: f64,
    /// Tessellate analytic and NURBS surfaces with about this many triangles (at most 4 million)
    /// instead of D_l2s/L_seg.
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Vertex welding tolerance. Default: 1e-7 of the bounding-box diagonal.
    #[arg(long, allow_hyphen_values = true)]
    pub weld_tolerance: Option<f64>,
    /// Output: courses JSON (.json).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Also write a G-code program (reference dialect).
    #[arg(long)]
    pub gcode: Option<PathBuf>,
    /// Also write a CSV table of course points.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Also write the (tessellated, welded) mesh (.stl, .obj or .ply).
    #[arg(long)]
    pub write_mesh: Option<PathBuf>,
    /// Also write a self-contained HTML page (.html) with the mesh and every course in 3D,
    /// coloured by course, angle deviation, steering radius or gap/overlap, and the summary.
    /// Opens offline in a browser: nothing in it is fetched.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Ply number in the G-code program.
    #[arg(long, default_value_t = 1)]
    pub ply_number: usize,
    /// Units of the surface (mesh coordinates, analytic sizes, NURBS control points) and of every
    /// length given: curves, start point, tolerances, radii, tow width without a unit. Outputs
    /// are in mm.
    #[arg(long, value_enum, default_value_t = UnitsArg::Mm)]
    pub units: UnitsArg,
    /// Stop with an error (writing nothing) after this many seconds, surface tessellation
    /// included.
    #[arg(long, allow_hyphen_values = true, default_value_t = 300.0)]
    pub time_limit: f64,
    /// Print one JSON object (summary) on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Units on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitsArg {
    /// Millimetres.
    Mm,
    /// Inches.
    In,
    /// Metres.
    M,
    /// Feet.
    Ft,
}

impl UnitsArg {
    fn units(self) -> Units {
        match self {
            UnitsArg::Mm => Units::Mm,
            UnitsArg::In => Units::In,
            UnitsArg::M => Units::M,
            UnitsArg::Ft => Units::Ft,
        }
    }
}

/// Course method on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodArg {
    /// Follow the design direction.
    Field,
    /// Geodesic parallels (equidistant).
    Parallel,
    /// Geodesic (natural-path) courses.
    Natural,
}

fn parse_vec3(s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("'{s}': expected X,Y,Z"));
    }
    let mut v = [0.0f64; 3];
    for (i, p) in parts.iter().enumerate() {
        v[i] = p.parse().map_err(|_| format!("'{p}' is not a number"))?;
        if !v[i].is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(DVec3::from(v))
}

fn read_text(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display())).map_err(exit::bad_input)
}

/// Parses `--tow-width`: a length with an optional unit suffix (`6.35`, `0.25in`).
fn parse_tow_width(s: &str) -> Result<(f64, Option<Units>), String> {
    Units::parse_length(s).ok_or_else(|| format!("'{s}' is not a length (a number, optionally with mm, in, m or ft)"))
}

/// The request the command line describes: files read, lengths in `--units` (a tow width with
/// its own unit converted to them).
fn request(args: &Args, deadline: Instant) -> anyhow::Result<LayupRequest> {
    let units = args.units.units();
    let (tw, tw_units) = args.tow_width;
    let tow_width = tw * tw_units.unwrap_or(units).mm() / units.mm();
    let direction = if !args.guide.is_empty() {
        let mut curves = Vec::new();
        for g in &args.guide {
            curves.push(read_curve(&read_text(g)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", g.display())))?);
        }
        DirectionSource::Guides(curves)
    } else if let Some(path) = &args.orientations {
        let samples =
            read_orientations(&read_text(path)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", path.display())))?;
        DirectionSource::Orientations(samples)
    } else {
        DirectionSource::Axis(args.axis.unwrap_or(DVec3::X))
    };
    let boundary = match &args.boundary {
        Some(path) => {
            Some(read_curve(&read_text(path)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", path.display())))?)
        }
        None => None,
    };
    let coverage = Coverage::from_percent(args.coverage)
        .ok_or_else(|| exit::bad_input(anyhow!("--coverage must be 0, 50 or 100, got {}", args.coverage)))?;
    let tessellation = match args.triangles {
        Some(n) => Tessellation::Triangles(n),
        None => Tessellation::Chord { d_l2s: args.d_l2s, l_seg: args.l_seg },
    };
    Ok(LayupRequest {
        surface: SurfaceRequest {
            source: surface_source(&args.surface)?,
            tessellation,
            weld_tolerance: args.weld_tolerance,
        },
        units,
        angle_deg: args.angle,
        direction,
        method: match args.method {
            MethodArg::Field => Method::Field,
            MethodArg::Parallel => Method::Parallel,
            MethodArg::Natural => Method::Natural,
        },
        tow_width,
        tows: args.tows,
        coverage,
        boundary,
        start: args.start,
        min_steering_radius: args.min_steering_radius,
        limits: Limits { deadline: Some(deadline), ..Limits::default() },
    })
}

/// A library refusal in the command line's words: the flag behind each field.
fn refused(e: LayupError, args: &Args) -> anyhow::Error {
    let flag = match &e {
        LayupError::NotFinite(what) | LayupError::NotPositive { what, .. } | LayupError::Negative { what, .. } => {
            match *what {
                "tow width" => "--tow-width",
                "minimum steering radius" => "--min-steering-radius",
                "weld tolerance" => "--weld-tolerance",
                "chord tolerance D_l2s" => "--d-l2s",
                "maximum edge length L_seg" => "--l-seg",
                "start point" => "--start",
                "guide curve point" => "--guide",
                "orientation sample" | "orientation sample direction" => "--orientations",
                "boundary point" => "--boundary",
                _ => "",
            }
        }
        LayupError::TowWidth { .. } => "--tow-width, --units",
        LayupError::Tows(_) => "--tows",
        LayupError::Angle { .. } => "--angle",
        LayupError::Axis => "--axis",
        LayupError::TooFar { what, .. } => match what.as_str() {
            "start point" => "--start",
            "boundary point" => "--boundary",
            "guide curve point" => "--guide",
            "orientation sample" => "--orientations",
            _ => "--units",
        },
        LayupError::StartOffSurface { .. } => "--start",
        LayupError::Guide(_) => "--guide",
        LayupError::Orientations => "--orientations",
        LayupError::Boundary => "--boundary",
        LayupError::TooMuchWork { .. } => "--tow-width, --tows, --units",
        LayupError::TimeLimit(_) => "--time-limit",
        LayupError::Tessellation(_) => "--d-l2s, --l-seg, --triangles",
        _ => "",
    };
    let what = match &e {
        LayupError::Boundary => args.boundary.as_ref().map(|p| format!("{}: ", p.display())),
        LayupError::Orientations => args.orientations.as_ref().map(|p| format!("{}: ", p.display())),
        LayupError::Guide(i) => args.guide.get(i.wrapping_sub(1)).map(|p| format!("{}: ", p.display())),
        LayupError::Mesh(_) | LayupError::Ply(_) | LayupError::NoCourses { .. } | LayupError::Tessellation(_) => {
            Some(format!("{}: ", args.surface))
        }
        _ => None,
    }
    .unwrap_or_default();
    let hint = if flag.is_empty() { String::new() } else { format!(" ({flag})") };
    exit::bad_input(anyhow!("{what}{e}{hint}"))
}

/// Runs `towpath layup`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    if !(args.time_limit > 0.0 && args.time_limit.is_finite() && args.time_limit <= 1e7) {
        return Err(exit::bad_input(anyhow!(
            "--time-limit must be a positive number of seconds (at most 1e7), got {}",
            args.time_limit
        )));
    }
    let deadline = t0 + Duration::from_secs_f64(args.time_limit);
    let mut files = declare_files(&args)?;
    let request = request(&args, deadline)?;
    let units = request.units;
    let direction = request.direction.describe();
    let spinner = progress_bar();
    spinner.set_message(format!("building {}", args.surface));
    let mut progress = |n: usize| spinner.set_message(format!("tracing courses: {n}"));
    let result = layup::run(request, &mut progress).map_err(|e| refused(e, &args))?;
    spinner.finish_and_clear();
    let meta = Meta {
        surface: args.surface.clone(),
        angle_deg: args.angle,
        direction_source: direction,
        tow_width: result.tow_width_mm,
        tows: args.tows,
        coverage_percent: args.coverage,
        method: result_method(&args),
        ply_number: args.ply_number,
        input_units: units,
    };
    let written = write_outputs(&args, &result, &meta, &mut files)?;
    files.commit()?;
    for w in &result.warnings {
        let _ = writeln!(std::io::stderr().lock(), "warning: {w}{}", warning_hint(w));
    }
    if args.json {
        print_json(&args, &result, &written, units, t0)?;
    } else {
        print_table(&args, &result, &meta, &written, t0);
    }
    Ok(())
}

fn result_method(args: &Args) -> Method {
    match args.method {
        MethodArg::Field => Method::Field,
        MethodArg::Parallel => Method::Parallel,
        MethodArg::Natural => Method::Natural,
    }
}

/// The flag a user would change for a warning.
fn warning_hint(w: &Warning) -> &'static str {
    match w {
        Warning::SurfaceSize { .. } => " (give them with --units)",
        Warning::TowWidth { .. } => " (--tow-width takes a unit: 0.25in, 6.35mm)",
        Warning::CourseWiderThanPly { .. } => " (--tow-width, --tows)",
        Warning::CourseCount { .. } => " (--boundary, --start)",
        _ => "",
    }
}

/// Stages every output; returns (path, what it is) for the summary.
fn write_outputs(
    args: &Args,
    result: &LayupResult,
    meta: &Meta,
    files: &mut Files,
) -> anyhow::Result<Vec<(PathBuf, &'static str)>> {
    let mut written = Vec::new();
    let ply = &result.ply;
    let mut text = serde_json::to_string(&output::to_json(ply, meta))?;
    text.push('\n');
    files.write(&args.output, text)?;
    written.push((args.output.clone(), "courses JSON"));
    if let Some(path) = &args.gcode {
        files.write(path, output::to_gcode(ply, meta, &Post::default()))?;
        written.push((path.clone(), "G-code"));
    }
    if let Some(path) = &args.csv {
        files.write(path, output::to_csv(ply))?;
        written.push((path.clone(), "CSV"));
    }
    if let Some(path) = &args.write_mesh {
        let format = mesh_format(path)?;
        files.write(path, io::write_bytes(&result.mesh.to_soup(), format)?)?;
        written.push((path.clone(), "mesh, mm"));
    }
    if let Some(path) = &args.report {
        written.push((path.clone(), "HTML report"));
        let title = format!("{}: {} deg ply, {} courses", args.surface, meta.angle_deg, ply.courses.len());
        let warnings: Vec<String> = result.warnings.iter().map(|w| w.to_string()).collect();
        let list: Vec<(String, &'static str)> =
            written.iter().map(|(p, what)| (p.display().to_string(), *what)).collect();
        let page = layup_report::Page {
            title: &title,
            rows: &summary_rows(args, result, meta),
            warnings: &warnings,
            files: &list,
        };
        files.write(path, layup_report::html(&page, result, args.tows)?)?;
    }
    Ok(written)
}

fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The units line: what the inputs were in and what tow width was used.
fn units_line(args: &Args, result: &LayupResult) -> String {
    let units = args.units.units();
    let (tw, tw_units) = args.tow_width;
    let given = match tw_units {
        Some(u) => format!("{tw} {u}"),
        None => format!("{tw} {units}"),
    };
    let surface = if units == Units::Mm {
        "surface and lengths in mm".to_string()
    } else {
        format!("surface and lengths in {units} (× {} to mm)", units.mm())
    };
    if given == format!("{} mm", result.tow_width_mm) {
        format!("{surface}; outputs in mm")
    } else {
        format!("{surface}; tow width {given} = {} mm; outputs in mm", sig(result.tow_width_mm))
    }
}

/// The summary's rows from the surface to the angle deviation (label, value), shared by the
/// table on stdout and the HTML report.
fn summary_rows(args: &Args, result: &LayupResult, meta: &Meta) -> Vec<(&'static str, String)> {
    let (mesh, ply, r) = (&result.mesh, &result.ply, &result.repair);
    let q = &ply.quality;
    let mut rows = Vec::new();
    rows.push((
        "surface",
        format!(
            "{} ({}, {})",
            args.surface,
            plural(mesh.num_faces(), "triangle", "triangles"),
            plural(mesh.positions().len(), "vertex", "vertices")
        ),
    ));
    rows.push(("units", units_line(args, result)));
    if r.vertices_in != r.vertices_out {
        rows.push((
            "welding",
            format!("{} → {} vertices (tolerance {} mm)", r.vertices_in, r.vertices_out, sig(r.weld_tolerance)),
        ));
    }
    if r.degenerate_removed + r.duplicates_removed + r.flipped + r.non_manifold_edges + r.orientation_conflicts > 0 {
        rows.push((
            "repairs",
            format!(
                "{} degenerate and {} duplicate triangles removed, {} flipped, {} non-manifold and {} non-orientable edges cut",
                r.degenerate_removed, r.duplicates_removed, r.flipped, r.non_manifold_edges, r.orientation_conflicts
            ),
        ));
    }
    rows.push((
        "ply",
        format!(
            "{} deg ({}), {} × {} mm tows ({} mm course), coverage rule {} %, {} method",
            meta.angle_deg,
            meta.direction_source,
            args.tows,
            sig(result.tow_width_mm),
            sig(result.tow_width_mm * args.tows as f64),
            meta.coverage_percent,
            match meta.method {
                Method::Field => "field",
                Method::Parallel => "parallel",
                Method::Natural => "natural",
            }
        ),
    ));
    rows.push((
        "courses",
        format!(
            "{} (N1 = {} left, N2 = {} right; section estimate {} / {})",
            ply.courses.len(),
            ply.n1,
            ply.n2,
            ply.n_estimate[0],
            ply.n_estimate[1]
        ),
    ));
    rows.push(("coverage", format!("{:.2} % of {} mm²", q.coverage_percent, sig(q.ply_area))));
    // Rounding noise (a millionth of the ply, a micrometre) is no gap or overlap.
    let area = |a: f64| if a < 1e-6 * q.ply_area { "0".to_string() } else { sig(a) };
    let width = |w: f64| if w < 1e-3 { "0".to_string() } else { sig(w) };
    rows.push((
        "gaps / overlaps",
        format!(
            "{} / {} mm² (widest {} / {} mm)",
            area(q.gap_area),
            area(q.overlap_area),
            width(q.max_gap),
            width(q.max_overlap)
        ),
    ));
    rows.push((
        "steering",
        format!(
            "min radius {} (limit {} mm, {} below)",
            q.min_steering_radius.map_or("straight".to_string(), |r| format!("{} mm", sig(r))),
            sig(q.min_steering_radius_limit),
            plural(q.points_below_min_radius, "point", "points")
        ),
    ));
    rows.push((
        "angle deviation",
        format!("mean {:.3} deg, max {:.3} deg", q.mean_angle_deviation_deg, q.max_angle_deviation_deg),
    ));
    rows
}

fn print_table(args: &Args, result: &LayupResult, meta: &Meta, written: &[(PathBuf, &'static str)], t0: Instant) {
    let mut rows = summary_rows(args, result, meta);
    // The first row is the heading line.
    if !rows.is_empty() {
        let (_, surface) = rows.remove(0);
        outln!("towpath layup: {surface}");
    }
    for (label, value) in rows {
        outln!("  {label:<16}: {value}");
    }
    let ply = &result.ply;
    if !result.warnings.is_empty() {
        outln!("  warnings        : {} (on standard error)", result.warnings.len());
    }
    outln!(
        "  time            : {:.3} s mesh, {:.3} s planning, {:.3} s total",
        result.load_seconds,
        ply.seconds,
        t0.elapsed().as_secs_f64()
    );
    let list: Vec<String> = written.iter().map(|(p, what)| format!("{} ({what})", p.display())).collect();
    outln!("  wrote           : {}", list.join(", "));
}

fn print_json(
    args: &Args,
    result: &LayupResult,
    written: &[(PathBuf, &'static str)],
    units: Units,
    t0: Instant,
) -> anyhow::Result<()> {
    let mut s = output::summary(&result.ply);
    if let Some(o) = s.as_object_mut() {
        o.insert("mesh_triangles".into(), result.mesh.num_faces().into());
        o.insert("repair".into(), serde_json::to_value(&result.repair)?);
        o.insert("units".into(), serde_json::to_value(units)?);
        o.insert("tow_width_mm".into(), result.tow_width_mm.into());
        o.insert("warnings".into(), serde_json::to_value(&result.warnings)?);
        o.insert("warning_messages".into(), result.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>().into());
        o.insert("load_seconds".into(), result.load_seconds.into());
        o.insert("total_seconds".into(), t0.elapsed().as_secs_f64().into());
        o.insert("output".into(), args.output.display().to_string().into());
        let files: Vec<serde_json::Value> = written
            .iter()
            .map(|(p, what)| serde_json::json!({ "path": p.display().to_string(), "kind": what }))
            .collect();
        o.insert("written".into(), files.into());
    }
    outln!("{s}");
    Ok(())
}

/// The run's inputs (surface, NURBS patch, curves, samples) and outputs, checked against each
/// other before any work.
fn declare_files(args: &Args) -> anyhow::Result<Files> {
    let mut files = Files::new();
    match args.surface.split_once(':') {
        Some(("nurbs", path)) => files.input("NURBS patch", Path::new(path))?,
        Some(("plane" | "cylinder" | "cone" | "sphere", _)) => {}
        _ => files.input("mesh", Path::new(&args.surface))?,
    }
    for g in &args.guide {
        files.input("guide curve", g)?;
    }
    if let Some(p) = &args.orientations {
        files.input("orientation samples", p)?;
    }
    if let Some(p) = &args.boundary {
        files.input("boundary curve", p)?;
    }
    files.output("courses file (-o)", &args.output)?;
    // The courses file is JSON; a name that says otherwise is a slip (-o for --gcode, --csv).
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if let Some(e) =
        ext.filter(|e| ["csv", "nc", "gcode", "ngc", "tap", "stl", "obj", "ply", "html", "htm"].contains(&e.as_str()))
    {
        return Err(exit::bad_input(anyhow!(
            "{}: -o writes the courses as JSON, not .{e}; name it .json (G-code: --gcode, CSV: --csv, mesh: --write-mesh, 3D page: --report)",
            args.output.display()
        )));
    }
    if let Some(p) = &args.gcode {
        files.output("G-code program", p)?;
    }
    if let Some(p) = &args.csv {
        files.output("CSV table", p)?;
    }
    if let Some(p) = &args.write_mesh {
        mesh_format(p)?;
        files.output("written mesh", p)?;
    }
    if let Some(p) = &args.report {
        let ext = p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("html" | "htm")) {
            return Err(exit::bad_input(anyhow!(
                "{}: --report writes an HTML page; name it .html (courses JSON: -o, G-code: --gcode, CSV: --csv)",
                p.display()
            )));
        }
        files.output("HTML report", p)?;
    }
    Ok(files)
}

/// The mesh format `--write-mesh` names by its extension.
fn mesh_format(path: &Path) -> anyhow::Result<io::Format> {
    io::Format::from_path(path).ok_or_else(|| {
        exit::bad_input(anyhow!("{}: --write-mesh needs a .stl, .obj or .ply file name", path.display()))
    })
}

fn progress_bar() -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.enable_steady_tick(std::time::Duration::from_millis(120));
        pb
    } else {
        indicatif::ProgressBar::hidden()
    }
}
