//! Cycle time first: with velocities in the machine file the default cost is time, and
//! whatever the cost, `optimize` never returns a program whose cycle time (the verifier's time
//! model, measured again here from the two texts) is longer than the input's.

use towpath_machine::{Axis, AxisKind, CostKind, Machine};
use towpath_nc::demo::{demo_parts, TOW_WIDTH};
use towpath_nc::{
    default_cost, optimize, parse, rewrite, verify, AfpOptions, Dialect, Fallback, OptimizeOptions, Placement,
    VerifyOptions, Width,
};

/// Cycle time (total, s) of `text` against `original`, by an independent verification.
fn cycle_times(original: &str, text: &str, machine: &Machine, d: &Dialect, w: Option<Width>) -> (f64, f64, f64, f64) {
    let v = verify(original, text, machine, d, &VerifyOptions { width: w, ..VerifyOptions::default() }).unwrap();
    let (b, a) = v.motion(CostKind::Time).expect("the machine has velocities");
    (b.total(), a.total(), b.off_part(), a.off_part())
}

/// The demo parts' machines have velocities: the default cost is time, and the default run's
/// cycle time, measured by `verify` on the written text, is never longer than the input's.
#[test]
fn demo_parts_default_run_is_never_slower() {
    let d = Dialect::default();
    for part in demo_parts() {
        assert_eq!(default_cost(&part.machine), CostKind::Time, "{}", part.name);
        let mut afp = AfpOptions::for_machine(&part.machine);
        afp.bidirectional = true;
        afp.width = Some(Width::Tow(TOW_WIDTH));
        let opts = OptimizeOptions { afp, time_limit: None, iterations: Some(150), threads: 1, ..Default::default() };
        let o = optimize(&part.program, &part.machine, &d, &opts).unwrap();
        let (before, after, off_before, off_after) =
            cycle_times(&part.program, &o.text, &part.machine, &d, Some(Width::Tow(TOW_WIDTH)));
        eprintln!(
            "{}: cycle {before:.1} -> {after:.1} s, off-part {off_before:.1} -> {off_after:.1} s, fallback {:?}",
            part.name, o.fallback
        );
        assert!(after <= before * (1.0 + 1e-9), "{}: cycle time {before} -> {after}", part.name);
        assert!(
            off_after <= off_before * (1.0 + 1e-9) + 1e-9,
            "{}: off-part time {off_before} -> {off_after}",
            part.name
        );
    }
}

/// A gantry whose X axis is cheap in Doherty et al.'s weights but slow, Y dear but fast.
fn slow_x_gantry() -> Machine {
    let mut axes = vec![
        Axis::new("X", AxisKind::Linear),
        Axis::new("Y", AxisKind::Linear),
        Axis::new("Z", AxisKind::Linear),
        Axis::new("C", AxisKind::Continuous),
    ];
    axes[0].weight = 0.01;
    axes[3].heading = true;
    for (a, v) in axes.iter_mut().zip([10.0, 1000.0, 1000.0, 1000.0]) {
        a.max_velocity = Some(v);
        a.max_acceleration = Some(5000.0);
    }
    Machine::new("slow x", axes).unwrap()
}

/// One course along +Y from (x, y) to (x, y + 20).
fn course(n: usize, x: f64, y: f64) -> String {
    format!(
        "(COURSE {n})\nG0 X{x} Y{y} Z20 C90\nG1 Z0 F1000\nM20\nM60 P15\nG1 Y{} F3000\nM61 P15\nM21\nG1 Z20\n",
        y + 20.0
    )
}

/// Four courses at the corners of a 200 × 300 mm rectangle, in the order that moves X once:
/// (0,0), (0,300), (200,300), (200,0).
fn slow_x_program() -> String {
    let mut s = String::from("%\nG21 G90\nG0 Z100\n(PLY 1)\n");
    for (n, (x, y)) in [(0.0, 0.0), (0.0, 300.0), (200.0, 300.0), (200.0, 0.0)].into_iter().enumerate() {
        s.push_str(&course(n + 1, x, y));
    }
    s.push_str("G0 Z100\nM30\n%\n");
    s
}

/// On a machine where the order of least weighted axis distance is slower: that order (checked
/// by hand through `rewrite` and `verify`) costs less axis distance and more time than the
/// input; optimizing the axis distance then keeps the input order (saying why) rather than
/// return the slower program, and optimizing time returns a program no slower than the input.
#[test]
fn axis_optimal_but_slower_is_never_returned() {
    let m = slow_x_gantry();
    let d = Dialect::default();
    let text = slow_x_program();
    let p = parse(&text, &m, &d).unwrap();
    // X moves twice (2 weighted mm each) instead of Y twice (300 each).
    let axis_order: Vec<Placement> = [0, 3, 2, 1].map(|course| Placement { course, reversed: false }).to_vec();
    let axis_text = rewrite(&p, &axis_order, &m, &d, &[]).unwrap();
    let v = verify(&text, &axis_text, &m, &d, &VerifyOptions::default()).unwrap();
    let (ab, aa) = v.motion(CostKind::Axis).unwrap();
    let (tb, ta) = v.motion(CostKind::Time).unwrap();
    assert!(aa.off_part() < ab.off_part() - 200.0, "axis {} -> {}", ab.off_part(), aa.off_part());
    assert!(ta.total() > tb.total() + 10.0, "time {} -> {}", tb.total(), ta.total());

    for cost in [CostKind::Axis, CostKind::Time, CostKind::Tool] {
        let opts = OptimizeOptions {
            afp: AfpOptions { cost, ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(200),
            threads: 1,
            ..Default::default()
        };
        let o = optimize(&text, &m, &d, &opts).unwrap();
        let (before, after, ..) = cycle_times(&text, &o.text, &m, &d, None);
        assert!(after <= before * (1.0 + 1e-9), "{cost}: cycle time {before} -> {after}");
        if cost == CostKind::Axis {
            // The solver finds the cheaper, slower order; the guard refuses it.
            match o.fallback {
                Some(Fallback::CycleTime { before: b, after: a }) => {
                    assert!(a > b + 10.0, "{b} -> {a}");
                    assert!((b - before).abs() < 1e-6, "the guard's figure is the verifier's");
                }
                other => panic!("expected a cycle-time fallback, got {other:?}"),
            }
            assert!(o.fell_back);
            assert_eq!(o.text, text);
            assert!(o.fallback.unwrap().to_string().contains("the input order is kept"));
        }
    }
}

/// Without velocities there is no time model: the default cost is Doherty et al.'s axis distance.
#[test]
fn default_cost_without_velocities_is_axis_distance() {
    let mut m = slow_x_gantry();
    assert_eq!(default_cost(&m), CostKind::Time);
    m.axes[1].max_velocity = None;
    assert_eq!(default_cost(&m), CostKind::Axis);
    assert_eq!(AfpOptions::for_machine(&m).cost, CostKind::Axis);
}
