//! Reversal moves (2-opt / Lin–Kernighan chains) on symmetric instances: plain TSP, point modes
//! (GTSP-like) and reversible two-mode tasks, closed and open. The solver's answer must be
//! feasible, its checked cost must match, and it must be a decent tour (within a few percent of
//! a long run).

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_seq::*;

fn points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n).map(|_| [rng.gen_range(0.0..1000.0), rng.gen_range(0.0..1000.0), 0.0]).collect()
}

fn run<C: CostModel>(p: &Problem<C>, iterations: u64) -> f64 {
    let opts = SolveOptions {
        time_limit: None,
        iterations: Some(iterations),
        threads: 1,
        exact_up_to: 0,
        ..Default::default()
    };
    let r = solve(p, &opts).unwrap();
    let c = check(p, &r.solution.steps).unwrap();
    assert!((c - r.solution.cost).abs() < 1e-6);
    c
}

#[test]
fn tsp_closed() {
    let pts = points(300, 1);
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    b.point_tasks(300);
    let p = b.build().unwrap();
    let short = run(&p, 200);
    let long = run(&p, 3000);
    assert!(long <= short + 1e-6);
    // random uniform 300 points in a 1000x1000 square: optimum is about 0.7124*sqrt(n*A) ~ 12.3k
    assert!(short < 13_500.0, "{short}");
}

#[test]
fn reversible_strokes_open() {
    let pts = points(400, 2);
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    for k in 0..200u32 {
        let (s, e) = (StateId(2 * k), StateId(2 * k + 1));
        b.task(vec![Mode::new(s, e), Mode::new(e, s)]);
    }
    b.end(End::Free);
    let p = b.build().unwrap();
    run(&p, 300);
}

#[test]
fn point_modes_from_start() {
    let pts = points(301, 3);
    let mut b = Problem::builder(PointCost::new(pts, Metric::EuclideanNint));
    for k in 0..100u32 {
        b.task((0..3).map(|j| Mode::point(StateId(3 * k + j))).collect());
    }
    b.start(StateId(300));
    let p = b.build().unwrap();
    run(&p, 300);
}

/// Plain symmetric one-mode tours and paths, where Lin–Kernighan chains take sequential 3-opt
/// steps and the kicks are four-arc double bridges: on small instances solved exactly (closed,
/// open with a free end, open from a start point), the answer is feasible, priced as the checker
/// prices it, and optimal on (nearly) all.
#[test]
fn plain_symmetric_tours_match_the_exact_optimum() {
    let mut misses = Vec::new();
    let mut total = 0;
    for seed in 0..90u64 {
        let n = 8 + (seed % 5) as usize;
        let pts = points(n + 1, 100 + seed);
        let mut b = Problem::builder(PointCost::new(pts, Metric::EuclideanNint));
        b.point_tasks(n);
        match seed % 3 {
            0 => {}
            1 => {
                b.end(End::Free);
            }
            _ => {
                b.start(StateId(n as u32)).end(End::Free);
            }
        }
        let p = b.build().unwrap();
        let exact = solve_exact(&p).unwrap().unwrap();
        let exact_cost = check(&p, &exact.steps).unwrap();
        let opts = SolveOptions {
            time_limit: None,
            iterations: Some(300),
            threads: 1,
            seed,
            exact_up_to: 0,
            ..Default::default()
        };
        let r = solve(&p, &opts).unwrap();
        let c = check(&p, &r.solution.steps).unwrap();
        assert!((c - r.solution.cost).abs() < 1e-6, "seed {seed}");
        assert!(c >= exact_cost - 1e-6, "seed {seed}: {c} below the optimum {exact_cost}");
        total += 1;
        if c > exact_cost + 1e-6 {
            misses.push(format!("seed {seed} (n {n}): {c} vs {exact_cost}"));
        }
    }
    assert!(misses.len() * 100 <= total, "misses:\n{}", misses.join("\n"));
}

#[test]
fn stalled_epochs_end_the_search_early_and_deterministically() {
    let pts = points(40, 7);
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    b.point_tasks(40);
    let p = b.build().unwrap();
    let opts = |stall: Option<u32>| SolveOptions {
        time_limit: None,
        iterations: Some(40_000),
        threads: 2,
        exact_up_to: 0,
        stall_epochs: stall,
        ..Default::default()
    };
    let full = solve(&p, &opts(None)).unwrap();
    let early = solve(&p, &opts(Some(2))).unwrap();
    let again = solve(&p, &opts(Some(2))).unwrap();
    assert_eq!(full.iterations, 40_000);
    // 40 cities settle long before 40,000 kicks: the stall stops the search after a few epochs
    assert!(early.iterations < full.iterations / 2, "{} kicks", early.iterations);
    assert_eq!(early.solution.steps, again.solution.steps);
    let c = check(&p, &early.solution.steps).unwrap();
    assert!((c - early.solution.cost).abs() < 1e-6);
    // on 40 cities both find the same (optimal) tour length
    assert!(
        (early.solution.cost - full.solution.cost).abs() < 1e-6,
        "{} vs {}",
        early.solution.cost,
        full.solution.cost
    );
}
