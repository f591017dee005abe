//! Every solver of the registry against the exact DP on small seeded instances: open rural
//! postman instances shaped like seed 004's data, and random problems with modes, precedence,
//! groups, pins and every kind of route end. Every answer must be feasible with the cost the
//! independent checker computes, never below the optimum; the deterministic solvers must be
//! bit-for-bit repeatable and the randomized ones repeatable by seed.

use std::time::Duration;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_baselines::*;
use towpath_coverage::{tewolde_sheng_like, RppModel};
use towpath_seq::*;

/// Options that make every solver deterministic: a work budget, no time limit, one thread.
fn det_opts(seed: u64) -> SolveOptions {
    SolveOptions { time_limit: None, iterations: Some(1000), seed, threads: 1, ..SolveOptions::default() }
}

fn random_problem(seed: u64) -> (Problem<MatrixCost>, String) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let n = rng.gen_range(3..=8usize);
    let max_modes = rng.gen_range(1..=3usize);
    let mut pts: Vec<(f64, f64)> = Vec::new();
    let mut tasks = Vec::new();
    for _ in 0..n {
        let k = rng.gen_range(1..=max_modes);
        let mut ms = Vec::new();
        for _ in 0..k {
            let a = pts.len() as u32;
            pts.push((rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0)));
            let b = if rng.gen_bool(0.5) {
                a
            } else {
                pts.push((rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0)));
                a + 1
            };
            ms.push(Mode { entry: StateId(a), exit: StateId(b), cost: rng.gen_range(0.0..5.0f64).round() });
        }
        tasks.push(ms);
    }
    let s = pts.len() as u32;
    pts.push((50.0, 50.0));
    let e = pts.len() as u32;
    pts.push((0.0, 100.0));
    let asym = rng.gen_bool(0.3);
    let ns = pts.len();
    let skew: Vec<f64> = (0..ns * ns).map(|_| if asym { rng.gen_range(0.0..20.0f64).round() } else { 0.0 }).collect();
    let m = MatrixCost::from_fn(ns, |i, j| {
        if i == j {
            0.0
        } else {
            ((pts[i].0 - pts[j].0).powi(2) + (pts[i].1 - pts[j].1).powi(2)).sqrt().round() + skew[i * ns + j]
        }
    });
    let mut b = Problem::builder(m);
    for ms in tasks {
        b.task(ms);
    }
    let route = rng.gen_range(0..5);
    let mut label = format!("seed {seed}, {n} tasks, ≤{max_modes} modes, asym {asym}, ");
    match route {
        0 => label += "cycle",
        1 => {
            b.start(StateId(s));
            label += "closed from start";
        }
        2 => {
            b.end(End::Free);
            label += "open";
        }
        3 => {
            b.start(StateId(s)).end(End::Free);
            label += "open from start";
        }
        _ => {
            b.start(StateId(s)).end(End::At(StateId(e)));
            label += "start to end";
        }
    }
    // precedence along a random order (not in cycles without an anchor)
    let mut order: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        order.swap(i, rng.gen_range(0..=i));
    }
    if route != 0 || rng.gen_bool(0.5) {
        if route == 0 {
            b.first(TaskId(order[0]));
            label += " pinned first";
        }
        for _ in 0..rng.gen_range(0..=n) {
            let i = rng.gen_range(1..n);
            let j = rng.gen_range(0..i);
            if route == 0 && j == 0 {
                continue;
            }
            b.precede(TaskId(order[j]), TaskId(order[i]));
        }
        label += " + precedence";
    }
    if rng.gen_bool(0.25) && route != 0 {
        // a consecutive group of two tasks adjacent in the order
        let i = rng.gen_range(0..n - 1);
        b.consecutive(vec![TaskId(order[i]), TaskId(order[i + 1])]);
        label += " + group";
    }
    match b.build() {
        Ok(p) => (p, label),
        Err(_) => random_problem(seed + 10_000),
    }
}

fn params_for_tests() -> BaselineParams {
    BaselineParams {
        ga: GaParams { generations: 60, ..GaParams::default() },
        aco: AcoParams { cycles: 10, ..AcoParams::default() },
        ..BaselineParams::default()
    }
}

#[test]
fn every_solver_is_feasible_and_never_below_the_optimum() {
    let params = params_for_tests();
    let mut optimal = std::collections::HashMap::new();
    let mut runs = std::collections::HashMap::new();
    for seed in 0..40u64 {
        let (p, label) = random_problem(seed);
        let exact = solve_exact(&p).unwrap().expect("random problems are feasible").cost;
        for name in SolverName::ALL {
            let r = match solve_with(name, &p, &det_opts(seed), &params) {
                Ok(r) => r,
                Err(BaselineError::Unsupported { solver: SolverName::Doherty, .. }) if !p.groups().is_empty() => {
                    continue
                }
                Err(e) => panic!("{name} on {label}: {e}"),
            };
            let c = check(&p, &r.solution.steps).unwrap_or_else(|v| panic!("{name} on {label}: {v}"));
            assert_eq!(c, r.solution.cost, "{name} on {label}: reported cost differs from the checker's");
            assert!(c >= exact - 1e-9, "{name} on {label}: {c} below the optimum {exact}");
            *runs.entry(name).or_insert(0) += 1;
            if c <= exact + 1e-9 {
                *optimal.entry(name).or_insert(0) += 1;
            }
        }
    }
    // towpath's solver is exact at this size; the baselines are heuristics but must not be
    // useless: each finds the optimum on a good share of these small instances. (Doherty's
    // solver ignores the moves between precedence sets and the route's ends by design, so on
    // these random routes it is only required to be feasible.)
    for name in SolverName::ALL.into_iter().filter(|&n| n != SolverName::Doherty) {
        let (o, n) = (optimal.get(&name).copied().unwrap_or(0), runs[&name]);
        let need = if name == SolverName::Towpath { n } else { n / 3 };
        assert!(o >= need, "{name}: optimal on {o} of {n}");
    }
}

#[test]
fn seed004_small_instances_are_solved_optimally_by_ga_and_aco() {
    // Table I: on data sets #1–#2 (3 and 5 required edges) GA, ACO1 and ACO2 all reach the
    // best length. Our generated instances of those sizes with the paper's settings should too,
    // nearly always.
    let params = BaselineParams { ga: GaParams::default(), aco: AcoParams::default(), ..BaselineParams::default() };
    let mut hits = std::collections::HashMap::new();
    let mut total = 0;
    for r in [3usize, 4, 5] {
        for seed in 1..=8u64 {
            let model = RppModel::new(tewolde_sheng_like(r, seed).unwrap()).unwrap();
            let p = model.problem();
            let exact = solve_exact(p).unwrap().unwrap().cost;
            total += 1;
            for name in [SolverName::Ga, SolverName::Aco1, SolverName::Aco2, SolverName::Doherty, SolverName::Castelino]
            {
                let rep = solve_with(name, p, &det_opts(seed), &params).unwrap();
                let route = model.route(&rep.solution.steps).unwrap();
                let len = towpath_coverage::verify_route(model.instance(), &route).unwrap();
                assert!((len - rep.solution.cost).abs() < 1e-9);
                assert!(len >= exact - 1e-9);
                if len <= exact + 1e-9 {
                    *hits.entry(name).or_insert(0) += 1;
                }
            }
        }
    }
    for name in [SolverName::Ga, SolverName::Aco1, SolverName::Aco2, SolverName::Castelino] {
        let h = hits.get(&name).copied().unwrap_or(0);
        assert!(h * 10 >= total * 8, "{name}: optimal on {h} of {total}");
    }
}

#[test]
fn deterministic_solvers_are_repeatable_bit_for_bit() {
    let params = params_for_tests();
    for seed in [3u64, 11, 17] {
        let (p, label) = random_problem(seed);
        for name in SolverName::ALL {
            let a = solve_with(name, &p, &det_opts(seed), &params);
            let b = solve_with(name, &p, &det_opts(seed), &params);
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.solution.steps, b.solution.steps, "{name} on {label}");
                    assert_eq!(a.solution.cost.to_bits(), b.solution.cost.to_bits(), "{name} on {label}");
                }
                (Err(a), Err(b)) => assert_eq!(a, b),
                _ => panic!("{name} on {label}: one run failed, the other did not"),
            }
        }
        // Doherty does not use the seed at all.
        let (p, _) = random_problem(seed + 100);
        let a = solve_with(SolverName::Doherty, &p, &det_opts(1), &params);
        let b = solve_with(SolverName::Doherty, &p, &det_opts(2), &params);
        if let (Ok(a), Ok(b)) = (a, b) {
            assert_eq!(a.solution.steps, b.solution.steps);
        }
    }
}

#[test]
fn randomized_solvers_depend_on_the_seed() {
    // On a 30-edge instance different seeds give different GA and ACO runs.
    let model = RppModel::new(tewolde_sheng_like(30, 2).unwrap()).unwrap();
    let params = BaselineParams::default();
    for name in [SolverName::Ga, SolverName::Aco1, SolverName::Aco2] {
        let runs: Vec<Vec<Step>> =
            (1..=4).map(|s| solve_with(name, model.problem(), &det_opts(s), &params).unwrap().solution.steps).collect();
        assert!(runs.windows(2).any(|w| w[0] != w[1]), "{name}: four seeds, one answer");
    }
}

#[test]
fn an_initial_route_is_never_made_worse() {
    // seed 000 requirement 4: F(p) ≤ F(o), for every solver.
    let model = RppModel::new(tewolde_sheng_like(12, 9).unwrap()).unwrap();
    let p = model.problem();
    let best = solve(p, &SolveOptions { time_limit: Some(Duration::from_millis(300)), ..det_opts(1) }).unwrap();
    let params = BaselineParams {
        ga: GaParams { generations: 5, population: 10, ..GaParams::default() },
        ..BaselineParams::default()
    };
    for name in SolverName::ALL {
        let opts = SolveOptions { initial: Some(best.solution.steps.clone()), ..det_opts(1) };
        let r = solve_with(name, p, &opts, &params).unwrap();
        assert!(r.solution.cost <= best.solution.cost + 1e-9, "{name}");
        assert_eq!(r.initial_cost, Some(best.solution.cost));
    }
}

#[test]
fn time_limit_is_honoured() {
    let model = RppModel::new(tewolde_sheng_like(40, 1).unwrap()).unwrap();
    let params = BaselineParams {
        ga: GaParams { generations: 1_000_000, ..GaParams::default() },
        aco: AcoParams { cycles: 1_000_000, ..AcoParams::default() },
        ..BaselineParams::default()
    };
    for name in [SolverName::Ga, SolverName::Aco2] {
        let opts = SolveOptions { time_limit: Some(Duration::from_millis(200)), threads: 1, ..SolveOptions::default() };
        let r = solve_with(name, model.problem(), &opts, &params).unwrap();
        assert!(r.elapsed < Duration::from_millis(1500), "{name} took {:?}", r.elapsed);
        check(model.problem(), &r.solution.steps).unwrap();
    }
}

#[test]
fn castelino_on_built_gtsp_and_pcgtsp_instances() {
    // GTSP-LIB-shaped instances small enough for the exact DP (25 points, 5–6 clusters: a
    // transformed problem of 50 nodes).
    let mut optimal = 0;
    let mut total = 0;
    for seed in 0..6u64 {
        for precedence in [false, true] {
            let p = random_gtsp(25, seed, precedence).unwrap();
            let exact = solve_exact(&p).unwrap().unwrap().cost;
            let opts =
                SolveOptions { time_limit: None, iterations: Some(1000), seed, threads: 1, ..SolveOptions::default() };
            let r = solve_castelino(&p, &CastelinoParams::default(), &opts).unwrap();
            let c = check(&p, &r.solution.steps).unwrap();
            assert_eq!(c, r.solution.cost);
            assert!(c >= exact - 1e-9, "seed {seed}: {c} below the optimum {exact}");
            total += 1;
            if c <= exact + 1e-9 {
                optimal += 1;
            }
        }
    }
    assert!(optimal * 10 >= total * 8, "castelino optimal on {optimal} of {total}");
}
