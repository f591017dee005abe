//! `towpath-bench motion`: motion safety. Three ways to write the transits of the demo parts in
//! a cell (straight and unsafe, planned against the cell, a fixed clearance above everything),
//! a 10,000-course panel on its tool optimized and verified with the cell, and the checking
//! speed of `towpath-motion` on a 1,000,000-triangle mold. Prints Markdown and, with
//! `--write FILE`, puts it under the heading "## Motion safety (towpath-motion)".

use std::sync::Arc;
use std::time::Instant;

use towpath_geom::DVec3;
use towpath_machine::CostKind;
use towpath_motion::Cell;
use towpath_nc::demo::{demo_parts, gantry, plate_mesh, stacked_panel, DemoPart, TOW_WIDTH};
use towpath_nc::{
    check_program, optimize, parse, AfpOptions, Clearance, Dialect, OptimizeOptions, Safety, SafetyOptions,
};

use crate::stats::{cpu_seconds, machine, median, write_section};

/// Arguments of `towpath-bench motion`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Runs per measurement (median).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Solver work budget per optimization of a demo part (improvement kicks; deterministic).
    #[arg(long, default_value_t = 20_000)]
    iterations: u64,
    /// Transits in the checking-speed benchmark.
    #[arg(long, default_value_t = 10_000)]
    transits: usize,
    /// Plies and courses per ply of the large panel.
    #[arg(long, default_value_t = 100)]
    plies: usize,
    /// Courses per ply of the large panel.
    #[arg(long, default_value_t = 100)]
    courses: usize,
    /// Solver time limit on the large panel, seconds.
    #[arg(long, default_value_t = 2.0)]
    big_time_limit: f64,
    /// Write the tables into this Markdown file, replacing their section.
    #[arg(long, value_name = "FILE")]
    write: Option<std::path::PathBuf>,
}

const HEADING: &str = "## Motion safety (towpath-motion)";

fn cell_of(tris: impl IntoIterator<Item = [[f64; 3]; 3]>) -> Arc<Cell> {
    Arc::new(Cell::from_triangles(tris.into_iter().map(|t| t.map(DVec3::from_array)).collect()))
}

/// One way of writing transits, measured on a written program.
struct Outcome {
    off_time: f64,
    off_tool: f64,
    total_time: f64,
    collisions: usize,
    near: usize,
    seconds: f64,
}

/// Optimizes `part` with `dialect` and `safety`, `runs` times; the program's motion from the
/// verifier, its safety checked against `cell` whatever the optimization knew. With `guard`
/// false the solver's order is written whatever it costs against the input (the optimizer
/// keeps the input's order when a fixed clearance makes every order slower than the input's
/// straight, unsafe transits).
fn measure(
    part: &DemoPart,
    dialect: &Dialect,
    safety: Option<Safety>,
    cell: &Safety,
    guard: bool,
    a: &Args,
) -> anyhow::Result<Outcome> {
    let mut secs = Vec::new();
    let mut last = None;
    let afp = AfpOptions { bidirectional: true, cost: CostKind::Time, ..AfpOptions::default() };
    for _ in 0..a.runs.max(1) {
        let t0 = Instant::now();
        let (text, v) = if guard {
            let opts = OptimizeOptions {
                afp: afp.clone(),
                time_limit: None,
                iterations: Some(a.iterations),
                threads: 2,
                safety: safety.clone(),
                ..OptimizeOptions::default()
            };
            let o = optimize(&part.program, &part.machine, dialect, &opts)?;
            (o.text, o.verification)
        } else {
            let program = parse(&part.program, &part.machine, dialect)?;
            let problem = towpath_nc::build_problem(&program, &part.machine, dialect, &afp)?;
            let solve = towpath_seq::SolveOptions {
                time_limit: None,
                iterations: Some(a.iterations),
                threads: 2,
                ..towpath_seq::SolveOptions::default()
            };
            let report = towpath_nc::sequence(
                towpath_nc::SolverName::Towpath,
                &towpath_nc::BaselineParams::default(),
                &program,
                &problem,
                &afp,
                &solve,
            )?;
            towpath_nc::apply_steps(&program, &problem, &report.solution.steps, &part.machine, dialect, &afp)?
        };
        secs.push(t0.elapsed().as_secs_f64());
        last = Some((text, v));
    }
    let (text, v) = last.ok_or_else(|| anyhow::anyhow!("no run"))?;
    let (_, t) = v.motion(CostKind::Time).ok_or_else(|| anyhow::anyhow!("no time model"))?;
    let (_, d) = v.motion(CostKind::Tool).ok_or_else(|| anyhow::anyhow!("no tool cost"))?;
    let checked = check_program(&parse(&text, &part.machine, dialect)?, cell);
    Ok(Outcome {
        off_time: t.off_part(),
        off_tool: d.off_part(),
        total_time: t.total(),
        collisions: checked.collisions.len(),
        near: checked.near_misses.len(),
        seconds: median(&secs),
    })
}

/// One run on the large panel: wall and CPU seconds, stage times, courses, the output's safety.
type PanelRun = (f64, f64, towpath_nc::Timings, usize, towpath_nc::SafetyReport);

/// Runs the benchmark.
pub fn run(a: Args) -> anyhow::Result<()> {
    let base = Dialect { tow_width: Some(TOW_WIDTH), ..Dialect::default() };
    let mut md = format!("{HEADING}\n\n");
    md.push_str(&format!(
        "Regenerate with `cargo run --release -p towpath-bench -- motion --write BENCHMARKS.md` ({}).\n\n\
         ### Transits: straight, planned against the cell, or over a fixed clearance\n\n\
         `towpath demo`'s parts in a cell, optimized for cycle time, bidirectional, with a fixed budget of {} \
         solver kicks on 2 threads (deterministic), three ways: **straight** transits that ignore the cell \
         (what towpath wrote before motion safety; unsafe), transits **planned** against the cell (`--mold`, \
         5 mm clearance: straight where that clears, else lifted only as high as needed, priced so by the \
         sequencer), and a **fixed clearance** plane above every obstacle (the dialect's `clearance`: every \
         transit goes up to it, across and down; the solver's order is written as it is, since the optimizer \
         would keep the input's faster but unsafe straight transits). Times are the machine's time model on the written programs; \
         every output is checked against the cell afterwards. *planar-45 on its tool* has no obstacle above the \
         tool plate (its fixed clearance is the 25 mm standoff). Optimization seconds: median of {} runs.\n\n",
        machine(),
        a.iterations,
        a.runs
    ));
    md.push_str(
        "| part | transits | off-part time s | off-part tool path mm | cycle time s | collisions, near misses | optimize s | vs straight (off-part time) |\n\
         |---|---|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut parts: Vec<(DemoPart, Arc<Cell>, f64)> = Vec::new();
    for p in demo_parts() {
        let level = match p.name.as_str() {
            // The stringer's top (60 mm) plus the clearance and the planner's 1 mm step.
            "planar-stringer" => 66.0,
            // The flange's rim (radius 470 mm) plus the clearance and the step, on the radial axis.
            "cylinder-flange" => 476.0,
            "planar-45" => 25.0,
            _ => continue,
        };
        let cell = if p.obstacles.is_empty() {
            cell_of(plate_mesh([-100.0, 1300.0], [-100.0, 900.0], 0.0))
        } else {
            cell_of(p.obstacles.iter().flat_map(|o| o.triangles.iter().copied()))
        };
        parts.push((p, cell, level));
    }
    let mut verdicts = Vec::new();
    for (p, cell, level) in &parts {
        let safety = Safety::new(&p.machine, &base, cell.clone(), SafetyOptions::default())?;
        let fixed = Dialect { clearance: Some(Clearance { axis: "Z".into(), value: *level }), ..base.clone() };
        let straight = measure(p, &base, None, &safety, true, &a)?;
        let planned = measure(p, &base, Some(safety.clone()), &safety, true, &a)?;
        let clear = measure(p, &fixed, None, &safety, false, &a)?;
        let name = if p.obstacles.is_empty() { format!("{} on its tool", p.name) } else { p.name.clone() };
        for (what, o) in [("straight (unsafe)", &straight), ("planned", &planned), ("fixed clearance", &clear)] {
            let row = format!(
                "| {name} | {what} | {:.1} | {:.0} | {:.1} | {}, {} | {:.2} | {:+.1} % |\n",
                o.off_time,
                o.off_tool,
                o.total_time,
                o.collisions,
                o.near,
                o.seconds,
                100.0 * (o.off_time - straight.off_time) / straight.off_time
            );
            eprint!("{row}");
            md.push_str(&row);
        }
        verdicts.push(format!(
            "{name}: planned {:+.1} % off-part time against straight, {:+.1} % against the fixed clearance, \
             {} collisions",
            100.0 * (planned.off_time - straight.off_time) / straight.off_time,
            100.0 * (planned.off_time - clear.off_time) / clear.off_time,
            planned.collisions
        ));
    }
    md.push_str(&format!(
        "\nTargets: planned transits within 2 % of the unsafe straight ones where obstacles are few, clearly \
         below a fixed clearance, and no collision in anything towpath writes. Measured: {}.\n",
        verdicts.join("; ")
    ));

    // The large panel on its tool.
    let text = stacked_panel(a.plies, a.courses);
    let gantry = gantry();
    let tool = cell_of(plate_mesh([0.0, 6000.0], [0.0, 6000.0], 0.0));
    let mut rows = Vec::new();
    for run in 0..a.runs.max(1) {
        let safety = Safety::new(&gantry, &base, tool.clone(), SafetyOptions::default())?;
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: true, ..AfpOptions::for_machine(&gantry) },
            time_limit: Some(std::time::Duration::from_secs_f64(a.big_time_limit)),
            seed: 1 + run as u64,
            safety: Some(safety),
            ..OptimizeOptions::default()
        };
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let o = optimize(&text, &gantry, &base, &opts)?;
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        let after = o.safety.as_ref().map(|s| s.after.clone()).unwrap_or_default();
        eprintln!("panel run {run}: {wall:.2} s wall, {cpu:.2} s CPU, {:?}", o.timings);
        rows.push((wall, cpu, o.timings.clone(), o.program.courses.len(), after));
    }
    let m = |f: &dyn Fn(&PanelRun) -> f64| median(&rows.iter().map(f).collect::<Vec<_>>());
    let (courses, moves, coll) =
        rows.first().map_or((0, 0, 0), |r| (r.3, r.4.moves_checked, r.4.collisions.len() + r.4.limit_violations.len()));
    md.push_str(&format!(
        "\n### A 10,000-course panel on its tool\n\n`towpath-bench afp`'s stacked panel ({} plies, {courses} courses) \
         on a 6 × 6 m tool plate, optimized for cycle time, bidirectional, with the cell (`--mold`), a {} s solver \
         limit, verified, and both programs checked move by move ({moves} moves in the output; {coll} collisions \
         or limit violations): **{:.2} s wall** ({:.2} s CPU), median of {} runs — parse {:.2} s, problem {:.2} s, \
         solve {:.2} s, rewrite {:.2} s, verify and safety checks {:.2} s. Target: under 10 s.\n",
        a.plies,
        a.big_time_limit,
        m(&|r| r.0),
        m(&|r| r.1),
        rows.len(),
        m(&|r| r.2.parse),
        m(&|r| r.2.build),
        m(&|r| r.2.solve),
        m(&|r| r.2.rewrite),
        m(&|r| r.2.verify),
    ));

    md.push_str("\n### Checking speed: 10,000 transits against a 1,000,000-triangle mold\n\n");
    md.push_str(&crate::motion_speed::run(a.runs, a.transits)?);
    print!("{md}");
    if let Some(path) = &a.write {
        write_section(path, HEADING, &md)?;
    }
    Ok(())
}
