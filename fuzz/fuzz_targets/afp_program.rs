//! Fuzzes the AFP program parser: any text is either refused with an error or parsed into a
//! program that writes back byte for byte, whose courses can be reversed or refused, never a
//! panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use towpath_machine::{Axis, AxisKind, Machine};
use towpath_nc::{parse, reverse_course, rewrite, Dialect, Placement};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    let mut a = Axis::new("A", AxisKind::Mandrel);
    a.weight = 2.0;
    let Ok(machine) = Machine::new(
        "fuzz",
        vec![Axis::new("X", AxisKind::Linear), Axis::new("Y", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), c, a],
    ) else {
        return;
    };
    let dialect = Dialect::default();
    if let Ok(p) = parse(&text, &machine, &dialect) {
        let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        let out = rewrite(&p, &order, &machine, &dialect, &[]).expect("the original order always writes");
        assert_eq!(out, text);
        let reversed: Vec<_> = (0..p.courses.len()).map(|c| reverse_course(&p, c, &machine, &dialect).ok()).collect();
        let order: Vec<Placement> =
            (0..p.courses.len()).rev().map(|c| Placement { course: c, reversed: reversed[c].is_some() }).collect();
        let _ = rewrite(&p, &order, &machine, &dialect, &reversed);
    }
});
