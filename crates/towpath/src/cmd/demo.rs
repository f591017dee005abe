//! `towpath demo`: the whole AFP flow on built-in parts, with no files of the user's own.
//!
//! Writes Doherty et al.'s (2022) test parts (planar base ply and pad-ups at 0°, 45° and 90°,
//! and three cylinders) as programs, with the machine and dialect files, into a directory;
//! optimizes each (cycle time by default, bidirectional, course-level precedence); writes the
//! optimized program and an HTML report; verifies the output independently; and prints the
//! cycle time before and after, then the distance savings beside the paper's.

use std::path::{Path, PathBuf};

use towpath_machine::CostKind;
use towpath_nc::demo::{demo_parts, gantry, mandrel_machine, TOW_WIDTH};
use towpath_nc::{optimize, parse, verify, AfpOptions, Dialect, OptimizeOptions, Report, VerifyOptions};

use super::optimize::classify;
use super::solver_args::SolverArgs;
use crate::files::{DemoManifest, Files};
use crate::{exit, outln};

/// Arguments of `towpath demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Directory to write the programs, machines, optimized programs and reports into.
    #[arg(long, default_value = "towpath-demo", value_name = "DIR")]
    pub dir: PathBuf,
    /// Solver time limit per part, in seconds.
    #[arg(long, default_value_t = 0.3, value_name = "S")]
    pub time_limit: f64,
    /// Work budget per part instead of a time limit: the outputs then depend only on the inputs.
    #[arg(long, value_name = "N", conflicts_with = "time_limit")]
    pub iterations: Option<u64>,
    /// What to minimize: cycle time (time, the default: the demo's machines have velocities),
    /// Doherty et al.'s weighted axis distance (axis, the paper's cost), or the tool point's
    /// distance (tool). A longer cycle time than the input's is never returned.
    #[arg(long, value_name = "time|axis|tool")]
    pub cost: Option<CostKind>,
    /// Keep every course in its original direction.
    #[arg(long)]
    pub unidirectional: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Replace files in DIR that a previous demo did not write (without it such a run is
    /// refused, so none of your files is lost).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub solver: SolverArgs,
}

/// The file the demo writes a part's obstacle mesh to.
fn obstacle_file(part: &str, obstacle: &str) -> String {
    format!("{part}.{obstacle}.stl")
}

/// The file the demo writes a part's machine to.
fn machine_file(m: &towpath_machine::Machine) -> String {
    format!("{}.toml", m.name)
}

/// Runs the demo.
pub fn run(args: Args) -> anyhow::Result<()> {
    let time_limit = super::solver_args::time_limit(args.time_limit)?;
    let dir = &args.dir;
    let dialect = Dialect { tow_width: Some(TOW_WIDTH), ..Dialect::default() };
    let parts = demo_parts();
    // Every file the demo writes, declared before any work: none may replace a file of the
    // user's own (one the demo did not write) unless --force.
    let mut names: Vec<String> = ["gantry-afp.toml", "mandrel-afp.toml", "dialect.toml"].map(String::from).to_vec();
    for part in &parts {
        names.extend(["nc", "opt.nc", "html"].map(|ext| format!("{}.{ext}", part.name)));
        names.extend(part.obstacles.iter().map(|o| obstacle_file(&part.name, &o.name)));
    }
    if dir.exists() && !dir.is_dir() {
        return Err(exit::bad_input(anyhow::anyhow!("{}: --dir names a file, not a directory", dir.display())));
    }
    let manifest = DemoManifest::read(dir);
    manifest.check(dir, &names, args.force)?;
    let mut files = Files::new();
    for n in &names {
        files.output("demo file", &dir.join(n))?;
    }
    let (manifest_path, manifest_text) = manifest.updated(&names);
    files.output("demo manifest", &manifest_path)?;
    files.write(&dir.join("gantry-afp.toml"), gantry().to_toml_string())?;
    files.write(&dir.join("mandrel-afp.toml"), mandrel_machine().to_toml_string())?;
    files.write(&dir.join("dialect.toml"), dialect.to_toml_string())?;
    let cost = args.cost.unwrap_or_else(|| towpath_nc::default_cost(&gantry()));
    let afp = AfpOptions { cost, bidirectional: !args.unidirectional, ..AfpOptions::default() };
    let opts = OptimizeOptions {
        afp: afp.clone(),
        time_limit: if args.iterations.is_some() { None } else { Some(time_limit) },
        iterations: args.iterations,
        solver: args.solver.solver,
        baselines: args.solver.params(),
        ..OptimizeOptions::default()
    };
    if !args.json {
        outln!("towpath demo: Doherty et al.'s (2022) AFP test parts, written to {}/", dir.display());
        outln!(
            "Each program is planned badly on purpose: plies out of order, every course laid in the same direction.\n\
             The {} solver re-sequences the courses for {} ({}, a course after the courses of earlier plies it\n\
             overlaps), towpath rewrites only the off-part motion and verifies the result independently.\n\
             Course width: tow width {TOW_WIDTH} mm × tows on, from the demo's dialect ({}).\n",
            args.solver.solver,
            towpath_nc::cost_words(cost),
            if args.unidirectional { "unidirectional" } else { "bidirectional" },
            dir.join("dialect.toml").display()
        );
        outln!(
            "{:<22} {:>7} {:>21} {:>7} {:>21} {:>7} {:>10} {:>9} {:>8}",
            "part",
            "courses",
            "off-part time (s)",
            "saved",
            "cycle time (s)",
            "saved",
            "axis dist.",
            "paper's",
            "verified"
        );
    }
    let mut rows = Vec::new();
    let mut in_cells = Vec::new();
    for part in parts {
        let prog_path = dir.join(format!("{}.nc", part.name));
        let out_path = dir.join(format!("{}.opt.nc", part.name));
        files.write(&prog_path, &part.program)?;
        let mut opts = opts.clone();
        if !part.obstacles.is_empty() {
            let mut all = Vec::new();
            for ob in &part.obstacles {
                let tris: Vec<[towpath_geom::DVec3; 3]> =
                    ob.triangles.iter().map(|t| t.map(towpath_geom::DVec3::from_array)).collect();
                let bytes = towpath_geom::io::write_bytes(
                    &towpath_geom::Soup::from_triangles(tris.iter().copied()),
                    towpath_geom::io::Format::Stl,
                )?;
                files.write(&dir.join(obstacle_file(&part.name, &ob.name)), bytes)?;
                all.extend(tris);
            }
            let cell = std::sync::Arc::new(towpath_motion::Cell::from_triangles(all));
            opts.safety = Some(towpath_nc::Safety::new(&part.machine, &dialect, cell, Default::default())?);
            in_cells.push(part.name.clone());
        }
        let o = optimize(&part.program, &part.machine, &dialect, &opts)
            .map_err(|e| classify(&prog_path, &dir.join(machine_file(&part.machine)), e))?;
        files.write(&out_path, &o.text)?;
        let report = Report::new(&format!("{}.nc", part.name), &part.machine, &o, &afp);
        let optimized = parse(&o.text, &part.machine, &dialect)?;
        files.write(&dir.join(format!("{}.html", part.name)), report.to_html(&o, &optimized, &part.machine))?;
        // The whole flow: verify the written output again, from the texts alone.
        let v = verify(&part.program, &o.text, &part.machine, &dialect, &VerifyOptions::default())
            .map_err(|e| exit::check_failed(anyhow::anyhow!("{}: {e}", out_path.display())))?;
        // The table's figures come from this second, independent verification.
        let totals = towpath_nc::totals(&v);
        let of = |kind: CostKind| totals.iter().find(|t| t.kind == kind);
        let (seed_off, seed_total) = part.seed.map_or((f64::NAN, f64::NAN), |s| (s.1, s.2));
        if !args.json {
            let span = |t: Option<&towpath_nc::Totals>, total: bool| {
                t.map_or(("-".to_string(), "-".to_string()), |t| {
                    let (b, a, p) = if total {
                        (t.total_before, t.total_after, t.total_saved_percent)
                    } else {
                        (t.off_before, t.off_after, t.off_saved_percent)
                    };
                    (format!("{b:.1} -> {a:.1}"), format!("{p:.1}%"))
                })
            };
            let (off, off_saved) = span(of(CostKind::Time), false);
            let (total, total_saved) = span(of(CostKind::Time), true);
            outln!(
                "{:<22} {:>7} {:>21} {:>7} {:>21} {:>7} {:>10} {:>9} {:>8}",
                part.name,
                v.courses,
                off,
                off_saved,
                total,
                total_saved,
                of(CostKind::Axis).map_or("-".to_string(), |t| format!("{:.1}%", t.off_saved_percent)),
                if seed_off.is_nan() { "-".to_string() } else { format!("{seed_off:.1}%") },
                "yes"
            );
        }
        rows.push(serde_json::json!({
            "part": part.name,
            "description": part.description,
            "courses": v.courses,
            "reversed": v.reversed,
            "cycle_time": of(CostKind::Time),
            "totals": totals,
            "fallback": o.fallback,
            "doherty_2022_off_part_saved_percent": if seed_off.is_nan() { None } else { Some(seed_off) },
            "doherty_2022_total_saved_percent": if seed_total.is_nan() { None } else { Some(seed_total) },
            "program": prog_path,
            "optimized": out_path,
            "solver": o.solver.solver,
            "seconds": o.timings.total,
            "safety": o.safety,
        }));
        if let (Some(sf), false) = (&o.safety, args.json) {
            outln!("{:<22} motion safety: input {}", "", sf.before.summary());
            outln!("{:<22} output {}", "", sf.after.summary());
        }
    }
    files.write(&manifest_path, manifest_text)?;
    files.commit()?;
    if args.json {
        let width =
            serde_json::json!({ "tow_width": TOW_WIDTH, "from": "dialect", "dialect": dir.join("dialect.toml") });
        outln!("{}", serde_json::json!({ "dir": dir, "width": width, "parts": rows }));
    } else {
        outln!(
            "\n'time' is the machine's time model (trapezoidal moves, all axes together); 'axis dist.' is the off-part\n\
             saving in Doherty et al.'s weighted axis distance, and 'paper's' the saving their paper reports for the part."
        );
        for line in follow_up(dir) {
            outln!("{line}");
        }
    }
    Ok(())
}

/// What to run next, as commands that work pasted into the shell the demo ran from: the
/// binary by a path that reaches it from here (its name alone when it is the `towpath` on the
/// PATH), the demo's files by the path given to `--dir`, outputs into that folder.
pub fn follow_up(dir: &Path) -> Vec<String> {
    let bin = invocation();
    let q = |p: PathBuf| shell_quote(&p.display().to_string());
    let (program, machine, dialect) =
        (q(dir.join("planar-45.nc")), q(dir.join("gantry-afp.toml")), q(dir.join("dialect.toml")));
    let (out, report) = (q(dir.join("planar-45.mine.nc")), q(dir.join("planar-45.mine.html")));
    vec![
        format!("\nOpen {} for a before/after plan view. To run one part yourself:", dir.join("planar-45.html").display()),
        format!(
            "  {bin} optimize {program} --machine {machine} --dialect {dialect} \\\n    --bidirectional -o {out} --report {report}"
        ),
        format!("  {bin} verify {program} {out} --machine {machine} --dialect {dialect}"),
        "  # A part in a cell: its transits planned over the stringer, every move checked against the meshes.".to_string(),
        format!(
            "  {bin} optimize {} --machine {machine} --dialect {dialect} \\\n    --mold {} --mold {} --mold {} \\\n    \
             --bidirectional -o {} --report {}",
            q(dir.join("planar-stringer.nc")),
            q(dir.join("planar-stringer.tool.stl")),
            q(dir.join("planar-stringer.stringer.stl")),
            q(dir.join("planar-stringer.clamp.stl")),
            q(dir.join("planar-stringer.mine.nc")),
            q(dir.join("planar-stringer.mine.html")),
        ),
    ]
}

/// How to call this binary from the current directory: `towpath` when that name on the PATH
/// is this binary, else the shorter of its absolute path and its path relative to here.
fn invocation() -> String {
    let Ok(exe) = std::env::current_exe().and_then(|e| e.canonicalize()) else {
        return "towpath".into();
    };
    let on_path = std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|d| d.join("towpath").canonicalize().is_ok_and(|found| found == exe))
    });
    if on_path {
        return "towpath".into();
    }
    let relative = std::env::current_dir()
        .and_then(|d| d.canonicalize())
        .ok()
        .and_then(|here| relative_to(&exe, &here))
        .map(|r| if r.starts_with("..") { r } else { Path::new(".").join(r) });
    let abs = exe.display().to_string();
    match relative.map(|r| r.display().to_string()) {
        Some(r) if r.len() < abs.len() => shell_quote(&r),
        _ => shell_quote(&abs),
    }
}

/// `path` relative to the directory `base` (both absolute), by `..` steps.
fn relative_to(path: &Path, base: &Path) -> Option<PathBuf> {
    use std::path::Component;
    let p: Vec<Component> = path.components().collect();
    let b: Vec<Component> = base.components().collect();
    if p.first() != b.first() {
        return None;
    }
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c.as_os_str());
    }
    Some(out)
}

/// A word as a POSIX shell reads it: unchanged when it holds only safe characters, else in
/// single quotes.
fn shell_quote(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "/._-+:=,@%".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}
