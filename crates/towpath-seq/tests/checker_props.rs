//! Property tests of the independent checker: on random problems and random routes it accepts
//! exactly the feasible ones, prices them like a plain re-summation, and names the first thing
//! that is wrong otherwise.

use proptest::prelude::*;
use towpath_seq::*;

/// A random problem: `n` tasks with 1–3 modes over `2n` random points, random precedence over
/// pairs (i < j in task order), an optional start state.
fn problem(n: usize, coords: &[(f64, f64)], modes: &[u8], edges: &[(usize, usize)], start: bool) -> Problem<PointCost> {
    let pts: Vec<[f64; 3]> = coords.iter().map(|&(x, y)| [x, y, 0.0]).collect();
    let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
    for t in 0..n {
        let m = 1 + (modes[t] % 3) as u32;
        let (a, e) = (StateId(2 * t as u32), StateId(2 * t as u32 + 1));
        let ms = (0..m).map(|k| if k % 2 == 0 { Mode::new(a, e) } else { Mode::new(e, a) }).collect();
        b.task(ms);
    }
    for &(i, j) in edges {
        let (i, j) = (i % n, j % n);
        if i < j {
            b.precede(TaskId(i as u32), TaskId(j as u32));
        }
    }
    if start {
        b.start(StateId(0));
    } else {
        b.end(End::Free);
    }
    b.build().expect("edges go forward in task order, so they are acyclic")
}

/// (tasks, point coordinates, mode counts, precedence pairs, has start, order, mode picks)
type Case = (usize, Vec<(f64, f64)>, Vec<u8>, Vec<(usize, usize)>, bool, Vec<usize>, Vec<u8>);

fn arb_case() -> impl Strategy<Value = Case> {
    (2usize..9).prop_flat_map(|n| {
        (
            Just(n),
            prop::collection::vec((0.0..100.0f64, 0.0..100.0f64), 2 * n),
            prop::collection::vec(any::<u8>(), n),
            prop::collection::vec((0usize..9, 0usize..9), 0..6),
            any::<bool>(),
            Just((0..n).collect::<Vec<usize>>()).prop_shuffle(),
            prop::collection::vec(any::<u8>(), n),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn checker_accepts_exactly_feasible_routes((n, coords, modes, edges, start, order, mode_pick) in arb_case()) {
        let p = problem(n, &coords, &modes, &edges, start);
        let steps: Vec<Step> = order
            .iter()
            .map(|&t| Step { task: TaskId(t as u32), mode: mode_pick[t] as u32 % p.modes(TaskId(t as u32)).len() as u32 })
            .collect();
        let mut pos = vec![0usize; n];
        for (i, &t) in order.iter().enumerate() {
            pos[t] = i;
        }
        let feasible = p.tasks().all(|t| p.precedence().successors(t).iter().all(|s| pos[t.index()] < pos[s.index()]));
        match check(&p, &steps) {
            Ok(c) => {
                prop_assert!(feasible);
                // an independent re-summation
                let mut total = 0.0;
                let mut prev = p.start();
                for s in &steps {
                    let m = p.modes(s.task)[s.mode as usize];
                    if let Some(q) = prev {
                        total += p.transition(q, m.entry);
                    }
                    total += m.cost;
                    prev = Some(m.exit);
                }
                if let (Some(q), Some(s0)) = (prev, p.start()) {
                    total += p.transition(q, s0);
                }
                prop_assert!((c - total).abs() < 1e-9);
            }
            Err(Violation::Precedence { before, after }) => {
                prop_assert!(!feasible);
                prop_assert!(pos[before as usize] > pos[after as usize]);
            }
            Err(v) => prop_assert!(false, "unexpected violation {v}"),
        }
    }

    #[test]
    fn checker_names_broken_routes((n, coords, modes, edges, start, order, _m) in arb_case(), which in 0u8..3) {
        let p = problem(n, &coords, &modes, &edges, start);
        let mut steps: Vec<Step> = order.iter().map(|&t| Step { task: TaskId(t as u32), mode: 0 }).collect();
        match which {
            0 => {
                steps.pop();
                let r = check(&p, &steps);
                prop_assert!(matches!(r, Err(Violation::WrongLength { .. })), "{:?}", r);
            }
            1 => {
                let last = steps.len() - 1;
                steps[last] = steps[0];
                let r = check(&p, &steps);
                prop_assert!(matches!(r, Err(Violation::Duplicate { .. })), "{:?}", r);
            }
            _ => {
                steps[0].mode = 3;
                let r = check(&p, &steps);
                prop_assert!(matches!(r, Err(Violation::UnknownMode { .. })), "{:?}", r);
            }
        }
    }
}
