//! End-to-end tests on the built-in demo parts: parse, optimize, rewrite, verify.

use std::time::Duration;

use towpath_machine::CostKind;
use towpath_nc::demo::{demo_parts, TOW_WIDTH};
use towpath_nc::{optimize, parse, rewrite, AfpOptions, Dialect, OptimizeOptions, Placement, Width};

/// The machine as Doherty et al. (2022) model it: weights, no velocities, so no time model and
/// no cycle-time guard (with velocities, `optimize` keeps the input order when the order of
/// least axis distance is slower, which `tests/cycle_time.rs` checks).
fn paper_machine(m: &towpath_machine::Machine) -> towpath_machine::Machine {
    let mut m = m.clone();
    for a in &mut m.axes {
        a.max_velocity = None;
        a.max_acceleration = None;
    }
    m
}

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
                time_limit: None,
                iterations: Some(300),
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
            // The parts are planned badly on purpose (plies out of order, every course the same
            // way): laid both ways, a real saving of the axis distance, unless the order found
            // would take longer than the input (the cycle-time guard then keeps the input, and
            // says by how much).
            match o.fallback {
                Some(towpath_nc::Fallback::CycleTime { before, after }) => {
                    assert!(o.text == part.program && after > before, "{}: {before} -> {after}", part.name)
                }
                Some(f) => panic!("{}: {f}", part.name),
                None if bidirectional => {
                    assert!(a.off_part() < 0.9 * b.off_part(), "{}: {} -> {}", part.name, b.off_part(), a.off_part())
                }
                None => {}
            }
        }
    }
}

/// Doherty et al.'s solver through `optimize`, on their machine model (without velocities):
/// it runs per precedence set (every course of a set is laid before any course of the next),
/// its answer is written and verified like towpath's, saves off-part motion on the badly
/// planned parts, and never costs more.
#[test]
fn doherty_sequences_the_demo_parts_set_by_set() {
    use towpath_nc::{doherty_sets, PrecedenceRule, SolverName};
    let d = Dialect::default();
    for part in demo_parts() {
        for precedence in [PrecedenceRule::Courses, PrecedenceRule::Sets, PrecedenceRule::Plies] {
            let afp = AfpOptions {
                cost: CostKind::Axis,
                bidirectional: true,
                precedence,
                width: Some(Width::Tow(TOW_WIDTH)),
                ..AfpOptions::default()
            };
            let opts = OptimizeOptions {
                afp: afp.clone(),
                time_limit: Some(Duration::from_secs(10)),
                threads: 1,
                solver: SolverName::Doherty,
                ..OptimizeOptions::default()
            };
            let machine = paper_machine(&part.machine);
            let o = optimize(&part.program, &machine, &d, &opts).unwrap();
            assert_eq!(o.solver.solver, "doherty");
            let (b, a) = o.verification.motion(CostKind::Axis).unwrap();
            assert!(a.off_part() <= b.off_part() + 1e-6, "{} {precedence}", part.name);
            assert!(
                a.off_part() < 0.9 * b.off_part(),
                "{} {precedence}: {} -> {}",
                part.name,
                b.off_part(),
                a.off_part()
            );
            // Set by set, in order.
            let sets = doherty_sets(&o.program, &o.afp, &afp).unwrap();
            let mut set_of = vec![usize::MAX; o.program.courses.len()];
            for (k, s) in sets.iter().enumerate() {
                for t in &s.tasks {
                    set_of[t.index()] = k;
                }
            }
            assert!(set_of.iter().all(|&k| k != usize::MAX), "{}: the sets cover every course", part.name);
            let laid: Vec<usize> = o.order.iter().map(|p| set_of[p.course]).collect();
            assert!(laid.windows(2).all(|w| w[0] <= w[1]), "{} {precedence}: sets out of order {laid:?}", part.name);
        }
    }
}

#[test]
fn doherty_refuses_to_keep_the_ply_order() {
    use towpath_nc::{NcError, SolverName};
    let d = Dialect::default();
    let part = &demo_parts()[0];
    let opts = OptimizeOptions {
        afp: AfpOptions { keep_ply_order: true, width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() },
        solver: SolverName::Doherty,
        ..OptimizeOptions::default()
    };
    match optimize(&part.program, &part.machine, &d, &opts) {
        Err(e @ NcError::DohertyKeepsNoPlyOrder) => assert!(e.to_string().contains("within each ply"), "{e}"),
        other => panic!("expected a solver error, got {:?}", other.map(|o| o.solver)),
    }
}

/// The target "off-part saving at least seed 000's on every analogous part": on each
/// demo part with a published seed-000 figure, the off-part saving in seed 000's weighted axis
/// distance, measured by the verifier on the written program (moves between precedence sets
/// counted, which seed 000 leaves out), is at least the paper's. A work budget, not a time
/// limit, so the outcome does not depend on the machine's load.
#[test]
fn demo_parts_save_at_least_seed_000_s_published_off_part_share() {
    let d = Dialect::default();
    let mut compared = 0;
    for part in demo_parts() {
        let Some((figure, seed_off, _)) = part.seed.filter(|s| s.1.is_finite()) else { continue };
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(300),
            threads: 1,
            ..OptimizeOptions::default()
        };
        let o = optimize(&part.program, &paper_machine(&part.machine), &d, &opts).unwrap();
        let (b, a) = o.verification.motion(CostKind::Axis).unwrap();
        let saved = 100.0 * (1.0 - a.off_part() / b.off_part());
        eprintln!("{} ({figure}): towpath saves {saved:.1} %, seed 000 {seed_off:.1} %", part.name);
        assert!(saved >= seed_off, "{} ({figure}): towpath saves {saved:.1} %, seed 000 {seed_off:.1} %", part.name);
        compared += 1;
    }
    assert!(compared >= 6, "{compared} parts with a seed-000 figure");
}

/// Front ends follow a run by its stages and stop it with the cancel flag: the stages come in
/// order with the input's route cost, a flag set before the run stops it with `Cancelled`, and a
/// flag set while the solver runs (here from the first progress report) stops it too.
#[test]
fn optimize_reports_its_stages_and_stops_when_cancelled() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Arc, Mutex};
    use towpath_nc::{NcError, Stage};
    let d = Dialect::default();
    let part = &demo_parts()[0];
    let stages = Arc::new(Mutex::new(Vec::new()));
    let seen = stages.clone();
    let opts = OptimizeOptions {
        afp: AfpOptions { width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() },
        time_limit: None,
        iterations: Some(100),
        threads: 1,
        stage: Some(Arc::new(move |s: Stage| seen.lock().unwrap().push(s))),
        ..OptimizeOptions::default()
    };
    let o = optimize(&part.program, &part.machine, &d, &opts).unwrap();
    let stages = stages.lock().unwrap().clone();
    let labels: Vec<&str> = stages.iter().map(Stage::label).collect();
    assert_eq!(
        labels,
        ["parsing", "checking limits and the cell", "building the problem", "solving", "writing and verifying"]
    );
    let Stage::Solving { initial_cost: Some(initial) } = stages[3] else { panic!("{stages:?}") };
    assert!((initial - o.solver.initial_cost).abs() <= 1e-9 * initial, "{initial} vs {}", o.solver.initial_cost);
    // Cancelled before it starts.
    let cancel = Arc::new(AtomicBool::new(true));
    let opts = OptimizeOptions { cancel: Some(cancel.clone()), stage: None, ..opts };
    assert!(matches!(optimize(&part.program, &part.machine, &d, &opts), Err(NcError::Cancelled)));
    // Cancelled while solving, under a budget it would otherwise take a long time to spend.
    cancel.store(false, Ordering::Relaxed);
    let flag = cancel.clone();
    let opts = OptimizeOptions {
        iterations: None,
        time_limit: Some(Duration::from_secs(600)),
        progress: Some(Arc::new(move |_: &towpath_seq::Progress| flag.store(true, Ordering::Relaxed))),
        ..opts
    };
    let t0 = std::time::Instant::now();
    assert!(matches!(optimize(&part.program, &part.machine, &d, &opts), Err(NcError::Cancelled)));
    // The first report comes within half a second, from the branch and bound on the
    // assignment if it runs, else from the first epoch of kicks (at most 2 s).
    assert!(t0.elapsed() < Duration::from_secs(20), "{:?}", t0.elapsed());
}
