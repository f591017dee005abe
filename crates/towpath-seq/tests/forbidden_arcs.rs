//! Forbidden (infinite) transitions: the search prices them high but finite, so its bookkeeping
//! stays exact, and it never returns a route that uses one when a feasible route exists.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_seq::*;

#[test]
fn routes_avoid_forbidden_arcs() {
    for seed in 0..20u64 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let n = rng.gen_range(12..40usize);
        // a hidden feasible cycle 0 -> perm[1] -> ... ; every other arc forbidden with prob 0.4
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (2..n).rev() {
            perm.swap(i, rng.gen_range(1..=i));
        }
        let mut succ = vec![0usize; n];
        for k in 0..n {
            succ[perm[k]] = perm[(k + 1) % n];
        }
        let data: Vec<f64> = (0..n * n)
            .map(|x| {
                let (i, j) = (x / n, x % n);
                if i == j {
                    0.0
                } else if succ[i] == j {
                    rng.gen_range(50.0..100.0_f64).round()
                } else if rng.gen_bool(0.4) {
                    f64::INFINITY
                } else {
                    rng.gen_range(1.0..100.0_f64).round()
                }
            })
            .collect();
        let mut b = Problem::builder(MatrixCost::new(n, data).unwrap());
        b.point_tasks(n);
        let p = b.build().unwrap();
        let opts = SolveOptions {
            time_limit: None,
            iterations: Some(500),
            threads: 1,
            seed,
            exact_up_to: 0,
            ..Default::default()
        };
        let r = solve(&p, &opts).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let c = check(&p, &r.solution.steps).unwrap_or_else(|v| panic!("seed {seed}: {v}"));
        assert!(c.is_finite() && (c - r.solution.cost).abs() < 1e-6);
    }
}

/// When every route needs a forbidden transition, a solve under a work budget (no time limit)
/// ends, saying no feasible route exists. (The case where rounding in the huge forbidden price
/// made the local search cycle for ever is towpath-nc's
/// `no_safe_transit_within_the_travel_limits_is_refused`; these matrices do not reproduce it.)
#[test]
fn infeasible_problems_end_under_a_work_budget() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for seed in 0..10u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = rng.gen_range(20..60usize);
            // Two clusters; every transition between them is forbidden, so a closed tour
            // through both cannot exist.
            let side = |i: usize| i % 2 == 0;
            let data: Vec<f64> = (0..n * n)
                .map(|x| {
                    let (i, j) = (x / n, x % n);
                    if i == j {
                        0.0
                    } else if side(i) != side(j) {
                        f64::INFINITY
                    } else {
                        rng.gen_range(1.0..1000.0_f64) * 1.000_000_1
                    }
                })
                .collect();
            let mut b = Problem::builder(MatrixCost::new(n, data).unwrap());
            b.point_tasks(n);
            let p = b.build().unwrap();
            let opts = SolveOptions {
                time_limit: None,
                iterations: Some(300),
                threads: 1,
                seed,
                exact_up_to: 0,
                ..Default::default()
            };
            let r = solve(&p, &opts);
            assert!(matches!(r, Err(SolveError::NoFeasibleRoute(_))), "seed {seed}: {:?}", r.map(|r| r.solution.cost));
        }
        let _ = tx.send(());
    });
    rx.recv_timeout(std::time::Duration::from_secs(120)).expect("the solves end within two minutes");
}
