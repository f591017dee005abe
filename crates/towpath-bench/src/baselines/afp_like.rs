//! Seed 000's solver against towpath's on AFP-like parts built like the paper's planar test
//! cases (§4.5, Figs. 7–10): a large rectangular base ply and three non-intersecting pad-ups
//! placed on it, programmed with the planners' mistakes the paper corrects (illogical ply order,
//! unidirectional layup where bidirectional is allowed).
//!
//! Courses are straight, one course width (101.6 mm: 16 tows of 6.35 mm) apart, covering each
//! ply's rectangle at the ply angle; each may be laid forward or reversed. Off-part travel is the
//! straight-line distance of the tool point from the end of one course to the start of the next
//! (the paper measures axis motion of its machine; there is no machine here). Precedence sets
//! follow §3.1: consecutive plies are joined while they do not intersect the current set, so
//! the base ply is one set and the three pad-ups another.
//!
//! A second table runs both solvers on `towpath demo`'s parts (real AFP programs through
//! towpath-nc: machine axis cost, course-level precedence, the programs' seed-000 sets).

use std::time::Duration;

use towpath_baselines::{solve_with, BaselineParams, DohertyParams, PrecedenceSet, SolverName};
use towpath_seq::{check, End, Metric, Mode, PointCost, Problem, SolveOptions, SolveReport, StateId, Step, TaskId};

use super::Args;
use crate::stats::ms;

/// Course width, mm.
const WIDTH: f64 = 101.6;

struct Ply {
    /// x0, y0, x1, y1 (mm).
    rect: [f64; 4],
    angle_deg: f64,
}

struct Part {
    name: &'static str,
    paper_saving: &'static str,
    plies: Vec<Ply>,
}

fn parts() -> Vec<Part> {
    let base = |a: f64| Ply { rect: [0.0, 0.0, 2400.0, 1200.0], angle_deg: a };
    let pad = |x: f64, y: f64, a: f64| Ply { rect: [x, y, x + 500.0, y + 350.0], angle_deg: a };
    let scattered = |a: f64| vec![base(a), pad(1750.0, 750.0, a), pad(150.0, 100.0, a), pad(950.0, 420.0, a)];
    vec![
        Part { name: "planar 0°, pad-ups scattered (Fig. 7)", paper_saving: "67.9 %", plies: scattered(0.0) },
        Part {
            name: "planar 0°, pad-ups equidistant (Fig. 8)",
            paper_saving: "65 %",
            plies: vec![base(0.0), pad(1700.0, 420.0, 0.0), pad(200.0, 420.0, 0.0), pad(950.0, 420.0, 0.0)],
        },
        Part { name: "planar 45° (Fig. 9)", paper_saving: "57.5 %", plies: scattered(45.0) },
        Part { name: "planar 90° (Fig. 10)", paper_saving: "56.2 %", plies: scattered(90.0) },
    ]
}

/// The courses covering a ply: segments at the ply angle, one width apart, clipped to its
/// rectangle, in order across the ply, each from the same side (unidirectional).
fn courses(ply: &Ply) -> Vec<([f64; 3], [f64; 3])> {
    let [x0, y0, x1, y1] = ply.rect;
    let a = ply.angle_deg.to_radians();
    let d = [a.cos(), a.sin()];
    let nv = [-a.sin(), a.cos()];
    let proj: Vec<f64> = [[x0, y0], [x1, y0], [x0, y1], [x1, y1]].iter().map(|c| c[0] * nv[0] + c[1] * nv[1]).collect();
    let smin = proj.iter().copied().fold(f64::INFINITY, f64::min);
    let smax = proj.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut out = Vec::new();
    let mut s = smin + WIDTH / 2.0;
    while s < smax {
        let o = [s * nv[0], s * nv[1]];
        let (mut tmin, mut tmax) = (f64::NEG_INFINITY, f64::INFINITY);
        for (k, (lo, hi)) in [(x0, x1), (y0, y1)].into_iter().enumerate() {
            if d[k].abs() > 1e-12 {
                let (t1, t2) = ((lo - o[k]) / d[k], (hi - o[k]) / d[k]);
                tmin = tmin.max(t1.min(t2));
                tmax = tmax.min(t1.max(t2));
            } else if o[k] < lo || o[k] > hi {
                tmax = f64::NEG_INFINITY;
            }
        }
        if tmax - tmin > 1.0 {
            let p = |t: f64| [o[0] + t * d[0], o[1] + t * d[1], 0.0];
            out.push((p(tmin), p(tmax)));
        }
        s += WIDTH;
    }
    out
}

fn overlaps(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

struct Built {
    problem: Problem<PointCost>,
    sets: Vec<PrecedenceSet>,
    original: Vec<Step>,
}

fn build(part: &Part) -> anyhow::Result<Built> {
    let mut pts = Vec::new();
    let mut ply_tasks: Vec<Vec<TaskId>> = Vec::new();
    let mut modes = Vec::new();
    for ply in &part.plies {
        let mut ts = Vec::new();
        for (a, b) in courses(ply) {
            let (sa, sb) = (StateId(pts.len() as u32), StateId(pts.len() as u32 + 1));
            pts.push(a);
            pts.push(b);
            ts.push(TaskId(modes.len() as u32));
            modes.push(vec![Mode::new(sa, sb), Mode::new(sb, sa)]);
        }
        ply_tasks.push(ts);
    }
    // §3.1: join consecutive plies while they do not intersect the current set.
    let mut sets: Vec<(Vec<usize>, PrecedenceSet)> = Vec::new();
    for (i, ply) in part.plies.iter().enumerate() {
        let joins =
            sets.last().is_some_and(|(members, _)| members.iter().all(|&j| !overlaps(&part.plies[j].rect, &ply.rect)));
        if joins {
            if let Some((members, set)) = sets.last_mut() {
                members.push(i);
                set.tasks.extend(&ply_tasks[i]);
                set.plies += 1;
            }
        } else {
            sets.push((vec![i], PrecedenceSet { tasks: ply_tasks[i].clone(), plies: 1 }));
        }
    }
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    for m in modes {
        b.task(m);
    }
    for w in sets.windows(2) {
        b.precede_groups(&w[0].1.tasks, &w[1].1.tasks);
    }
    b.end(End::Free);
    let problem = b.build()?;
    let original = ply_tasks.iter().flatten().map(|&t| Step { task: t, mode: 0 }).collect();
    Ok(Built { problem, sets: sets.into_iter().map(|(_, s)| s).collect(), original })
}

/// Runs the table and returns its Markdown.
pub fn run(args: &Args) -> anyhow::Result<String> {
    let towpath_s = if args.quick { 0.2 } else { 1.0 };
    let mut s = String::new();
    s.push_str("### Doherty et al. (2022): their solver vs towpath on AFP-like parts\n\n");
    s.push_str(&format!(
        "Parts built like the paper's planar test cases (Figs. 7–10): a 2400 × 1200 mm base ply and three \
         500 × 350 mm pad-ups, 101.6 mm courses, programmed ply by ply in an illogical pad-up order and \
         unidirectionally; bidirectional layup allowed. Off-part travel is the tool point's straight-line \
         distance between courses (no machine model). Precedence sets by §3.1 (base ply; the three pad-ups \
         joined). `doherty` runs with those sets and its default parameters; towpath's solver with the \
         precedence DAG (base before pad-ups), a {towpath_s} s limit, one thread. Both start from the \
         original order and never return worse. The paper's savings are for its own parts and machine.\n\n"
    ));
    s.push_str("| part | courses | original off-part (mm) | doherty (mm) | doherty saving | towpath (mm) | towpath saving | doherty ms | towpath ms | paper's saving |\n");
    s.push_str("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for part in parts() {
        let b = build(&part)?;
        let p = &b.problem;
        let original = check(p, &b.original)?;
        let params = BaselineParams {
            doherty: DohertyParams { sets: Some(b.sets.clone()), ..DohertyParams::default() },
            ..BaselineParams::default()
        };
        let opts =
            SolveOptions { time_limit: None, threads: 1, initial: Some(b.original.clone()), ..SolveOptions::default() };
        let d = solve_with(SolverName::Doherty, p, &opts, &params)?;
        let opts = SolveOptions {
            time_limit: Some(Duration::from_secs_f64(towpath_s)),
            threads: 1,
            initial: Some(b.original.clone()),
            ..SolveOptions::default()
        };
        let t = solve_with(SolverName::Towpath, p, &opts, &params)?;
        s.push_str(&format!(
            "| {} | {} | {} {} |\n",
            part.name,
            p.num_tasks(),
            compared(original, &d, &t),
            part.paper_saving
        ));
        eprintln!("Doherty et al. part {} done", part.name);
    }
    s.push('\n');
    s.push_str(&demo_table(towpath_s)?);
    Ok(s)
}

/// Both solvers on the demo parts, through towpath-nc's problem and seed-000 sets.
fn demo_table(towpath_s: f64) -> anyhow::Result<String> {
    use towpath_nc::demo::{demo_parts, TOW_WIDTH};
    use towpath_nc::{build_problem, parse, sequence, AfpOptions, Dialect, Width};

    let mut s = String::new();
    s.push_str(&format!(
        "On `towpath demo`'s parts (the AFP programs of the \"AFP programs (Doherty et al. 2022)\" section, read by \
         towpath-nc): the route cost is the off-part motion in Doherty et al.'s weighted axis distance (approach and \
         retract included, moves between precedence sets counted), bidirectional, course-level precedence. \
         `doherty` gets each program's Doherty et al. precedence sets (§3.1, from the course footprints) and orders set \
         after set, treating the moves between sets as free, as the paper does; towpath's solver sees only the \
         course-level precedence, {towpath_s} s, one thread. Both from the original order. The programs \
         written from these routes are verified in the AFP section.\n\n"
    ));
    s.push_str("| part | courses | sets | original off-part (axis) | doherty | doherty saving | towpath | towpath saving | doherty ms | towpath ms |\n");
    s.push_str("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let dialect = Dialect::default();
    let afp_opts = AfpOptions { bidirectional: true, width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() };
    for part in demo_parts() {
        let program = parse(&part.program, &part.machine, &dialect)?;
        let afp = build_problem(&program, &part.machine, &dialect, &afp_opts)?;
        let original = check(&afp.problem, &afp.original)?;
        let params = BaselineParams::default();
        let opts = SolveOptions { time_limit: None, threads: 1, ..SolveOptions::default() };
        let d = sequence(SolverName::Doherty, &params, &program, &afp, &afp_opts, &opts)?;
        let opts = SolveOptions {
            time_limit: Some(Duration::from_secs_f64(towpath_s)),
            threads: 1,
            ..SolveOptions::default()
        };
        let t = sequence(SolverName::Towpath, &params, &program, &afp, &afp_opts, &opts)?;
        s.push_str(&format!(
            "| {} | {} | {} | {}\n",
            part.name,
            afp.problem.num_tasks(),
            afp.sets.iter().filter(|c| !c.is_empty()).count(),
            compared(original, &d, &t),
        ));
        eprintln!("Doherty et al. demo part {} done", part.name);
    }
    s.push('\n');
    Ok(s)
}

/// The cells both tables share: original cost, doherty's cost and saving, towpath's cost and
/// saving, both solve times (each cell followed by ` |`).
fn compared(original: f64, d: &SolveReport, t: &SolveReport) -> String {
    let save = |c: f64| 100.0 * (original - c) / original;
    format!(
        "{original:.0} | {:.0} | {:.1} % | {:.0} | {:.1} % | {} | {} |",
        d.solution.cost,
        save(d.solution.cost),
        t.solution.cost,
        save(t.solution.cost),
        ms(d.elapsed.as_secs_f64()),
        ms(t.elapsed.as_secs_f64()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn courses_cover_the_ply() {
        for a in [0.0, 45.0, 90.0] {
            let ply = Ply { rect: [0.0, 0.0, 2400.0, 1200.0], angle_deg: a };
            let c = courses(&ply);
            // area covered ≈ Σ length × width (within one course width at the edges)
            let covered: f64 =
                c.iter().map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt() * WIDTH).sum();
            assert!((covered / (2400.0 * 1200.0) - 1.0).abs() < 0.1, "angle {a}: {covered}");
            for (p, q) in &c {
                for r in [p, q] {
                    assert!(r[0] >= -1e-6 && r[0] <= 2400.0 + 1e-6 && r[1] >= -1e-6 && r[1] <= 1200.0 + 1e-6);
                }
            }
        }
    }

    #[test]
    fn sets_follow_section_3_1() {
        for part in parts() {
            let b = build(&part).unwrap();
            assert_eq!(b.sets.len(), 2, "{}", part.name);
            assert_eq!(b.sets[1].plies, 3);
            check(&b.problem, &b.original).unwrap();
        }
    }
}
