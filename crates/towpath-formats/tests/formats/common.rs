//! Shared helpers: fixture paths and the published optima of the fixtures.

use std::path::PathBuf;

use towpath_formats::{read_instance, with_problem, Instance};
use towpath_seq::{SolveOptions, SolveReport};

/// Path of a fixture under `tests/data`.
pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// Reads a fixture, panicking with the reader's message if it is refused.
pub fn load(name: &str) -> Instance {
    read_instance(&data(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// The published value of an instance from `tests/data/optima.csv` (a copy of the benchmark
/// index rows for the fixtures): (value, status).
pub fn published(name: &str, kind: &str) -> (f64, String) {
    let text = std::fs::read_to_string(data("optima.csv")).unwrap();
    for row in text.lines().skip(1) {
        let cols: Vec<&str> = row.splitn(6, ',').collect();
        if cols[0] == name && cols[1] == kind {
            return (cols[3].parse().unwrap(), cols[4].trim_matches('"').to_string());
        }
    }
    panic!("{name} ({kind}) is not in optima.csv");
}

/// The optimum of an instance; panics if the published value is only a bound.
pub fn optimum(name: &str, kind: &str) -> f64 {
    let (v, status) = published(name, kind);
    assert!(status.starts_with("optimal"), "{name}: {status}");
    v
}

/// Solves with a deterministic work budget on one thread.
pub fn solve(inst: &Instance, iterations: u64, seed: u64) -> SolveReport {
    let opts =
        SolveOptions { time_limit: None, iterations: Some(iterations), seed, threads: 1, ..SolveOptions::default() };
    with_problem!(&inst.problem, p => towpath_seq::solve(p, &opts)).unwrap()
}
