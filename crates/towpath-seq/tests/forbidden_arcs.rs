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
