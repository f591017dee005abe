//! The SOP-3-exchange of Gambardella and Dorigo (2000): path-preserving 3-opt (two adjacent
//! segments trade places, nothing is reversed) searched lexicographically and exhaustively
//! around one node, with precedence feasibility kept by labelling.
//!
//! Forward search from a node at position `h`: the left segment `h+1..=i` grows one node at a
//! time and the direct successors of each new node are labelled; for each `i` the right segment
//! `i+1..=j` grows until it meets a labelled node (a successor of the left segment, which may
//! not move before it), and every longer right segment is infeasible too. The backward search
//! mirrors this from the node at position `j+1`: the right segment grows leftwards labelling
//! predecessors, the left one grows leftwards until it meets a label. Each exchange is priced
//! in O(1) from the three arcs it removes and the three it adds. Direct precedence edges are
//! enough: the current tour is feasible, so a chain `x ≺ z ≺ y` with `x` left and `y` right
//! has `z` inside the two segments and one of its two edges is seen.
//!
//! Used by the local search on one-mode instances with precedence and without groups (where
//! candidate lists miss improving exchanges, as on random asymmetric costs with sparse
//! precedence), and by the precedence-keeping double-bridge kick [`bridge`] that such a
//! complete 3-exchange neighbourhood cannot undo in one move.

use rand::Rng;
use rand_pcg::Pcg64Mcg;

use super::net::Net;
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

/// Longest stretch (left plus right segment) an exchange spans: keeps a search around one node
/// at O(`WINDOW`²) arc evaluations on large instances.
const WINDOW: usize = 600;

/// Longest segment of a [`bridge`] kick.
const BRIDGE_SEGMENT: usize = 50;

/// An improving exchange: segments `h+1..=i` and `i+1..=j` trade places, changing the tour cost
/// by `delta` (negative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Exchange {
    pub h: usize,
    pub i: usize,
    pub j: usize,
    pub delta: Cost,
}

/// Scratch state of the SOP-3-exchange search (labels stamped per search).
pub(crate) struct Sop3 {
    label: Vec<u32>,
    stamp: u32,
}

/// Whether the local search uses the SOP-3-exchange: precedence, one mode per task, no groups.
pub(crate) fn applies<C: CostModel>(net: &Net<'_, C>) -> bool {
    net.has_prec && !net.multi_mode && !net.has_groups && net.n >= 4
}

impl Sop3 {
    pub fn new(n: usize) -> Self {
        Sop3 { label: vec![0; n], stamp: 0 }
    }

    fn next_stamp(&mut self) -> u32 {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.label.fill(0);
            self.stamp = 1;
        }
        self.stamp
    }

    /// The first improving feasible exchange found by the forward search from `v` (`v` before
    /// the left segment) or the backward search from it (`v` after the right segment).
    pub fn find<C: CostModel>(&mut self, net: &Net<'_, C>, tour: &Tour, v: u32, eps: Cost) -> Option<Exchange> {
        let n = tour.len();
        if n < 4 {
            return None;
        }
        let p = tour.pos[v as usize] as usize;
        if let Some(ex) = self.forward(net, tour, p, eps) {
            return Some(ex);
        }
        self.backward(net, tour, if p == 0 { n - 1 } else { p - 1 }, eps)
    }

    /// Exchanges with the left segment starting at `h + 1`.
    fn forward<C: CostModel>(&mut self, net: &Net<'_, C>, tour: &Tour, h: usize, eps: Cost) -> Option<Exchange> {
        let n = tour.len();
        if h + 2 >= n {
            return None;
        }
        let st = self.next_stamp();
        let last = (n - 1).min(h + WINDOW);
        let hv = tour.seq[h];
        let a = tour.seq[h + 1];
        let base_h = tour.arc(net, hv, a);
        for i in h + 1..last {
            let iv = tour.seq[i];
            for &s in net.successors(iv) {
                self.label[s as usize] = st;
            }
            let c = tour.seq[i + 1];
            if self.label[c as usize] == st {
                // the right segment would begin with a successor of the left one
                continue;
            }
            // gain of removing h->a and i->c and adding h->c
            let g1 = base_h + tour.arc(net, iv, c) - tour.arc(net, hv, c);
            for j in i + 1..=last {
                let dv = tour.seq[j];
                if self.label[dv as usize] == st {
                    break;
                }
                let q = tour.next_of_pos(j);
                let delta = tour.arc(net, dv, a) + tour.arc(net, iv, q) - tour.arc(net, dv, q) - g1;
                if delta < -eps {
                    return Some(Exchange { h, i, j, delta });
                }
            }
        }
        None
    }

    /// Exchanges with the right segment ending at `j`.
    fn backward<C: CostModel>(&mut self, net: &Net<'_, C>, tour: &Tour, j: usize, eps: Cost) -> Option<Exchange> {
        if j < 2 {
            return None;
        }
        let st = self.next_stamp();
        let first = j.saturating_sub(WINDOW);
        let dv = tour.seq[j];
        let q = tour.next_of_pos(j);
        let base_j = tour.arc(net, dv, q);
        for i in (first.max(1)..j).rev() {
            let c = tour.seq[i + 1];
            for &s in net.predecessors(c) {
                self.label[s as usize] = st;
            }
            let iv = tour.seq[i];
            if self.label[iv as usize] == st {
                // the left segment would end with a predecessor of the right one
                continue;
            }
            // gain of removing i->c and d->q and adding i->q
            let g1 = base_j + tour.arc(net, iv, c) - tour.arc(net, iv, q);
            for h in (first..i).rev() {
                let a = tour.seq[h + 1];
                if self.label[a as usize] == st {
                    break;
                }
                let hv = tour.seq[h];
                let delta = tour.arc(net, hv, c) + tour.arc(net, dv, a) - tour.arc(net, hv, a) - g1;
                if delta < -eps {
                    return Some(Exchange { h, i, j, delta });
                }
            }
        }
        None
    }
}

/// Applies an exchange and returns the endpoints of the arcs it changed.
pub(crate) fn apply(tour: &mut Tour, ex: Exchange) -> [u32; 6] {
    let Exchange { h, i, j, delta } = ex;
    let ends = [tour.seq[h], tour.seq[h + 1], tour.seq[i], tour.seq[i + 1], tour.seq[j], tour.next_of_pos(j)];
    tour.swap_adjacent(h + 1, i, j);
    tour.cost += delta;
    ends
}

/// A double bridge that keeps the path and precedence: three consecutive short segments
/// B C D become D C B (four arcs change, so no single 3-exchange undoes it). Tries a few random
/// placements and returns the endpoints of the changed arcs, or `None` when none was feasible.
pub(crate) fn bridge<C: CostModel>(net: &Net<'_, C>, tour: &mut Tour, rng: &mut Pcg64Mcg) -> Option<[u32; 8]> {
    let n = tour.len();
    if n < 5 {
        return None;
    }
    let max_len = ((n - 1) / 3).clamp(1, BRIDGE_SEGMENT);
    for _attempt in 0..20 {
        let (lb, lc, ld) = (rng.gen_range(1..=max_len), rng.gen_range(1..=max_len), rng.gen_range(1..=max_len));
        if lb + lc + ld > n - 1 {
            continue;
        }
        let i = rng.gen_range(1..=n - lb - lc - ld);
        let (j, k, l) = (i + lb - 1, i + lb + lc - 1, i + lb + lc + ld - 1);
        // every pair of the three segments changes order: no edge from B to C or D, or C to D
        let blocked = |from: std::ops::RangeInclusive<usize>, lo: usize| {
            from.into_iter().any(|t| {
                net.successors(tour.seq[t]).iter().any(|&s| {
                    let ps = tour.pos[s as usize] as usize;
                    ps >= lo && ps <= l
                })
            })
        };
        if blocked(i..=j, j + 1) || blocked(j + 1..=k, k + 1) {
            continue;
        }
        return Some(tour.double_bridge(net, i, j, k, l));
    }
    None
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::MatrixCost;
    use crate::model::{Mode, Problem, TaskId};
    use crate::search::net::Net;
    use crate::search::tour::Tour;
    use crate::solution::{check, Step};
    use crate::{solve, solve_exact, SolveOptions};

    /// A closed tour of `n` tasks with random integer asymmetric costs and random precedence
    /// over a random order (task `perm[0]` pinned first), or an open path from a start state.
    fn random_sop(seed: u64, n: usize) -> Problem<MatrixCost> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let ns = n + 1;
        let m = MatrixCost::from_fn(ns, |i, j| if i == j { 0.0 } else { rng.gen_range(0..100) as f64 });
        let mut b = Problem::builder(m);
        for k in 0..n as u32 {
            b.task(vec![Mode::point(crate::cost::StateId(k))]);
        }
        let mut perm: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            perm.swap(i, rng.gen_range(0..=i));
        }
        let density = rng.gen_range(0.05..0.4);
        for i in 0..n {
            for j in i + 1..n {
                if rng.gen_bool(density) {
                    b.precede(TaskId(perm[i]), TaskId(perm[j]));
                }
            }
        }
        if rng.gen_bool(0.5) {
            b.first(TaskId(perm[0]));
        } else {
            b.start(crate::cost::StateId(n as u32));
        }
        b.build().expect("random precedence over an order is acyclic")
    }

    fn steps_of<C: CostModel>(net: &Net<'_, C>, tour: &Tour) -> Vec<Step> {
        tour.nodes().filter(|&(v, _)| v != net.depot).map(|(v, m)| Step { task: TaskId(v), mode: m }).collect()
    }

    /// A feasible start: tasks in topological order, rotated so that position 0 holds the
    /// anchor (or the depot).
    fn start_tour<C: CostModel>(net: &Net<'_, C>) -> Tour {
        let mut seq: Vec<u32> = (0..net.n as u32).collect();
        seq.sort_by_key(|&v| if v == net.depot || v == net.anchor { 0 } else { net.topo_rank[v as usize] + 1 });
        Tour::new(net, seq, vec![0; net.n])
    }

    /// Every exchange of the tour, priced and checked by rebuilding the sequence.
    fn brute_best<C: CostModel>(p: &Problem<C>, net: &Net<'_, C>, tour: &Tour) -> Option<f64> {
        let n = tour.len();
        let mut best: Option<f64> = None;
        for h in 0..n {
            for i in h + 1..n {
                for j in i + 1..n {
                    let mut seq = tour.seq.clone();
                    seq[h + 1..=j].rotate_left(i - h);
                    let t = Tour::new(net, seq, vec![0; net.n]);
                    if let Ok(c) = check(p, &steps_of(net, &t)) {
                        let d = c - tour.cost;
                        if best.is_none_or(|b| d < b) {
                            best = Some(d);
                        }
                    }
                }
            }
        }
        best
    }

    #[test]
    fn every_exchange_keeps_precedence_and_prices_right_and_descent_is_complete() {
        for seed in 0..150u64 {
            let n = 4 + (seed % 6) as usize;
            let p = random_sop(seed, n);
            let net = Net::new(&p);
            let mut tour = start_tour(&net);
            check(&p, &steps_of(&net, &tour)).unwrap_or_else(|v| panic!("seed {seed}: start infeasible: {v}"));
            let mut s = Sop3::new(net.n);
            let mut moves = 0;
            loop {
                let mut found = None;
                for v in 0..net.n as u32 {
                    if let Some(ex) = s.find(&net, &tour, v, 1e-9) {
                        found = Some(ex);
                        break;
                    }
                }
                let Some(ex) = found else { break };
                apply(&mut tour, ex);
                moves += 1;
                let checked = check(&p, &steps_of(&net, &tour))
                    .unwrap_or_else(|v| panic!("seed {seed}: move {ex:?} broke feasibility: {v}"));
                assert!((checked - tour.cost).abs() < 1e-6, "seed {seed}: tracked {} != {checked}", tour.cost);
                assert!((tour.full_cost(&net) - tour.cost).abs() < 1e-6, "seed {seed}: arcs disagree");
                assert!(moves < 10_000, "seed {seed}: descent does not end");
            }
            // a local optimum of the search is one of the whole feasible neighbourhood
            if let Some(d) = brute_best(&p, &net, &tour) {
                assert!(d > -1e-9, "seed {seed}: an improving exchange ({d}) was missed");
            }
        }
    }

    #[test]
    fn bridge_keeps_precedence_and_prices_right() {
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        for seed in 0..100u64 {
            let n = 5 + (seed % 5) as usize;
            let p = random_sop(1000 + seed, n);
            let net = Net::new(&p);
            let mut tour = start_tour(&net);
            for _ in 0..20 {
                if bridge(&net, &mut tour, &mut rng).is_some() {
                    let checked = check(&p, &steps_of(&net, &tour))
                        .unwrap_or_else(|v| panic!("seed {seed}: bridge broke feasibility: {v}"));
                    assert!((checked - tour.cost).abs() < 1e-6, "seed {seed}: tracked {} != {checked}", tour.cost);
                }
            }
        }
    }

    #[test]
    fn search_reaches_the_optimum_on_small_instances() {
        for seed in 0..60u64 {
            let n = 6 + (seed % 4) as usize;
            let p = random_sop(5000 + seed, n);
            let Ok(Some(exact)) = solve_exact(&p) else { panic!("seed {seed}: no exact answer") };
            let opts = SolveOptions {
                time_limit: None,
                iterations: Some(400),
                threads: 1,
                exact_up_to: 0,
                seed,
                assignment_branching: false,
                ..SolveOptions::default()
            };
            let r = solve(&p, &opts).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            assert!(!r.exact);
            assert!(
                (r.solution.cost - exact.cost).abs() < 1e-6,
                "seed {seed} n {n}: heuristic {} != optimum {}",
                r.solution.cost,
                exact.cost
            );
        }
    }
}
