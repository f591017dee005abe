//! `towpath spray`: spray forming and painting (Tewolde & Sheng 2008): flat patches, passes per
//! patch at the spacing that minimises the thickness error, one sequenced robot path, and the
//! predicted thickness map.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::anyhow;
use towpath_geom::surface::Tessellation;
use towpath_geom::{BuildOptions, DVec3, Mesh, RepairReport};
use towpath_spray::output::{self, Meta};
use towpath_spray::{Gun, PatternChoice, Profile, SeqOptions, SprayError, SprayParams, ThicknessMap};

use crate::cmd::solver_args::{time_limit, SolverArgs};
use crate::cmd::surface_arg::{soup_of, surface_source};
use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath spray`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  towpath spray plane:a=600,b=400 --standoff 200 --spray-radius 50 --target-thickness 20 -o path.json --thickness-map t.ply\n  towpath spray part.stl --standoff 150 --spray-radius 40 --target-thickness 25 --max-deviation 15 --home 0,0,800 -o path.json --json\n\nThe path file (format towpath-spray-path/1) is described in docs/spray.md, with the deposition model."
)]
pub struct Args {
    /// The part: a mesh file (.stl, .obj, .ply) or an analytic description such as
    /// `plane:a=600,b=400`, `cylinder:r=300,l=600,a0=0,a1=120`, `sphere:r=400,lat0=30,lat1=90`.
    pub surface: String,
    /// Standoff h: distance from the gun to the surface along its axis (mm).
    #[arg(long)]
    pub standoff: f64,
    /// Spray radius R: radius of the footprint at the standoff (mm).
    #[arg(long)]
    pub spray_radius: f64,
    /// Target mean thickness (µm).
    #[arg(long)]
    pub target_thickness: f64,
    /// Flux profile across the footprint: beta:B ((1 − r²/R²)^(B−1)) or gauss:SIGMA (mm).
    #[arg(long, default_value = "beta:2")]
    pub profile: String,
    /// Volume flow of material that stays on the part (mm³/s; 500 = 30 cm³/min).
    #[arg(long, default_value_t = towpath_spray::DEFAULT_FLOW)]
    pub flow: f64,
    /// β_th: the largest deviation of a triangle normal from its patch's mean normal (degrees).
    #[arg(long, default_value_t = towpath_spray::DEFAULT_MAX_DEVIATION)]
    pub max_deviation: f64,
    /// Pass pattern per patch: zigzag, spiral, auto (the faster of the two per patch), or slicer
    /// (no partition: parallel plane slices over the whole part, for comparison).
    #[arg(long, value_enum, default_value_t = PatternArg::Auto)]
    pub pattern: PatternArg,
    /// Fixed pass spacing (mm) instead of the optimised one.
    #[arg(long)]
    pub spacing: Option<f64>,
    /// Fixed gun speed on passes (mm/s) instead of the one that gives the target thickness.
    #[arg(long)]
    pub speed: Option<f64>,
    /// How far passes run past free and sharp edges (mm). Default: the spray radius.
    #[arg(long)]
    pub overrun: Option<f64>,
    /// Gun speed on transits with the spray off (mm/s).
    #[arg(long, default_value_t = towpath_spray::DEFAULT_TRAVEL_SPEED)]
    pub travel_speed: f64,
    /// Largest factor by which the gun speed may vary along the passes to even out the
    /// thickness (speeds between v/F and v·F); 1 keeps the planned speed. Not used with --speed.
    #[arg(long, default_value_t = towpath_spray::modulation::DEFAULT_MAX_SPEED_CHANGE, value_name = "F")]
    pub max_speed_change: f64,
    /// Home position X,Y,Z where the path starts.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub home: Option<DVec3>,
    /// Skip the topology split (holes, notches): grow flat patches on the whole part.
    #[arg(long)]
    pub no_topology: bool,
    /// Time limit of the sequencing solver (s).
    #[arg(long, default_value_t = 1.0)]
    pub time_limit: f64,
    /// Work budget of the sequencing solver (improvement kicks per round); with it the answer is
    /// the same on every run (given --threads).
    #[arg(long)]
    pub iterations: Option<u64>,
    /// Seed for the solver's random choices.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Sequencing threads (default: all cores): transit pricing, and the general solver on plans
    /// of more than 1,500 passes; towpath's search for smaller plans runs on one.
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub solver: SolverArgs,
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
    /// Output: the path file (JSON, format towpath-spray-path/1).
    #[arg(short = 'o', long = "output", value_name = "PATH.json")]
    pub output: PathBuf,
    /// Also write the poses as a CSV table.
    #[arg(long, value_name = "F.csv")]
    pub csv: Option<PathBuf>,
    /// Also write the predicted thickness per vertex as a PLY mesh (scalar and colour).
    #[arg(long, value_name = "F.ply")]
    pub thickness_map: Option<PathBuf>,
    /// Print one JSON object (the summary) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Pattern on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatternArg {
    /// Parallel passes.
    Zigzag,
    /// Rings.
    Spiral,
    /// Per patch, the faster.
    Auto,
    /// Plane slices over the whole part, no partition (comparison).
    Slicer,
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

/// A number given on the command line that must be positive.
fn positive(flag: &str, what: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(exit::bad_input(anyhow!("{flag} {v}: the {what} must be a positive number")))
    }
}

/// Library refusals are the user's to fix (exit code 2).
fn refused(surface: &str, e: SprayError) -> anyhow::Error {
    exit::bad_input(anyhow!("{surface}: {e}"))
}

/// A loaded surface: the mesh and what welding and repair did.
struct LoadedSurface {
    mesh: Mesh,
    report: RepairReport,
}

/// Reads a mesh file or tessellates an analytic description / NURBS patch (as `layup` does),
/// then welds it.
fn load_surface(text: &str, tess: Tessellation, weld_tolerance: Option<f64>) -> anyhow::Result<LoadedSurface> {
    let soup = soup_of(surface_source(text)?, &tess)?;
    let (mesh, report) = Mesh::build(&soup, &BuildOptions { weld_tolerance, ..BuildOptions::default() })
        .map_err(|e| exit::bad_input(anyhow!("{text}: {e}")))?;
    Ok(LoadedSurface { mesh, report })
}

/// Runs `towpath spray`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let mut files = Files::new();
    match args.surface.split_once(':') {
        Some(("plane" | "cylinder" | "cone" | "sphere", _)) => {}
        Some(("nurbs", path)) => files.input("NURBS patch", Path::new(path))?,
        _ => files.input("mesh", Path::new(&args.surface))?,
    }
    files.output("path file (-o)", &args.output)?;
    if let Some(p) = &args.csv {
        files.output("CSV table", p)?;
    }
    if let Some(p) = &args.thickness_map {
        files.output("thickness map", p)?;
    }
    positive("--standoff", "standoff", args.standoff)?;
    positive("--spray-radius", "spray radius", args.spray_radius)?;
    positive("--target-thickness", "target thickness (µm)", args.target_thickness)?;
    positive("--flow", "material flow", args.flow)?;
    positive("--travel-speed", "travel speed", args.travel_speed)?;
    if !(args.max_speed_change >= 1.0 && args.max_speed_change.is_finite()) {
        return Err(exit::bad_input(anyhow!(
            "--max-speed-change {}: give a factor ≥ 1 (1 keeps the planned speeds)",
            args.max_speed_change
        )));
    }
    if let Some(d) = args.spacing {
        positive("--spacing", "pass spacing", d)?;
    }
    if let Some(v) = args.speed {
        positive("--speed", "gun speed", v)?;
    }
    if let Some(e) = args.overrun {
        if !(e.is_finite() && e >= 0.0) {
            return Err(exit::bad_input(anyhow!("--overrun {e}: give a length ≥ 0")));
        }
    }
    if !(args.max_deviation > 0.0 && args.max_deviation < 90.0) {
        return Err(exit::bad_input(anyhow!(
            "--max-deviation {}: give an angle between 0 and 90 degrees",
            args.max_deviation
        )));
    }
    let profile = Profile::parse(&args.profile).map_err(|e| exit::bad_input(anyhow!("--profile: {e}")))?;
    let gun = Gun { standoff: args.standoff, radius: args.spray_radius, profile, flow: args.flow };
    gun.validate().map_err(|e| exit::bad_input(anyhow!("{e}")))?;
    let tess = match args.triangles {
        Some(n) => Tessellation::Triangles(n),
        None => Tessellation::Chord { d_l2s: args.d_l2s, l_seg: args.l_seg },
    };
    let tl = Instant::now();
    let loaded = load_surface(&args.surface, tess, args.weld_tolerance)?;
    let load_seconds = tl.elapsed().as_secs_f64();
    let mesh = &loaded.mesh;
    let mut params = SprayParams::new(gun, args.target_thickness);
    params.max_deviation_deg = args.max_deviation;
    params.pattern = match args.pattern {
        PatternArg::Zigzag => PatternChoice::Zigzag,
        PatternArg::Spiral => PatternChoice::Spiral,
        PatternArg::Auto => PatternChoice::Auto,
        PatternArg::Slicer => PatternChoice::Slicer,
    };
    params.spacing = args.spacing;
    params.speed = args.speed;
    params.overrun = args.overrun;
    params.travel_speed = args.travel_speed;
    params.max_speed_change = args.max_speed_change;
    params.home = args.home;
    params.topology = !args.no_topology;
    params.seq = SeqOptions {
        solver: args.solver.solver,
        params: args.solver.params(),
        time_limit: Some(time_limit(args.time_limit)?),
        iterations: args.iterations,
        seed: args.seed,
        threads: args.threads.unwrap_or_else(|| SeqOptions::default().threads).max(1),
    };
    let plan = towpath_spray::plan(mesh, &params).map_err(|e| refused(&args.surface, e))?;
    let tm = Instant::now();
    let map = ThicknessMap::compute(mesh, &gun, &plan.poses, args.target_thickness, gun.radius / 4.0, gun.radius)
        .map_err(|e| refused(&args.surface, e))?;
    let map_seconds = tm.elapsed().as_secs_f64();
    let meta = Meta {
        surface: args.surface.clone(),
        target_thickness_um: args.target_thickness,
        max_deviation_deg: args.max_deviation,
        pattern: format!("{:?}", args.pattern).to_ascii_lowercase(),
        solver: args.solver.solver.to_string(),
        travel_speed: args.travel_speed,
        overrun: args.overrun.unwrap_or(gun.radius),
    };
    let doc = output::path_json(&plan, &gun, Some(&map), &meta);
    let mut text = serde_json::to_string(&doc)?;
    text.push('\n');
    files.write(&args.output, text)?;
    if let Some(p) = &args.csv {
        files.write(p, output::poses_csv(&plan))?;
    }
    if let Some(p) = &args.thickness_map {
        files.write(p, output::thickness_ply(mesh, &map))?;
    }
    files.commit()?;
    let total = t0.elapsed();
    if args.json {
        let mut s = output::summary(&plan, Some(&map), &meta);
        if let Some(o) = s.as_object_mut() {
            o.insert("mesh_triangles".into(), mesh.num_faces().into());
            o.insert("repair".into(), serde_json::to_value(&loaded.report)?);
            o.insert("load_seconds".into(), load_seconds.into());
            o.insert("thickness_seconds".into(), map_seconds.into());
            o.insert("total_seconds".into(), total.as_secs_f64().into());
            o.insert("output".into(), args.output.display().to_string().into());
        }
        outln!("{s}");
        return Ok(());
    }
    let t = &plan.totals;
    let th = &map.interior;
    let mut zig = 0;
    let mut spi = 0;
    for p in &plan.patches {
        match p.pattern {
            towpath_spray::Pattern::Spiral => spi += 1,
            _ => zig += 1,
        }
    }
    outln!("towpath spray: {} ({} triangles, {:.0} mm²)", args.surface, mesh.num_faces(), mesh.area());
    outln!(
        "  gun             : standoff {} mm, spray radius {} mm, {}, flow {} mm³/s",
        gun.standoff,
        gun.radius,
        gun.profile,
        gun.flow
    );
    outln!(
        "  patches         : {} ({} zigzag, {} spiral; β_th {}°, {} topology cells)",
        plan.partition.patches.len(),
        zig,
        spi,
        args.max_deviation,
        plan.partition.cells
    );
    outln!(
        "  spacing         : optimum {:.2} mm (ripple {:.2} % on a plane)",
        plan.optimum.spacing,
        plan.optimum.ripple * 100.0
    );
    outln!("  passes          : {} ({} turns)", plan.passes.len(), t.turns);
    outln!(
        "  path            : spray {:.0} mm, travel {:.0} mm ({} lifted transits), cycle {:.1} s",
        t.spray_length_mm,
        t.travel_mm,
        plan.sequenced.lifted,
        t.cycle_time_s
    );
    let m = &plan.modulation;
    if m.rms_after < m.rms_before {
        outln!(
            "  speed modulation: {} segments, speeds {:.2}–{:.2}× planned, RMS to target {:.2} % → {:.2} % (coarse points)",
            m.segments,
            m.min_speed_factor,
            m.max_speed_factor,
            m.rms_before * 100.0,
            m.rms_after * 100.0
        );
    }
    outln!(
        "  solver          : {} ({} rounds, {:.2} s)",
        args.solver.solver,
        plan.sequenced.rounds,
        plan.sequenced.solver_seconds
    );
    outln!(
        "  thickness       : mean {:.2} µm (target {}), min {:.2}, max {:.2}, RMS {:.2} % (edge band of {} mm left out)",
        th.mean,
        args.target_thickness,
        th.min,
        th.max,
        th.rms_rel * 100.0,
        map.band
    );
    outln!(
        "  coverage        : {:.2} % of the area within ±20 % of the target ({:.2} % with the edge band), {} triangles uncovered",
        th.within_20pct * 100.0,
        map.whole.within_20pct * 100.0,
        map.uncovered_triangles
    );
    outln!("  time            : {:.3} s (load {:.3}, thickness {:.3})", total.as_secs_f64(), load_seconds, map_seconds);
    outln!("  wrote           : {}", args.output.display());
    Ok(())
}
