//! Fuzzes the TSPLIB-style readers (TSP/ATSP/SOP/GTSP/PCGLNS problems and tours): no input may
//! make them panic, and an accepted problem must be usable (pricing and mapping a route back).
//!
//! The body of the `tsplib` fuzz target: run by cargo-fuzz (`fuzz_targets/tsplib.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use std::path::Path;
use towpath_seq::{Step, TaskId};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let _ = towpath_formats::parse_tour(&text, Path::new("fuzz.tour"));
    if let Ok(inst) = towpath_formats::parse_tsplib(&text, Path::new("fuzz.tsp")) {
        let steps: Vec<Step> = (0..inst.num_tasks() as u32).map(|t| Step { task: TaskId(t), mode: 0 }).collect();
        let _ = inst.problem.check(&steps);
        let answer = inst.answer(&steps);
        if let towpath_formats::Answer::Nodes(nodes) = answer {
            let _ = inst.steps_from_nodes(&nodes);
        }
    }
}
