//! `towpath demo`: a built-in part, sequenced and checked, with no files of the user's own.

use std::time::Duration;

use anyhow::Context;
use rand::{Rng, SeedableRng};
use towpath_seq::{check, solve, Metric, Mode, PointCost, Problem, SolveOptions, StateId};

/// Arguments of `towpath demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Time limit for the solver, in seconds.
    #[arg(long, default_value_t = 2.0)]
    pub time_limit: f64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs the demo.
pub fn run(args: Args) -> anyhow::Result<()> {
    // 400 straight strokes on a 1 m × 1 m plate, each drawable in either direction, badly
    // ordered as given: the sequencer chooses order and direction.
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
    let mut pts = Vec::new();
    for _ in 0..400 {
        let (x, y) = (rng.gen_range(0.0..1000.0), rng.gen_range(0.0..1000.0));
        let a: f64 = rng.gen_range(0.0..std::f64::consts::PI);
        let l = rng.gen_range(10.0..60.0);
        pts.push([x, y, 0.0]);
        pts.push([x + l * a.cos(), y + l * a.sin(), 0.0]);
    }
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    for k in 0..400u32 {
        let (s, e) = (StateId(2 * k), StateId(2 * k + 1));
        b.task(vec![Mode::new(s, e), Mode::new(e, s)]);
    }
    let problem = b.build().context("building the demo problem")?;
    let initial: Vec<towpath_seq::Step> = problem.tasks().map(|t| towpath_seq::Step { task: t, mode: 0 }).collect();
    let opts = SolveOptions {
        time_limit: Some(Duration::from_secs_f64(args.time_limit)),
        initial: Some(initial),
        ..SolveOptions::default()
    };
    let report = solve(&problem, &opts)?;
    let checked = check(&problem, &report.solution.steps)?;
    let before = report.initial_cost.unwrap_or(f64::NAN);
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "tasks": problem.num_tasks(),
                "travel_before": before,
                "travel_after": checked,
                "saved_percent": 100.0 * (before - checked) / before,
                "seconds": report.elapsed.as_secs_f64(),
            })
        );
    } else {
        println!("towpath demo: 400 strokes on a plate, order and direction free");
        println!("  off-part travel as given : {before:>10.1} mm");
        println!("  off-part travel sequenced: {checked:>10.1} mm ({:.1} % less)", 100.0 * (before - checked) / before);
        println!("  solver time              : {:>10.2} s", report.elapsed.as_secs_f64());
    }
    Ok(())
}
