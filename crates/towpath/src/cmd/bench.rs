//! `towpath bench ...`: benchmarks that print tables and write them into `BENCHMARKS.md`.

use super::bench_baselines;
use crate::exit;

/// Arguments of `towpath bench`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

/// The benchmarks.
#[derive(clap::Subcommand, Debug)]
pub enum What {
    /// The seed papers' solvers against towpath's: seed 004's GA/ACO on its sample-data shapes,
    /// seed 000's solver on AFP-like parts, seed 003's transformation on GTSP instances.
    Baselines(bench_baselines::Args),
}

/// Runs a benchmark.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.what {
        What::Baselines(a) => {
            check_baselines(&a)?;
            bench_baselines::run(a)
        }
    }
}

/// Most instances, runs or threads a benchmark takes (each a loop of solves).
const MAX_COUNT: u64 = 10_000;

/// Refuses (exit code 2) budgets that are not durations and counts beyond what a benchmark runs,
/// before any work: a negative or NaN time limit would stop the run half way, a count of 10¹⁸
/// would never end.
fn check_baselines(a: &bench_baselines::Args) -> anyhow::Result<()> {
    let time = |flag: &str, seconds: f64| {
        if !(seconds.is_finite() && (0.0..=86_400.0).contains(&seconds)) {
            return Err(exit::bad_input(anyhow::anyhow!("{flag}: give a time from 0 to one day, not {seconds}")));
        }
        Ok(())
    };
    for &ms in &a.towpath_ms {
        time("--towpath-ms", ms / 1e3)?;
    }
    time("--reference-ms", a.reference_ms / 1e3)?;
    time("--gtsp-seconds", a.gtsp_seconds)?;
    for (flag, n) in [("--seeds", a.seeds), ("--runs", a.runs), ("--gtsp-threads", a.gtsp_threads as u64)] {
        if n > MAX_COUNT || (flag == "--gtsp-threads" && n as usize > towpath_seq::MAX_THREADS) {
            return Err(exit::bad_input(anyhow::anyhow!("{flag} {n}: too many for a benchmark")));
        }
    }
    Ok(())
}
