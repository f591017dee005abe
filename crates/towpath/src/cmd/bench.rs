//! `towpath bench ...`: benchmarks that print tables and write them into `BENCHMARKS.md`.

use super::bench_baselines;

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
        What::Baselines(a) => bench_baselines::run(a),
    }
}
