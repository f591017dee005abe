//! `towpath bench baselines`: the seed papers' own solvers against towpath's, on the same
//! inputs, in one run. Three tables:
//!
//! 1. seed 004's comparison (Table I): GA, ACO1 and ACO2 at the paper's settings and towpath's
//!    solver at a short time limit, on generated instances of the ten Table I sizes;
//! 2. seed 000's solver against towpath's on AFP-like parts built like the paper's planar test
//!    cases (Figs. 7–10) and on `towpath demo`'s AFP programs: off-part travel saved from the
//!    original order;
//! 3. seed 003's transformation (castelino) against towpath's direct search on GTSP-LIB and
//!    PCGLNS files from the benchmark data (`--data`).
//!
//! Every solver runs on one thread, except on the GTSP files (`--gtsp-threads`, both alike).
//! Times are wall times of the solve (shortest paths and model building excluded, they are
//! shared), medians over instances and runs; they are noisy on
//! a shared machine.

mod afp_like;
mod gtsp;
mod rpp;

use std::path::PathBuf;

use anyhow::Context;

/// Arguments of `towpath bench baselines`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Generated instances per Table I size.
    #[arg(long, default_value_t = 5)]
    pub seeds: u64,
    /// Runs (solver seeds) per instance for the randomized solvers.
    #[arg(long, default_value_t = 3)]
    pub runs: u64,
    /// towpath's time limits on the seed-004 instances, milliseconds (one column each).
    #[arg(long, value_delimiter = ',', default_values_t = [0.8, 2.0, 20.0])]
    pub towpath_ms: Vec<f64>,
    /// A long towpath run per seed-004 instance as a reference (best known), milliseconds; 0 skips it.
    #[arg(long, default_value_t = 500.0)]
    pub reference_ms: f64,
    /// Time limit of both castelino and towpath on each GTSP-LIB / PCGLNS file, seconds.
    #[arg(long, default_value_t = 5.0)]
    pub gtsp_seconds: f64,
    /// Threads of both castelino and towpath on the GTSP-LIB / PCGLNS files.
    #[arg(long, default_value_t = 2)]
    pub gtsp_threads: usize,
    /// The benchmark data directory (with `index.csv`, `gtsp/gtsplib/`, `pcgtsp/`).
    #[arg(long, value_name = "DIR", default_value = "/work/shared/data")]
    pub data: PathBuf,
    /// A small, fast run (3 sizes, 2 instances, 1 run) to check the benchmark works.
    #[arg(long)]
    pub quick: bool,
    /// Write the tables into this Markdown file, replacing its "Seed baselines" section (or
    /// appending one).
    #[arg(long, value_name = "FILE")]
    pub write: Option<PathBuf>,
}

/// The heading of this benchmark's section in `BENCHMARKS.md`.
const HEADING: &str = "## Seed baselines: the papers' own solvers against towpath's";

/// Runs the benchmark.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut md = String::new();
    md.push_str(HEADING);
    md.push_str("\n\n");
    md.push_str(&format!(
        "Measured by `towpath bench baselines{}` ({}). Every solver on one thread except where a table \
         says otherwise; times are wall times of the solve, medians over instances and runs, noisy on a \
         shared 2-core machine.\n\n",
        if args.quick { " --quick" } else { "" },
        machine()
    ));
    let section = rpp::run(&args)?;
    crate::out!("{section}");
    md.push_str(&section);
    let section = afp_like::run(&args)?;
    crate::out!("{section}");
    md.push_str(&section);
    let section = gtsp::run(&args)?;
    crate::out!("{section}");
    md.push_str(&section);
    if let Some(path) = &args.write {
        let old = std::fs::read_to_string(path).unwrap_or_default();
        let new = replace_section(&old, &md);
        std::fs::write(path, new).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("tables written to {}", path.display());
    }
    Ok(())
}

/// Replaces the section that starts with [`HEADING`] (up to the next `## ` heading) by
/// `section`, or appends it.
fn replace_section(old: &str, section: &str) -> String {
    let body = section.trim_end();
    let Some(start) = old.find(HEADING) else {
        let pre = old.trim_end();
        let pre = if pre.is_empty() { "# Benchmarks".to_string() } else { pre.to_string() };
        return format!("{pre}\n\n{body}\n");
    };
    let after = start + HEADING.len();
    match old[after..].find("\n## ") {
        Some(k) => format!("{}{body}\n\n{}", &old[..start], &old[after + k + 1..]),
        None => format!("{}{body}\n", &old[..start]),
    }
}

/// A one-line description of the machine.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{cpu}, {cores} cores visible")
}

/// The median of the values (NaN if none).
pub(crate) fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let k = s.len();
    if k % 2 == 1 {
        s[k / 2]
    } else {
        0.5 * (s[k / 2 - 1] + s[k / 2])
    }
}

/// Milliseconds, with a precision that suits the value.
pub(crate) fn ms(seconds: f64) -> String {
    let m = seconds * 1e3;
    if m < 1.0 {
        format!("{m:.2}")
    } else if m < 100.0 {
        format!("{m:.1}")
    } else {
        format!("{m:.0}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_replaced_or_appended() {
        let sec = format!("{HEADING}\n\nnew\n\n");
        assert_eq!(replace_section("", &sec), format!("# Benchmarks\n\n{HEADING}\n\nnew\n"));
        let old = format!("# B\n\n## Other\n\nx\n\n{HEADING}\n\nold\n\n## Later\n\ny\n");
        assert_eq!(replace_section(&old, &sec), format!("# B\n\n## Other\n\nx\n\n{HEADING}\n\nnew\n\n## Later\n\ny\n"));
        let old = format!("# B\n\n{HEADING}\n\nold\n");
        assert_eq!(replace_section(&old, &sec), format!("# B\n\n{HEADING}\n\nnew\n"));
        let old = "# B\n\n## Other\n\nx\n";
        assert_eq!(replace_section(old, &sec), format!("# B\n\n## Other\n\nx\n\n{HEADING}\n\nnew\n"));
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
