//! `towpath demo`: the whole AFP flow on built-in parts, with no files of the user's own.
//!
//! Writes seed 000's test parts (planar base ply and pad-ups at 0°, 45° and 90°, and three
//! cylinders) as programs, with the machine and dialect files, into a directory; optimizes each
//! (bidirectional, course-level precedence); writes the optimized program and an HTML report;
//! verifies the output independently; and prints the savings beside seed 000's.

use std::path::PathBuf;

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
    /// Cost model to optimize.
    #[arg(long, default_value = "axis", value_name = "axis|time|tool")]
    pub cost: CostKind,
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
    let afp = AfpOptions { cost: args.cost, bidirectional: !args.unidirectional, ..AfpOptions::default() };
    let opts = OptimizeOptions {
        afp: afp.clone(),
        time_limit: if args.iterations.is_some() { None } else { Some(time_limit) },
        iterations: args.iterations,
        solver: args.solver.solver,
        baselines: args.solver.params(),
        ..OptimizeOptions::default()
    };
    if !args.json {
        outln!("towpath demo: seed 000's AFP test parts, written to {}/", dir.display());
        outln!(
            "Each program is planned badly on purpose: plies out of order, every course laid in the same direction.\n\
             The {} solver re-sequences the courses ({}, a course after the courses of earlier plies it overlaps),\n\
             towpath rewrites only the off-part motion and verifies the result independently.\n\
             Course width: tow width {TOW_WIDTH} mm × tows on, from the demo's dialect ({}).\n",
            args.solver.solver,
            if args.unidirectional { "unidirectional" } else { "bidirectional" },
            dir.join("dialect.toml").display()
        );
        outln!(
            "{:<22} {:>7} {:>24} {:>8} {:>9} {:>13} {:>9}",
            "part",
            "courses",
            format!("off-part ({})", args.cost),
            "saved",
            "seed 000",
            "total (tool)",
            "verified"
        );
    }
    let mut rows = Vec::new();
    for part in parts {
        let prog_path = dir.join(format!("{}.nc", part.name));
        let out_path = dir.join(format!("{}.opt.nc", part.name));
        files.write(&prog_path, &part.program)?;
        let o = optimize(&part.program, &part.machine, &dialect, &opts)
            .map_err(|e| classify(&prog_path, &dir.join(machine_file(&part.machine)), e))?;
        files.write(&out_path, &o.text)?;
        let report = Report::new(&format!("{}.nc", part.name), &part.machine, &o, &afp);
        let optimized = parse(&o.text, &part.machine, &dialect)?;
        files.write(&dir.join(format!("{}.html", part.name)), report.to_html(&o, &optimized, &part.machine))?;
        // The whole flow: verify the written output again, from the texts alone.
        let v = verify(&part.program, &o.text, &part.machine, &dialect, &VerifyOptions::default())
            .map_err(|e| exit::check_failed(anyhow::anyhow!("{}: {e}", out_path.display())))?;
        let t = report.total(args.cost).cloned();
        let tool = report.total(CostKind::Tool).cloned();
        let (seed_off, seed_total) = part.seed.map_or((f64::NAN, f64::NAN), |s| (s.1, s.2));
        if !args.json {
            if let Some(t) = &t {
                outln!(
                    "{:<22} {:>7} {:>24} {:>7.1}% {:>9} {:>12.1}% {:>9}",
                    part.name,
                    v.courses,
                    format!("{:.0} -> {:.0}", t.off_before, t.off_after),
                    t.off_saved_percent,
                    if seed_off.is_nan() { "-".to_string() } else { format!("{seed_off:.1}%") },
                    tool.as_ref().map_or(f64::NAN, |x| x.total_saved_percent),
                    "yes"
                );
            }
        }
        rows.push(serde_json::json!({
            "part": part.name,
            "description": part.description,
            "courses": v.courses,
            "reversed": v.reversed,
            "totals": report.totals,
            "seed_000_off_part_saved_percent": if seed_off.is_nan() { None } else { Some(seed_off) },
            "seed_000_total_saved_percent": if seed_total.is_nan() { None } else { Some(seed_total) },
            "program": prog_path,
            "optimized": out_path,
            "solver": o.solver.solver,
            "seconds": o.timings.total,
        }));
    }
    files.write(&manifest_path, manifest_text)?;
    files.commit()?;
    if args.json {
        let width =
            serde_json::json!({ "tow_width": TOW_WIDTH, "from": "dialect", "dialect": dir.join("dialect.toml") });
        outln!("{}", serde_json::json!({ "dir": dir, "width": width, "parts": rows }));
    } else {
        outln!(
            "\nOpen {}/planar-45.html for a before/after plan view. To run one part yourself:\n  \
             towpath optimize {0}/planar-45.nc --machine {0}/gantry-afp.toml --dialect {0}/dialect.toml \\\n    \
             --bidirectional -o planar-45.opt.nc --report planar-45.html\n  \
             towpath verify {0}/planar-45.nc planar-45.opt.nc --machine {0}/gantry-afp.toml --dialect {0}/dialect.toml",
            dir.display()
        );
    }
    Ok(())
}
