//! Fuzzes `Instance::to_json` (what `towpath convert` writes): any problem a reader accepts,
//! written as towpath JSON (points or matrix) and read back, must be accepted again with the same
//! tasks and give the same checker verdict and cost for a route.
//!
//! The body of the `convert` fuzz target: run by cargo-fuzz (`fuzz_targets/convert.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use std::path::Path;
use towpath_formats::{parse_instance, parse_json, write_json, CostsAs};
use towpath_seq::{Step, TaskId};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(inst) = parse_instance(&text, Path::new("fuzz.tsp")) else { return };
    let steps: Vec<Step> = (0..inst.num_tasks() as u32).map(|t| Step { task: TaskId(t), mode: 0 }).collect();
    let expected = inst.problem.check(&steps);
    let small = inst.problem.num_states() <= 300;
    for costs in [CostsAs::Native, CostsAs::Matrix] {
        if costs == CostsAs::Matrix && !small {
            continue;
        }
        let Ok(problem) = inst.to_json(costs) else { continue };
        let json = write_json(&problem);
        let back = parse_json(&json, Path::new("converted.json"))
            .unwrap_or_else(|e| panic!("a converted problem was refused: {e}\n{json}"));
        assert_eq!(back.num_tasks(), inst.num_tasks());
        assert_eq!(back.problem.check(&steps).ok(), expected.clone().ok(), "{costs:?}");
    }
}
