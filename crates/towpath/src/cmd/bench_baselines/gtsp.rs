//! Seed 003's transformation (castelino) against towpath's direct search on generalized TSPs.
//!
//! Instances are built in code ([`towpath_baselines::random_gtsp`]: GTSP-LIB's clustering on
//! random points; with precedence, PCGTSP-like). GTSP-LIB and PCGLNS files from
//! `/work/shared/data` join the table through [`row`] once the formats crate reads them.

use std::time::Duration;

use towpath_baselines::{random_gtsp, solve_with, BaselineParams, SolverName};
use towpath_seq::{CostModel, Problem, SolveOptions};

use super::{ms, Args};

/// Header of the table.
const HEADER: &str = "| instance | clusters | nodes | best known | towpath | towpath ms | castelino | castelino ms | castelino / towpath |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";

/// One row: towpath's direct search and castelino, each with `seconds` on one thread.
pub fn row<C: CostModel>(name: &str, p: &Problem<C>, best_known: Option<f64>, seconds: f64) -> anyhow::Result<String> {
    let nodes: usize = p.tasks().map(|t| p.modes(t).len()).sum();
    let opts = SolveOptions {
        time_limit: Some(Duration::from_secs_f64(seconds)),
        threads: 1,
        seed: 1,
        ..SolveOptions::default()
    };
    let params = BaselineParams::default();
    let t = solve_with(SolverName::Towpath, p, &opts, &params)?;
    let c = solve_with(SolverName::Castelino, p, &opts, &params)?;
    Ok(format!(
        "| {name} | {} | {nodes} | {} | {:.0} | {} | {:.0} | {} | {:.4} |\n",
        p.num_tasks(),
        best_known.map_or("–".to_string(), |b| format!("{b:.0}")),
        t.solution.cost,
        ms(t.elapsed.as_secs_f64()),
        c.solution.cost,
        ms(c.elapsed.as_secs_f64()),
        c.solution.cost / t.solution.cost
    ))
}

/// Runs the table and returns its Markdown.
pub fn run(args: &Args) -> anyhow::Result<String> {
    let sizes: &[usize] = if args.quick { &[50] } else { &[100, 200, 400] };
    let seconds = if args.quick { 0.3 } else { args.gtsp_seconds };
    let mut s = String::new();
    s.push_str("### Seed 003: Castelino et al.'s GTSP→TSP transformation vs towpath's direct search\n\n");
    s.push_str(&format!(
        "Instances built in code by `random_gtsp(nodes, seed)` (towpath-baselines): random points in a \
         1000 × 1000 square, `EUC_2D` distances, GTSP-LIB's clustering (⌈n/5⌉ farthest-first centres), closed \
         tour; \"pc\" instances add a one-point depot pinned first and random cluster precedence (PCGTSP-like). \
         `castelino` transforms each to an ATSP of 2n nodes (with depot states for open routes) and solves it \
         with towpath's SOP/TSP search; towpath's solver works on the clusters directly (a cluster is a task, \
         its points the modes). Both get the same {seconds} s limit and one thread, seed 1. GTSP-LIB and \
         PCGLNS files will be added when the formats crate can read them.\n\n"
    ));
    s.push_str(HEADER);
    for &n in sizes {
        for precedence in [false, true] {
            let p = random_gtsp(n, 1, precedence)?;
            let name = format!("{}gtsp-like n{n} s1", if precedence { "pc" } else { "" });
            s.push_str(&row(&name, &p, None, seconds)?);
            eprintln!("seed 003 {name} done");
        }
    }
    s.push('\n');
    Ok(s)
}
