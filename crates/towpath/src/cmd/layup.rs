//! `towpath layup`: fiber courses of one ply on a mold surface.
//!
//! The surface is a mesh file (STL, OBJ, PLY) or an analytic description tessellated on the fly
//! (`cylinder:r=300,l=1000`, `cone:r0=..,r1=..,l=..`, `sphere:r=..`, `plane:a=..,b=..`,
//! `nurbs:PATCH.json`). The design direction comes from a reference axis, guide curves or
//! orientation samples; the ply from the whole mesh or a boundary curve.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Context};
use towpath_geom::surface::{tessellate, tessellate_analytic, Analytic, Nurbs, Tessellation};
use towpath_geom::{io, BuildOptions, DVec3, Mesh, RepairReport, Soup};
use towpath_layup::boundary::Region;
use towpath_layup::field::{DirectionField, Guides, Polyline, Rosette, Samples};
use towpath_layup::input::{read_curve, read_orientations};
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::{self, Method, PlySpec};
use towpath_layup::section::Coverage;

use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath layup`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  towpath layup cylinder:r=300,l=1000 --angle 45 --axis 0,0,1 --tow-width 6.35 --tows 16 -o courses.json\n  towpath layup mold.stl --angle 0 --guide spine.csv --boundary ply1.csv --coverage 100 -o ply1.json --gcode ply1.nc"
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
    /// surface (seed 001 Algorithm 5).
    #[arg(long, conflicts_with = "orientations")]
    pub guide: Vec<PathBuf>,
    /// Orientation samples CSV (x,y,z,dx,dy,dz per line), blended within one course width.
    #[arg(long)]
    pub orientations: Option<PathBuf>,
    /// Tow width in mm.
    #[arg(long)]
    pub tow_width: f64,
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
    /// Minimum steering radius in mm (points below it are flagged). Default: 100 tow widths.
    #[arg(long)]
    pub min_steering_radius: Option<f64>,
    /// Course method: field (follow the design direction), parallel (geodesic parallels of a
    /// geodesic reference course), natural (geodesic courses seeded across the ply).
    #[arg(long, value_enum, default_value_t = MethodArg::Field)]
    pub method: MethodArg,
    /// Chord tolerance D_l2s (mm) for analytic surfaces.
    #[arg(long, default_value_t = 0.05)]
    pub d_l2s: f64,
    /// Maximum edge length L_seg (mm) for analytic surfaces.
    #[arg(long, default_value_t = 20.0)]
    pub l_seg: f64,
    /// Tessellate analytic surfaces with about this many triangles instead of D_l2s/L_seg.
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Vertex welding tolerance (mm). Default: 1e-7 of the bounding-box diagonal.
    #[arg(long)]
    pub weld_tolerance: Option<f64>,
    /// Output: courses JSON.
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
    /// Ply number in the G-code program.
    #[arg(long, default_value_t = 1)]
    pub ply_number: usize,
    /// Print one JSON object (summary) on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
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

/// A loaded surface: the mesh and, for analytic input, the exact surface.
pub struct LoadedSurface {
    /// The mesh.
    pub mesh: Mesh,
    /// What welding and repair did.
    pub report: RepairReport,
}

/// Loads a surface argument into a mesh.
pub fn load_surface(text: &str, tess: Tessellation, weld_tolerance: Option<f64>) -> anyhow::Result<LoadedSurface> {
    let kind = text.split(':').next().unwrap_or("");
    let soup: Soup = match kind {
        "plane" | "cylinder" | "cone" | "sphere" if text.contains(':') => {
            let s = Analytic::parse(text).map_err(exit::bad_input)?;
            tessellate_analytic(&s, &tess).map_err(exit::bad_input)?
        }
        "nurbs" if text.contains(':') => {
            let path = &text["nurbs:".len()..];
            let bytes = std::fs::read(path).with_context(|| format!("{path}: cannot read")).map_err(exit::bad_input)?;
            let n: Nurbs = serde_json::from_slice(&bytes)
                .map_err(|e| anyhow!("{path}: not a NURBS patch: {e}"))
                .map_err(exit::bad_input)?;
            n.validate().map_err(|e| exit::bad_input(anyhow!("{path}: {e}")))?;
            tessellate(&n, &tess).map_err(exit::bad_input)?
        }
        _ => io::read_path(Path::new(text)).map_err(exit::bad_input)?,
    };
    let (mesh, report) = Mesh::build(&soup, &BuildOptions { weld_tolerance, ..BuildOptions::default() })
        .map_err(|e| exit::bad_input(anyhow!("{text}: {e}")))?;
    Ok(LoadedSurface { mesh, report })
}

fn read_text(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display())).map_err(exit::bad_input)
}

/// Runs `towpath layup`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let mut files = declare_files(&args)?;
    if !(args.tow_width > 0.0 && args.tow_width.is_finite()) {
        return Err(exit::bad_input(anyhow!("--tow-width must be a positive number of mm, got {}", args.tow_width)));
    }
    if args.tows == 0 || args.tows > 64 {
        return Err(exit::bad_input(anyhow!("--tows must be between 1 and 64, got {}", args.tows)));
    }
    if !args.angle.is_finite() {
        return Err(exit::bad_input(anyhow!("--angle must be a number of degrees")));
    }
    let coverage = Coverage::from_percent(args.coverage)
        .ok_or_else(|| exit::bad_input(anyhow!("--coverage must be 0, 50 or 100, got {}", args.coverage)))?;
    let tess = match args.triangles {
        Some(n) => Tessellation::Triangles(n),
        None => Tessellation::Chord { d_l2s: args.d_l2s, l_seg: args.l_seg },
    };
    let spinner = progress_bar();
    spinner.set_message(format!("loading {}", args.surface));
    let tl = Instant::now();
    let loaded = load_surface(&args.surface, tess, args.weld_tolerance)?;
    let load_seconds = tl.elapsed().as_secs_f64();
    let mesh = &loaded.mesh;
    if let Some(path) = &args.write_mesh {
        let format = mesh_format(path)?;
        files.write(path, io::write_bytes(&mesh.to_soup(), format)?)?;
    }
    let angle = args.angle.to_radians();
    let width = args.tow_width * args.tows as f64;
    let (field, source): (Box<dyn DirectionField>, String) = if !args.guide.is_empty() {
        let mut curves = Vec::new();
        for g in &args.guide {
            let pts = read_curve(&read_text(g)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", g.display())))?;
            let pl = Polyline::new(pts)
                .ok_or_else(|| exit::bad_input(anyhow!("{}: the curve has no length", g.display())))?;
            curves.push(pl);
        }
        (Box::new(Guides { curves, angle }), format!("{} guide curve(s)", args.guide.len()))
    } else if let Some(path) = &args.orientations {
        let samples =
            read_orientations(&read_text(path)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", path.display())))?;
        let n = samples.len();
        let f = Samples::new(samples, width, angle)
            .ok_or_else(|| exit::bad_input(anyhow!("{}: no usable orientation sample", path.display())))?;
        (Box::new(f), format!("{n} orientation samples"))
    } else {
        let axis = args.axis.unwrap_or(DVec3::X);
        if axis.length() == 0.0 {
            return Err(exit::bad_input(anyhow!("--axis must not be zero")));
        }
        (Box::new(Rosette { axis: axis.normalize(), angle }), format!("axis {},{},{}", axis.x, axis.y, axis.z))
    };
    let region = match &args.boundary {
        Some(path) => {
            let pts = read_curve(&read_text(path)?).map_err(|e| exit::bad_input(anyhow!("{}: {e}", path.display())))?;
            Region::curve(mesh, &pts, (0.5 * args.tow_width).max(1.0), args.start).ok_or_else(|| {
                exit::bad_input(anyhow!(
                    "{}: the boundary needs at least 3 distinct points on the surface",
                    path.display()
                ))
            })?
        }
        None => Region::whole(mesh),
    };
    let mut spec = PlySpec::new(args.tow_width, args.tows);
    spec.coverage = coverage;
    spec.start = args.start;
    spec.method = match args.method {
        MethodArg::Field => Method::Field,
        MethodArg::Parallel => Method::Parallel,
        MethodArg::Natural => Method::Natural,
    };
    if let Some(r) = args.min_steering_radius {
        spec.min_steering_radius = r;
    }
    spinner.set_message("tracing courses");
    let mut progress = |n: usize| spinner.set_message(format!("tracing courses: {n}"));
    let ply = ply::plan(mesh, field.as_ref(), &region, &spec, &mut progress)
        .map_err(|e| exit::bad_input(anyhow!("{}: {e}", args.surface)))?;
    spinner.finish_and_clear();
    let meta = Meta {
        surface: args.surface.clone(),
        angle_deg: args.angle,
        direction_source: source,
        tow_width: args.tow_width,
        tows: args.tows,
        coverage_percent: coverage.percent(),
        method: spec.method,
        ply_number: args.ply_number,
    };
    let doc = output::to_json(&ply, &meta);
    let mut text = serde_json::to_string(&doc)?;
    text.push('\n');
    files.write(&args.output, text)?;
    if let Some(path) = &args.gcode {
        files.write(path, output::to_gcode(&ply, &meta, &Post::default()))?;
    }
    if let Some(path) = &args.csv {
        files.write(path, output::to_csv(&ply))?;
    }
    files.commit()?;
    let q = &ply.quality;
    if args.json {
        let mut s = output::summary(&ply);
        if let Some(o) = s.as_object_mut() {
            o.insert("mesh_triangles".into(), mesh.num_faces().into());
            o.insert("repair".into(), serde_json::to_value(&loaded.report)?);
            o.insert("load_seconds".into(), load_seconds.into());
            o.insert("total_seconds".into(), t0.elapsed().as_secs_f64().into());
            o.insert("output".into(), args.output.display().to_string().into());
        }
        outln!("{s}");
    } else {
        let r = &loaded.report;
        outln!("towpath layup: {} ({} triangles, {} vertices)", args.surface, mesh.num_faces(), mesh.positions().len());
        if r.degenerate_removed + r.duplicates_removed + r.flipped + r.non_manifold_edges + r.orientation_conflicts > 0
        {
            outln!(
                "  repairs         : {} degenerate and {} duplicate triangles removed, {} flipped, {} non-manifold and {} non-orientable edges cut",
                r.degenerate_removed, r.duplicates_removed, r.flipped, r.non_manifold_edges, r.orientation_conflicts
            );
        }
        outln!(
            "  ply             : {} ({}), {} x {} mm tows, coverage {} %",
            meta.angle_deg,
            meta.direction_source,
            args.tows,
            args.tow_width,
            coverage.percent()
        );
        outln!(
            "  courses         : {} (N1 = {} left, N2 = {} right; section estimate {} / {})",
            ply.courses.len(),
            ply.n1,
            ply.n2,
            ply.n_estimate[0],
            ply.n_estimate[1]
        );
        outln!("  coverage        : {:.2} % of {:.0} mm2", q.coverage_percent, q.ply_area);
        outln!(
            "  gaps / overlaps : {:.0} / {:.0} mm2 (widest {:.2} / {:.2} mm)",
            q.gap_area,
            q.overlap_area,
            q.max_gap,
            q.max_overlap
        );
        outln!(
            "  steering        : min radius {} (limit {:.0} mm, {} points below)",
            q.min_steering_radius.map_or("straight".to_string(), |r| format!("{r:.0} mm")),
            q.min_steering_radius_limit,
            q.points_below_min_radius
        );
        outln!(
            "  angle deviation : mean {:.3} deg, max {:.3} deg",
            q.mean_angle_deviation_deg,
            q.max_angle_deviation_deg
        );
        outln!("  time            : {:.3} s planning, {:.3} s total", ply.seconds, t0.elapsed().as_secs_f64());
        outln!("  wrote           : {}", args.output.display());
    }
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
