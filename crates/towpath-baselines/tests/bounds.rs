//! Sizes taken on trust: every parameter and problem size that sets how much a baseline
//! allocates or must do before it can stop is checked first, and refused with what it would take
//! (a test that aborts or runs for minutes fails). The time limit also stops the work inside a
//! generation or a cycle.

use std::time::{Duration, Instant};

use towpath_baselines::*;
use towpath_seq::*;

/// `n` point tasks on a line, at `n / share` distinct places (tasks share states).
fn line(n: usize, share: usize) -> Problem<PointCost> {
    let places = (n / share.max(1)).max(1);
    let pts: Vec<[f64; 3]> = (0..places).map(|i| [i as f64, 0.0, 0.0]).collect();
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    for t in 0..n {
        b.task(vec![Mode::point(StateId((t % places) as u32))]);
    }
    b.build().unwrap()
}

fn opts() -> SolveOptions {
    SolveOptions { time_limit: Some(Duration::from_secs(30)), threads: 1, ..SolveOptions::default() }
}

#[test]
fn a_population_too_large_for_memory_is_refused_before_it_is_made() {
    let p = line(48, 1);
    let params = BaselineParams {
        ga: GaParams { population: 4_000_000_000, ..GaParams::default() },
        ..BaselineParams::default()
    };
    let t0 = Instant::now();
    let e = solve_with(SolverName::Ga, &p, &opts(), &params).unwrap_err();
    assert!(t0.elapsed() < Duration::from_secs(1));
    let BaselineError::TooMuch { param, message } = &e else { panic!("{e}") };
    assert_eq!(*param, "ga.population");
    assert!(message.contains("4000000000") && message.contains("at most"), "{message}");
    // The largest population the message offers is accepted (it fits the memory budget).
    let most: usize = message.rsplit("up to ").next().unwrap().split(' ').next().unwrap().parse().unwrap();
    let bytes = most as f64 * 1.2 * (64.0 + 8.0 * 48.0);
    assert!(bytes <= GA_MAX_BYTES as f64 && bytes * 1.01 > GA_MAX_BYTES as f64, "{most}");
    for rate in [f64::NAN, -1.0, 1e300] {
        let params = BaselineParams { ga: GaParams { crossover_rate: rate, ..GaParams::default() }, ..params.clone() };
        assert!(matches!(solve_with(SolverName::Ga, &p, &opts(), &params), Err(BaselineError::BadParams(_))));
    }
}

#[test]
fn ants_and_walks_are_bounded() {
    let p = line(30, 1);
    let params = BaselineParams {
        aco: AcoParams { ants_per_task: 1_000_000_000_000, ..AcoParams::default() },
        ..BaselineParams::default()
    };
    let e = solve_aco(&p, &params.aco, &opts()).unwrap_err();
    assert!(matches!(e, BaselineError::TooMuch { param: "aco.ants_per_task", .. }), "{e}");
    // 12,000 tasks on 1,000 places: few states, but each walk weighs 12,000 × 24,000 moves.
    let p = line(12_000, 12);
    let e = solve_with(SolverName::Aco1, &p, &opts(), &BaselineParams::default()).unwrap_err();
    assert!(matches!(e, BaselineError::TooLarge { solver: SolverName::Aco1, .. }), "{e}");
    assert!(e.to_string().contains(&ACO_MAX_WALK.to_string()), "{e}");
}

#[test]
fn the_seed_pool_and_the_decoder_refuse_passes_they_cannot_finish() {
    // One precedence set of 40,000 courses: a nearest-neighbour pass weighs 1.6e9 moves.
    let p = line(40_000, 1);
    let e = solve_with(SolverName::Doherty, &p, &opts(), &BaselineParams::default()).unwrap_err();
    assert!(matches!(e, BaselineError::TooLarge { solver: SolverName::Doherty, .. }), "{e}");
    // The GA decodes freely without precedence, but not with it.
    let pts: Vec<[f64; 3]> = (0..30_000).map(|i| [i as f64, 0.0, 0.0]).collect();
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    b.point_tasks(30_000).precede(TaskId(0), TaskId(1)).first(TaskId(0)).end(End::Free);
    let p = b.build().unwrap();
    let e = solve_with(SolverName::Ga, &p, &opts(), &BaselineParams::default()).unwrap_err();
    assert!(matches!(e, BaselineError::TooLarge { solver: SolverName::Ga, .. }), "{e}");
}

#[test]
fn castelino_counts_its_precedence_pairs_first() {
    // Two clusters of 3,000 nodes, one before the other: 4 · 3000 · 3000 node pairs.
    let pts: Vec<[f64; 3]> = (0..6000).map(|i| [i as f64, 0.0, 0.0]).collect();
    let mut b = Problem::builder(PointCost::new(pts, Metric::EuclideanNint));
    b.task((0..3000).map(|v| Mode::point(StateId(v))).collect());
    b.task((3000..6000).map(|v| Mode::point(StateId(v))).collect());
    b.precede(TaskId(0), TaskId(1)).end(End::Free);
    let p = b.build().unwrap();
    let e = solve_with(SolverName::Castelino, &p, &opts(), &BaselineParams::default()).unwrap_err();
    assert!(matches!(e, BaselineError::TooLarge { solver: SolverName::Castelino, .. }), "{e}");
    assert!(e.to_string().contains("36000000"), "{e}");
}

#[test]
fn the_time_limit_stops_a_cycle_of_ants() {
    // 2,000 tasks: one cycle is 2,000 walks of 2,000 × 4,000 moves (about a minute); the limit
    // ends it after the walks under way.
    let p = line(2000, 1);
    let opts = SolveOptions { time_limit: Some(Duration::from_millis(200)), threads: 1, ..SolveOptions::default() };
    let r = solve_with(SolverName::Aco1, &p, &opts, &BaselineParams::default()).unwrap();
    assert!(r.elapsed < Duration::from_secs(5), "took {:?}", r.elapsed);
    check(&p, &r.solution.steps).unwrap();
}
