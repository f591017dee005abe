//! `towpath-bench`: towpath's benchmark harnesses, kept out of the shipped `towpath` binary.
//!
//! ```text
//! cargo run --release -p towpath-bench -- baselines [--quick] [--data DIR] [--write BENCHMARKS.md]
//! cargo run --release -p towpath-bench -- afp [--runs N] [--write BENCHMARKS.md]
//! cargo run --release -p towpath-bench -- layup [OUT_DIR] [--repeats N]
//! cargo run --release -p towpath-bench -- motion [--runs N] [--write BENCHMARKS.md]
//! ```
//!
//! `baselines` runs the papers' own solvers (Doherty et al. 2022, Castelino et al. 2003, Tewolde
//! & Sheng 2008) against towpath's; `afp` the AFP programs of `towpath demo` and a 10,000-course
//! panel; `layup` the course-tracing accuracy study that `bench/layup.py` compares with
//! potpourri3d; `motion` the motion-safety figures (transits straight, planned or over a fixed
//! clearance; a 10,000-course panel with its tool; checking speed on a 1,000,000-triangle mold). The benchmark data directory (GTSP-LIB, PCGLNS) comes from `--data` or the
//! environment variable `TOWPATH_BENCH_DATA`; `TOWPATH_BENCH_MACHINE` names the CPU in captions.

mod afp;
mod baselines;
mod layup;
mod motion;
mod motion_speed;
mod stats;

use clap::{Parser, Subcommand};

/// towpath's benchmarks: print Markdown tables and, with --write, put them into BENCHMARKS.md.
#[derive(Parser, Debug)]
#[command(name = "towpath-bench", version)]
struct Cli {
    #[command(subcommand)]
    which: Which,
}

#[derive(Subcommand, Debug)]
enum Which {
    /// The papers' solvers against towpath's: Tewolde & Sheng's GA/ACO on their sample-data
    /// shapes, Doherty et al.'s solver on AFP-like parts, Castelino et al.'s transformation on
    /// GTSP instances.
    Baselines(baselines::Args),
    /// AFP programs: the demo parts and a large panel optimized and verified, beside Doherty et
    /// al.'s solver.
    Afp(afp::Args),
    /// Course tracing accuracy and speed (the driver of bench/layup.py).
    Layup(layup::Args),
    /// Motion safety: transits straight, planned or over a fixed clearance; a large panel in
    /// its cell; checking speed.
    Motion(motion::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.which {
        Which::Baselines(a) => baselines::run(a),
        Which::Afp(a) => afp::run(a),
        Which::Layup(a) => layup::run(a),
        Which::Motion(a) => motion::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::from(2)
        }
    }
}
