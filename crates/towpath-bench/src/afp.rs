//! `towpath-bench afp`: Doherty et al.'s (2022) test parts and a 100-ply, 10,000-course panel,
//! optimized and verified, beside Doherty et al.'s own solver (`doherty`); prints a Markdown
//! table and, with `--write FILE`, puts it into that file under the heading
//! "## AFP programs (Doherty et al. 2022)". Run through `bench/afp.sh`.

use std::time::{Duration, Instant};

use crate::stats::{cpu_seconds, duration as ms, median, write_section};

use towpath_machine::CostKind;
use towpath_nc::demo::{demo_parts, gantry, stacked_panel, TOW_WIDTH};
use towpath_nc::{optimize, AfpOptions, Dialect, OptimizeOptions, SolverName, Width};

/// One run on the large part.
struct BigRun {
    wall: f64,
    cpu: f64,
    timings: towpath_nc::Timings,
    saved: f64,
    courses: usize,
    edges: usize,
    lines: usize,
}

/// Arguments of `towpath-bench afp`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Runs per demo part (median).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Solver time limit per run on the demo parts, seconds.
    #[arg(long, default_value_t = 1.0)]
    time_limit: f64,
    /// Solver time limit per run on the large panel, seconds.
    #[arg(long, default_value_t = 2.0)]
    big_time_limit: f64,
    /// Plies of the large panel.
    #[arg(long, default_value_t = 100)]
    plies: usize,
    /// Courses per ply of the large panel.
    #[arg(long, default_value_t = 100)]
    courses: usize,
    /// Runs on the large panel.
    #[arg(long, default_value_t = 3)]
    big_runs: u64,
    /// Write the table into this Markdown file, replacing its section (or appending one).
    #[arg(long, value_name = "FILE")]
    write: Option<std::path::PathBuf>,
}

/// The heading of this benchmark's section in `BENCHMARKS.md`.
const HEADING: &str = "## AFP programs (Doherty et al. 2022)";

/// Runs the benchmark.
pub fn run(a: Args) -> anyhow::Result<()> {
    for (flag, t) in [("--time-limit", a.time_limit), ("--big-time-limit", a.big_time_limit)] {
        if !(t.is_finite() && (0.0..=86_400.0).contains(&t)) {
            anyhow::bail!("{flag}: give a time from 0 to one day, not {t}");
        }
    }
    let dialect = Dialect::default();
    let mut md = String::new();
    md.push_str(HEADING);
    md.push_str("\n\n");
    md.push_str(&format!(
        "Regenerate with `bench/afp.sh` (release build; {} runs per part, median; solver time limit {} s per \
         run, all cores). Parts: `towpath demo`'s, modelled on Doherty et al.'s §4.5 (programs planned badly on \
         purpose: plies out of order, every course laid in the same direction). towpath optimizes Doherty et al.'s \
         weighted axis distance (`--cost axis`), bidirectional, course-level precedence; savings are measured \
         by the independent verifier on the written programs. *Off-part* counts every move outside roller \
         contact, including approach, retract and moves between precedence sets (Doherty et al. count moves \
         between sets as free); *total* adds the on-part motion, both as tool-point distance. Doherty et al.'s \
         figures are from its §4.5 (its part geometry and machine weights are not published, so the parts \
         are analogous, not identical).\n\n",
        a.runs, a.time_limit
    ));
    md.push_str("| part | courses | Doherty et al. off-part | Doherty et al. total | towpath off-part (axis) | towpath off-part (tool) | towpath total (tool) | towpath unidirectional off-part (axis) | towpath off-part time, optimizing time | doherty (Doherty et al.'s algorithm) off-part (axis) | doherty solve | towpath off-part (axis) at doherty's solve time | towpath solve | time per run |\n");
    md.push_str("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    // Runs in which `optimize` kept the input (see `KEPT_NOTE`), anywhere in the table.
    let mut any_kept = false;
    // Parts in a cell belong to `towpath-bench motion`.
    for part in demo_parts().into_iter().filter(|p| a.runs > 0 && p.obstacles.is_empty()) {
        let mut off_axis = Vec::new();
        let mut off_tool = Vec::new();
        let mut total_tool = Vec::new();
        let mut uni = Vec::new();
        let mut time_opt = Vec::new();
        let mut secs = Vec::new();
        let mut solve_secs = Vec::new();
        let mut doherty = Vec::new();
        let mut doherty_secs = Vec::new();
        let mut short = Vec::new();
        let mut courses = 0;
        // per column: main (axis, both ways), one way, doherty, towpath at doherty's time
        let mut kept = [0usize; 4];
        for run in 0..a.runs {
            for (cost, bidirectional) in [(CostKind::Axis, true), (CostKind::Axis, false), (CostKind::Time, true)] {
                let opts = OptimizeOptions {
                    afp: AfpOptions {
                        cost,
                        bidirectional,
                        width: Some(Width::Tow(TOW_WIDTH)),
                        ..AfpOptions::default()
                    },
                    time_limit: Some(Duration::from_secs_f64(a.time_limit)),
                    seed: 1 + run as u64,
                    ..OptimizeOptions::default()
                };
                let o = optimize(&part.program, &part.machine, &dialect, &opts).expect("demo part optimizes");
                courses = o.program.courses.len();
                let v = &o.verification;
                let pct = |b: f64, x: f64| 100.0 * (b - x) / b;
                let (ba, aa) = v.motion(CostKind::Axis).expect("axis cost");
                if cost == CostKind::Time {
                    let (bt, at) = v.motion(CostKind::Time).expect("time cost");
                    time_opt.push(pct(bt.off_part(), at.off_part()));
                } else if bidirectional {
                    let (bt, at) = v.motion(CostKind::Tool).expect("tool cost");
                    off_axis.push(pct(ba.off_part(), aa.off_part()));
                    kept[0] += usize::from(o.fell_back);
                    off_tool.push(pct(bt.off_part(), at.off_part()));
                    total_tool.push(pct(bt.total(), at.total()));
                    secs.push(o.timings.total);
                    solve_secs.push(o.timings.solve);
                } else {
                    uni.push(pct(ba.off_part(), aa.off_part()));
                    kept[1] += usize::from(o.fell_back);
                }
            }
        }
        // Seed 000's solver on the same problem (axis cost, bidirectional, course-level
        // precedence), per seed-000 precedence set; then towpath's with the time doherty took.
        let afp = AfpOptions {
            cost: CostKind::Axis,
            bidirectional: true,
            width: Some(Width::Tow(TOW_WIDTH)),
            ..AfpOptions::default()
        };
        for run in 0..a.runs {
            let opts = OptimizeOptions {
                afp: afp.clone(),
                time_limit: Some(Duration::from_secs_f64(a.time_limit)),
                threads: 1,
                solver: SolverName::Doherty,
                ..OptimizeOptions::default()
            };
            let o = optimize(&part.program, &part.machine, &dialect, &opts).expect("doherty optimizes the demo part");
            let (b, x) = o.verification.motion(CostKind::Axis).expect("axis cost");
            doherty.push(100.0 * (b.off_part() - x.off_part()) / b.off_part());
            kept[2] += usize::from(o.fell_back);
            doherty_secs.push(o.timings.solve);
            let opts = OptimizeOptions {
                afp: afp.clone(),
                time_limit: Some(Duration::from_secs_f64(o.timings.solve)),
                seed: 1 + run as u64,
                ..OptimizeOptions::default()
            };
            let o = optimize(&part.program, &part.machine, &dialect, &opts).expect("demo part optimizes");
            let (b, x) = o.verification.motion(CostKind::Axis).expect("axis cost");
            short.push(100.0 * (b.off_part() - x.off_part()) / b.off_part());
            kept[3] += usize::from(o.fell_back);
        }
        let (so, st) = part.seed.map_or((f64::NAN, f64::NAN), |s| (s.1, s.2));
        let fig = part.seed.map_or("", |s| s.0);
        let p = |x: f64| if x.is_nan() { "–".to_string() } else { format!("{x:.1} %") };
        let runs = a.runs;
        let pk = |x: f64, k: usize| if k > 0 { format!("{} (†{k}/{runs})", p(x)) } else { p(x) };
        any_kept |= kept.iter().any(|&k| k > 0);
        let row = format!(
            "| {} ({fig}) | {courses} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} s |\n",
            part.name,
            p(so),
            p(st),
            pk(median(&off_axis), kept[0]),
            pk(median(&off_tool), kept[0]),
            pk(median(&total_tool), kept[0]),
            pk(median(&uni), kept[1]),
            p(median(&time_opt)),
            pk(median(&doherty), kept[2]),
            ms(median(&doherty_secs)),
            pk(median(&short), kept[3]),
            ms(median(&solve_secs)),
            median(&secs)
        );
        eprint!("{row}");
        md.push_str(&row);
    }

    if any_kept {
        md.push_str(KEPT_NOTE);
    }

    // The big part.
    let text = stacked_panel(a.plies, a.courses);
    let machine = gantry();
    let mut rows = Vec::new();
    for run in 0..a.big_runs {
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() },
            time_limit: Some(Duration::from_secs_f64(a.big_time_limit)),
            seed: 1 + run,
            ..OptimizeOptions::default()
        };
        let c0 = cpu_seconds();
        let t0 = Instant::now();
        let o = optimize(&text, &machine, &dialect, &opts).expect("the stacked panel optimizes");
        let wall = t0.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - c0;
        let (b, x) = o.verification.motion(CostKind::Axis).expect("axis cost");
        eprintln!("big run {run}: wall {wall:.2} s, cpu {cpu:.2} s, {:?}", o.timings);
        rows.push(BigRun {
            wall,
            cpu,
            timings: o.timings.clone(),
            saved: 100.0 * (b.off_part() - x.off_part()) / b.off_part(),
            courses: o.program.courses.len(),
            edges: o.afp.edges,
            lines: o.program.lines.len(),
        });
    }
    let m = |f: &dyn Fn(&BigRun) -> f64| median(&rows.iter().map(f).collect::<Vec<_>>());
    let (courses, edges, lines) = rows.first().map_or((0, 0, 0), |r| (r.courses, r.edges, r.lines));
    md.push_str(&format!(
        "\n**Large part:** a stacked panel of {} plies (0°/45°/−45°/90°, each ply over all earlier ones) with {courses} \
         courses, {lines} program lines; {edges} precedence edges after reduction. Optimized bidirectional with \
         a {} s solver limit and verified, median of {} runs: **{:.2} s wall** ({:.2} s CPU; the benchmark machine \
         has 2 cores shared with other jobs, so wall time varies with its load) — parse {:.2} s, footprints + \
         precedence + reversal + problem {:.2} s, solve {:.2} s, rewrite {:.2} s, verify {:.2} s; off-part saved \
         {:.1} % (axis).\n",
        a.plies,
        a.big_time_limit,
        rows.len(),
        m(&|r| r.wall),
        m(&|r| r.cpu),
        m(&|r| r.timings.parse),
        m(&|r| r.timings.build),
        m(&|r| r.timings.solve),
        m(&|r| r.timings.rewrite),
        m(&|r| r.timings.verify),
        m(&|r| r.saved),
    ));
    md.push_str(
        "\nThe time column optimizes `--cost time` instead and measures motion time (all axes together, \
         trapezoidal profiles; rapids at the demo machines' limits, feed moves at their programmed feed, \
         docs/machine.md): time savings are smaller than distance savings \
         because every reversal turns the head 180° (1.25 s on these machines) and approach and retract \
         take the same time whatever the order; optimizing the axis distance can even lengthen the \
         off-part time.\n",
    );
    md.push_str(&format!(
        "\nThe doherty columns run Doherty et al.'s own algorithm (§3.2: seed pool, nearest neighbour, depth-first then \
         breadth-first search; `towpath optimize --solver doherty`, crate towpath-baselines) on the same problem: \
         axis cost, bidirectional, the same course-level precedence, with the part's Doherty et al. precedence sets \
         (§3.1) as its sets, one thread; its route is rewritten and verified like towpath's. As in the paper it \
         treats moves between precedence sets as free while searching; the saving shown counts them. *doherty \
         solve* is its solver time (deterministic; median of {} runs); *towpath … at doherty's solve time* runs \
         towpath's solver with that time as its limit (all cores); *towpath solve* is towpath's solver time in the \
         main columns (its limit). *Time per run* is the whole `optimize` (parse, build, solve, rewrite, verify) \
         for the main towpath column.\n",
        a.runs
    ));
    print!("{md}");
    if let Some(path) = &a.write {
        write_section(path, HEADING, &md)?;
    }
    Ok(())
}

/// The table's note on runs in which `optimize` returned the input unchanged.
const KEPT_NOTE: &str = "\n† k/N: in k of the N runs `optimize` returned the input program unchanged (0 % saved \
    in every column of that run) because the program optimized for axis distance had a longer cycle time \
    than the input's, and towpath never returns a slower program; the solver's own axis cost was lower.\n";
