//! Fuzzes the JSON problem reader: no input may make it panic, an accepted problem must be
//! usable, and what it accepts must survive a write/read round trip unchanged.
//!
//! The body of the `json` fuzz target: run by cargo-fuzz (`fuzz_targets/json.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use std::path::Path;
use towpath_seq::{Step, TaskId};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(problem) = towpath_formats::parse_json_problem(&text, Path::new("fuzz.json")) else { return };
    let again = towpath_formats::write_json(&problem);
    let back = towpath_formats::parse_json_problem(&again, Path::new("again.json"));
    assert_eq!(back.ok().as_ref(), Some(&problem), "write/read round trip changed the problem");
    if let Ok(inst) = problem.to_instance(&text, Path::new("fuzz.json")) {
        let steps: Vec<Step> = (0..inst.num_tasks() as u32).map(|t| Step { task: TaskId(t), mode: 0 }).collect();
        let _ = inst.problem.check(&steps);
        let _ = inst.answer(&steps);
    }
}
