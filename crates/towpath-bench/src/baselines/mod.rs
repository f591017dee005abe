//! `towpath-bench baselines`: the papers' own solvers against towpath's, on the same inputs, in
//! one run. Three tables:
//!
//! 1. Tewolde & Sheng's (2008) comparison (Table I): GA, ACO1 and ACO2 at the paper's settings
//!    and towpath's solver at a short time limit, on generated instances of the ten Table I sizes;
//! 2. Doherty et al.'s (2022) solver against towpath's on AFP-like parts built like the paper's
//!    planar test cases (Figs. 7–10) and on `towpath demo`'s AFP programs: off-part travel saved
//!    from the original order;
//! 3. Castelino et al.'s (2003) transformation (castelino) against towpath's direct search on
//!    GTSP-LIB and PCGLNS files from the benchmark data (`--data` or `TOWPATH_BENCH_DATA`).
//!
//! Every solver runs on one thread, except on the GTSP files (`--gtsp-threads`, both alike).
//! Times are wall times of the solve (shortest paths and model building excluded, they are
//! shared), medians over instances and runs; they are noisy on a shared machine.

mod afp_like;
mod gtsp;
mod rpp;

use std::path::PathBuf;

use anyhow::bail;

use crate::stats::{machine, write_section};

/// Arguments of `towpath-bench baselines`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Generated instances per Table I size.
    #[arg(long, default_value_t = 5)]
    pub seeds: u64,
    /// Runs (solver seeds) per instance for the randomized solvers.
    #[arg(long, default_value_t = 3)]
    pub runs: u64,
    /// towpath's time limits on the Tewolde & Sheng instances, milliseconds (one column each).
    #[arg(long, value_delimiter = ',', default_values_t = [0.8, 2.0, 20.0], allow_negative_numbers = true)]
    pub towpath_ms: Vec<f64>,
    /// A long towpath run per Tewolde & Sheng instance as a reference (best known), milliseconds;
    /// 0 skips it.
    #[arg(long, default_value_t = 500.0, allow_negative_numbers = true)]
    pub reference_ms: f64,
    /// Time limit of both castelino and towpath on each GTSP-LIB / PCGLNS file, seconds.
    #[arg(long, default_value_t = 5.0, allow_negative_numbers = true)]
    pub gtsp_seconds: f64,
    /// Threads of both castelino and towpath on the GTSP-LIB / PCGLNS files.
    #[arg(long, default_value_t = 2)]
    pub gtsp_threads: usize,
    /// The benchmark data directory (with `index.csv`, `gtsp/gtsplib/`, `pcgtsp/`); default: the
    /// environment variable `TOWPATH_BENCH_DATA`.
    #[arg(long, value_name = "DIR")]
    pub data: Option<PathBuf>,
    /// A small, fast run (3 sizes, 2 instances, 1 run) to check the benchmark works.
    #[arg(long)]
    pub quick: bool,
    /// Write the tables into this Markdown file, replacing its section (or appending one).
    #[arg(long, value_name = "FILE")]
    pub write: Option<PathBuf>,
}

/// The heading of this benchmark's section in `BENCHMARKS.md`.
const HEADING: &str = "## Seed baselines: the papers' own solvers against towpath's";

/// Most instances, runs or threads a benchmark takes (each a loop of solves).
const MAX_COUNT: u64 = 10_000;

/// The benchmark data directory: `--data`, else `TOWPATH_BENCH_DATA`; it must hold `index.csv`.
fn data_dir(args: &Args) -> anyhow::Result<PathBuf> {
    let dir = match (&args.data, std::env::var_os("TOWPATH_BENCH_DATA")) {
        (Some(d), _) => d.clone(),
        (None, Some(d)) if !d.is_empty() => PathBuf::from(d),
        _ => bail!(
            "the GTSP table needs the benchmark data: give --data DIR or set TOWPATH_BENCH_DATA to the folder \
             with index.csv, gtsp/gtsplib/ and pcgtsp/"
        ),
    };
    if !dir.join("index.csv").is_file() {
        bail!("{}: not the benchmark data directory (no index.csv in it)", dir.display());
    }
    Ok(dir)
}

/// Refuses budgets that are not durations and counts beyond what a benchmark runs, before any
/// work: a negative or NaN time limit would stop the run half way (or panic in making a
/// `Duration`), a count of 10¹⁸ would never end.
fn check(a: &Args) -> anyhow::Result<()> {
    let time = |flag: &str, seconds: f64| {
        if !(seconds.is_finite() && (0.0..=86_400.0).contains(&seconds)) {
            bail!("{flag}: give a time from 0 to one day, not {seconds}");
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
            bail!("{flag} {n}: too many for a benchmark");
        }
    }
    Ok(())
}

/// Runs the benchmark.
pub fn run(args: Args) -> anyhow::Result<()> {
    check(&args)?;
    let data = data_dir(&args)?;
    let mut md = String::new();
    md.push_str(HEADING);
    md.push_str("\n\n");
    md.push_str(&format!(
        "Measured by `cargo run --release -p towpath-bench -- baselines{}` ({}). Every solver on one thread except where a table \
         says otherwise; times are wall times of the solve, medians over instances and runs, noisy on a \
         shared 2-core machine.\n\n",
        if args.quick { " --quick" } else { "" },
        machine()
    ));
    let section = rpp::run(&args)?;
    print!("{section}");
    md.push_str(&section);
    let section = afp_like::run(&args)?;
    print!("{section}");
    md.push_str(&section);
    let section = gtsp::run(&args, &data)?;
    print!("{section}");
    md.push_str(&section);
    if let Some(path) = &args.write {
        write_section(path, HEADING, &md)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(extra: &[&str]) -> Args {
        Cli::parse_from(std::iter::once("baselines").chain(extra.iter().copied())).args
    }

    #[test]
    fn budgets_are_checked_before_any_work() {
        assert!(check(&parse(&[])).is_ok());
        for bad in [
            &["--towpath-ms", "-1"][..],
            &["--towpath-ms", "1,nan"],
            &["--reference-ms", "1e300"],
            &["--gtsp-seconds", "-2"],
            &["--runs", "1000000000000"],
            &["--gtsp-threads", "100000"],
        ] {
            let e = check(&parse(bad)).expect_err("refused").to_string();
            assert!(e.contains(bad[0]), "{bad:?}: {e}");
        }
    }

    #[test]
    fn the_data_directory_is_given_or_refused_clearly() {
        let e = data_dir(&parse(&["--data", "/nonexistent-towpath-data"])).expect_err("refused").to_string();
        assert!(e.contains("/nonexistent-towpath-data") && e.contains("index.csv"), "{e}");
        let dir = std::env::temp_dir().join(format!("towpath-bench-data-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("index.csv"), "name\n").unwrap();
        assert_eq!(data_dir(&parse(&["--data", dir.to_str().unwrap()])).unwrap(), dir);
    }
}
