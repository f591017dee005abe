//! Fuzzes the AFP program parser: any text is either refused with an error or parsed into a
//! program that writes back byte for byte, whose courses can be reversed or refused, and whose
//! rewrite in reverse order (reversing what can be) verifies against it; never a panic.
//!
//! The body of the `afp_program` fuzz target: run by cargo-fuzz (`fuzz_targets/afp_program.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use towpath_machine::{Axis, AxisKind, Machine};
use towpath_nc::{parse, reverse_course, rewrite, verify, Dialect, Placement, VerifyError, VerifyOptions};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    let mut a = Axis::new("A", AxisKind::Mandrel);
    a.weight = 2.0;
    let Ok(machine) = Machine::new(
        "fuzz",
        vec![
            Axis::new("X", AxisKind::Linear),
            Axis::new("Y", AxisKind::Linear),
            Axis::new("Z", AxisKind::Linear),
            c,
            a,
        ],
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
        // Any order writes a program the verifier reads back as the same courses, each forward
        // or legally reversed, with every kept line: only precedence may fail (no width here).
        if let Ok(out) = rewrite(&p, &order, &machine, &dialect, &reversed) {
            match verify(&text, &out, &machine, &dialect, &VerifyOptions::default()) {
                Ok(_) | Err(VerifyError::Setup(_) | VerifyError::Precedence { .. } | VerifyError::Order(_)) => {}
                Err(e) => panic!("the rewritten program does not verify: {e}\n{out}"),
            }
        }
    }
}
