//! Fuzzes the TSPLIB-style readers (TSP/ATSP/SOP/GTSP/PCGLNS problems and tours): no input may
//! make them panic, and an accepted problem must be usable (pricing and mapping a route back).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use towpath_seq::{Step, TaskId};

fuzz_target!(|data: &[u8]| {
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
});
