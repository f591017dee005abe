//! End-to-end tests on the built-in demo parts: parse, optimize, rewrite, verify.

use std::time::Duration;

use towpath_machine::CostKind;
use towpath_nc::demo::{demo_parts, TOW_WIDTH};
use towpath_nc::{optimize, parse, rewrite, AfpOptions, Dialect, OptimizeOptions, Placement, Width};

#[test]
fn demo_parts_round_trip_exactly() {
    let d = Dialect::default();
    for part in demo_parts() {
        let p = parse(&part.program, &part.machine, &d).unwrap();
        let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        let out = rewrite(&p, &order, &part.machine, &d, &[]).unwrap();
        assert_eq!(out, part.program, "{}", part.name);
    }
}

#[test]
fn demo_parts_optimize_and_verify() {
    let d = Dialect::default();
    for part in demo_parts() {
        for bidirectional in [false, true] {
            let opts = OptimizeOptions {
                afp: AfpOptions {
                    cost: CostKind::Axis,
                    bidirectional,
                    width: Some(Width::Tow(TOW_WIDTH)),
                    ..AfpOptions::default()
                },
                time_limit: Some(Duration::from_millis(300)),
                threads: 1,
                ..OptimizeOptions::default()
            };
            let o = optimize(&part.program, &part.machine, &d, &opts).unwrap();
            let (b, a) = o.verification.motion(CostKind::Axis).unwrap();
            eprintln!(
                "{} bi={bidirectional}: off {:.0} -> {:.0} ({:.1} %), reversed {}",
                part.name,
                b.off_part(),
                a.off_part(),
                100.0 * (1.0 - a.off_part() / b.off_part()),
                o.verification.reversed
            );
            assert!(a.off_part() <= b.off_part() + 1e-6);
        }
    }
}
