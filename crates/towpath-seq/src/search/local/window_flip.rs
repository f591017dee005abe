//! Reversal of a short stretch of tasks with every mode in it chosen afresh: the 2-opt move for
//! tasks with modes whose reverse is not a mode of their own (an AFP course laid the other way
//! has its own entry and exit states, with the head turned round), where the Lin–Kernighan
//! chains (which need a reverse mode per mode) do not run.
//!
//! From a task at position `v`, the stretch grows one task at a time to the right (`v..=hi`) and
//! to the left (`lo..=v`), up to [`WINDOW`] tasks. Turned round, the stretch runs
//! p → x_hi → … → x_lo → q; its cheapest modes for every pair of end modes are kept as a small
//! table that one more task extends in m³ operations, so every length is priced exactly (arcs,
//! mode costs, any asymmetry) in O(m³) more. A stretch whose two tasks are tied by precedence is
//! never reversed: growing stops at the first task with a predecessor (to the right) or a
//! successor (to the left) inside the stretch; the transitive reduction is enough, as every pair
//! tied only through others has those others between it.

use super::LocalSearch;
use crate::cost::{Cost, CostModel};
use crate::search::modes::relax_layers;
use crate::search::net::Net;
use crate::search::tour::Tour;

/// Longest stretch reversed. On a 10,000-course AFP panel (100 stacked plies, 10 s, seed 1)
/// 3, 6, 12 and 24 ended within one another's spread; on the demo's mandrel with a flange
/// (100 courses, transits planned round the flange, dear arcs; axis cost, 1 s) 3 / 6 / 24 gave
/// 19,999 / 20,290 / 24,319 against 20,761 without the move.
pub(super) const WINDOW: usize = 6;

/// Most modes a task may have for the move to run (its table grows as m², an extension as m³).
pub(super) const MAX_MODES: u32 = 4;

/// Whether the move runs: tasks with modes, no consecutive groups, at most [`MAX_MODES`] modes a
/// task, and no Lin–Kernighan reversals (`two_opt`) already.
pub(super) fn applies<C: CostModel>(net: &Net<'_, C>, two_opt: bool) -> bool {
    net.multi_mode && !two_opt && !net.has_groups && net.p.max_modes() <= MAX_MODES as usize
}

/// Cheapest costs through a turned-round stretch, by the modes of its first and last task in
/// the new order: `at(a, b)` runs from x_hi in mode `a` down to x_lo in mode `b`, mode costs
/// included.
struct Table {
    m: usize,
    cost: [Cost; (MAX_MODES * MAX_MODES) as usize],
}

impl Table {
    fn single<C: CostModel>(net: &Net<'_, C>, x: u32) -> Self {
        let m = net.num_modes(x) as usize;
        let mut cost = [Cost::INFINITY; (MAX_MODES * MAX_MODES) as usize];
        for a in 0..m {
            cost[a * MAX_MODES as usize + a] = net.mode_cost(x, a as u32);
        }
        Table { m, cost }
    }

    #[inline]
    fn at(&self, a: usize, b: usize) -> Cost {
        self.cost[a * MAX_MODES as usize + b]
    }
}

impl<'a, 'p, C: CostModel> LocalSearch<'a, 'p, C> {
    /// Tries every reversal of up to [`WINDOW`] tasks that begins or ends at `v`, and applies the
    /// best one that gains.
    pub(super) fn try_flip_window(&mut self, tour: &mut Tour, v: u32) -> bool {
        let n = tour.len();
        let pv = tour.pos[v as usize] as usize;
        if pv == 0 || n < 4 {
            return false;
        }
        let mut best: Option<(Cost, usize, usize)> = None;
        self.flip_right(tour, pv, &mut best);
        self.flip_left(tour, pv, &mut best);
        let Some((delta, lo, hi)) = best else { return false };
        self.apply_flip(tour, lo, hi, delta);
        true
    }

    /// Stretches `pv..=hi`, growing `hi`.
    fn flip_right(&self, tour: &Tour, lo: usize, best: &mut Option<(Cost, usize, usize)>) {
        let net = self.net;
        let n = tour.len();
        let p = tour.seq[lo - 1];
        let x_lo = tour.seq[lo];
        let mut table = Table::single(net, x_lo);
        // the stretch's present cost from p's arc on, without the arc out of x_hi
        let mut old = tour.arc(net, p, x_lo) + net.mode_cost(x_lo, tour.mode[x_lo as usize]);
        for hi in lo + 1..n.min(lo + WINDOW) {
            let x = tour.seq[hi];
            if net.has_prec && net.predecessors(x).iter().any(|&y| (lo..hi).contains(&(tour.pos[y as usize] as usize)))
            {
                break;
            }
            let prev = tour.seq[hi - 1];
            old += tour.arc(net, prev, x) + net.mode_cost(x, tour.mode[x as usize]);
            // x goes in front: x (mode c) -> old first x_{hi-1} (mode a) -> ... -> x_lo (mode b)
            let mx = net.num_modes(x) as usize;
            let mut next = Table { m: mx, cost: [Cost::INFINITY; (MAX_MODES * MAX_MODES) as usize] };
            for c in 0..mx {
                let own = net.mode_cost(x, c as u32);
                for b in 0..net.num_modes(x_lo) as usize {
                    let mut v = Cost::INFINITY;
                    for a in 0..table.m {
                        let t = table.at(a, b);
                        if t < Cost::INFINITY {
                            v = v.min(net.arc(x, c as u32, prev, a as u32) + t);
                        }
                    }
                    next.cost[c * MAX_MODES as usize + b] = own + v;
                }
            }
            table = next;
            let q = tour.next_of_pos(hi);
            let old_total = old + tour.arc(net, x, q);
            self.offer_flip_closed(tour, &table, p, x, x_lo, q, old_total, lo, hi, best);
        }
    }

    /// Stretches `lo..=pv`, growing downwards.
    fn flip_left(&self, tour: &Tour, hi: usize, best: &mut Option<(Cost, usize, usize)>) {
        let net = self.net;
        let x_hi = tour.seq[hi];
        let mut table = Table::single(net, x_hi);
        // the stretch's present cost up to q's arc, without the arc into x_lo
        let q = tour.next_of_pos(hi);
        let mut old = tour.arc(net, x_hi, q) + net.mode_cost(x_hi, tour.mode[x_hi as usize]);
        let floor = hi.saturating_sub(WINDOW - 1).max(1);
        for lo in (floor..hi).rev() {
            let x = tour.seq[lo];
            if net.has_prec
                && net.successors(x).iter().any(|&y| (lo + 1..=hi).contains(&(tour.pos[y as usize] as usize)))
            {
                break;
            }
            let after = tour.seq[lo + 1];
            old += tour.arc(net, x, after) + net.mode_cost(x, tour.mode[x as usize]);
            // x goes last: x_hi (mode a) -> ... -> old last x_{lo+1} (mode b) -> x (mode c)
            let mx = net.num_modes(x) as usize;
            let mut next = Table { m: table.m, cost: [Cost::INFINITY; (MAX_MODES * MAX_MODES) as usize] };
            let mb = net.num_modes(after) as usize;
            for a in 0..table.m {
                for c in 0..mx {
                    let mut v = Cost::INFINITY;
                    for b in 0..mb {
                        let t = table.at(a, b);
                        if t < Cost::INFINITY {
                            v = v.min(t + net.arc(after, b as u32, x, c as u32));
                        }
                    }
                    next.cost[a * MAX_MODES as usize + c] = v + net.mode_cost(x, c as u32);
                }
            }
            table = next;
            let p = tour.seq[lo - 1];
            let old_total = old + tour.arc(net, p, x);
            self.offer_flip_closed(tour, &table, p, x_hi, x, q, old_total, lo, hi, best);
        }
    }

    /// Offers the reversal of `lo..=hi` (new order p -> x_hi … x_lo -> q) against its present
    /// cost `old_total` (p's arc in to q's arc out).
    #[allow(clippy::too_many_arguments)]
    fn offer_flip_closed(
        &self,
        tour: &Tour,
        table: &Table,
        p: u32,
        x_hi: u32,
        x_lo: u32,
        q: u32,
        old_total: Cost,
        lo: usize,
        hi: usize,
        best: &mut Option<(Cost, usize, usize)>,
    ) {
        let net = self.net;
        let (mp, mq) = (tour.mode[p as usize], tour.mode[q as usize]);
        let mut new = Cost::INFINITY;
        for a in 0..table.m {
            let into = net.arc(p, mp, x_hi, a as u32);
            for b in 0..net.num_modes(x_lo) as usize {
                let t = table.at(a, b);
                if t < Cost::INFINITY {
                    new = new.min(into + t + net.arc(x_lo, b as u32, q, mq));
                }
            }
        }
        let delta = new - old_total;
        if delta < -self.eps && best.is_none_or(|(d, _, _)| delta < d) {
            *best = Some((delta, lo, hi));
        }
    }

    /// Reverses positions `lo..=hi` and gives the stretch its cheapest modes between its
    /// neighbours (a dynamic programme over the new order).
    fn apply_flip(&mut self, tour: &mut Tour, lo: usize, hi: usize, delta: Cost) {
        let net = self.net;
        let p = tour.seq[lo - 1];
        let q = tour.next_of_pos(hi);
        tour.reverse(lo, hi);
        let (mp, mq) = (tour.mode[p as usize], tour.mode[q as usize]);
        let len = hi - lo + 1;
        let m = MAX_MODES as usize;
        // f[k][c]: cheapest from p to the stretch's k-th task in mode c; from[k][c]: the mode
        // of the task before it
        let mut f = vec![Cost::INFINITY; len * m];
        let mut from = vec![0u32; len * m];
        let first = tour.seq[lo];
        for c in 0..net.num_modes(first) {
            f[c as usize] = net.arc(p, mp, first, c) + net.mode_cost(first, c);
        }
        relax_layers(net, &tour.seq[lo..=hi], m, &mut f, &mut from);
        let last = tour.seq[hi];
        let mut c = (0..net.num_modes(last))
            .min_by(|&a, &b| {
                let fa = f[(len - 1) * m + a as usize] + net.arc(last, a, q, mq);
                let fb = f[(len - 1) * m + b as usize] + net.arc(last, b, q, mq);
                fa.total_cmp(&fb)
            })
            .unwrap_or(0);
        for k in (0..len).rev() {
            let x = tour.seq[lo + k];
            tour.set_mode(x, c);
            c = from[k * m + c as usize];
        }
        tour.cost += delta;
        self.push(p);
        self.push(q);
        for k in lo..=hi {
            self.push(tour.seq[k]);
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{Metric, PointCost, StateId};
    use crate::model::{Mode, Problem, TaskId};
    use crate::search::neighbors::Neighbors;

    /// `n` courses with two modes each, like an AFP course and its reverse: mode 0 runs from a
    /// to b, mode 1 from b' to a', where the primed states stand 7 units above (the head turned
    /// round), so that no mode is another's reverse and the Lin–Kernighan chains do not run.
    /// Mode 1 costs a little more. Random precedence between tasks of a hidden order; an open
    /// route from a start state.
    fn courses(rng: &mut Pcg64Mcg, n: usize, edges: usize) -> Problem<PointCost> {
        let mut pts = Vec::new();
        for _ in 0..n {
            let (x, y) = (rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0));
            let (u, v) = (x + rng.gen_range(-30.0..30.0), y + rng.gen_range(-30.0..30.0));
            pts.extend([[x, y, 0.0], [u, v, 0.0], [u, v, 7.0], [x, y, 7.0]]);
        }
        pts.push([50.0, 50.0, 20.0]);
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in 0..n as u32 {
            let s = |k: u32| StateId(4 * t + k);
            b.task(vec![Mode { entry: s(0), exit: s(1), cost: 1.0 }, Mode { entry: s(2), exit: s(3), cost: 1.5 }]);
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            order.swap(i, rng.gen_range(0..=i));
        }
        for _ in 0..edges {
            let (i, j) = (rng.gen_range(0..n), rng.gen_range(0..n));
            if i < j {
                b.precede(TaskId(order[i]), TaskId(order[j]));
            }
        }
        b.start(StateId(4 * n as u32));
        b.build().expect("a valid problem")
    }

    /// A random route that keeps the precedence (a random topological order), random modes,
    /// the depot first.
    fn random_tour(net: &Net<'_, PointCost>, rng: &mut Pcg64Mcg) -> Tour {
        let n = net.n_tasks;
        let mut indegree = net.task_indegrees();
        let mut ready: Vec<u32> = (0..n as u32).filter(|&v| indegree[v as usize] == 0).collect();
        let mut seq = vec![net.depot];
        while !ready.is_empty() {
            let v = ready.swap_remove(rng.gen_range(0..ready.len()));
            seq.push(v);
            for &s in net.successors(v) {
                if (s as usize) < n {
                    indegree[s as usize] -= 1;
                    if indegree[s as usize] == 0 {
                        ready.push(s);
                    }
                }
            }
        }
        assert_eq!(seq.len(), net.n);
        let mut mode: Vec<u32> = (0..net.n).map(|_| rng.gen_range(0..2)).collect();
        mode[net.depot as usize] = 0;
        Tour::new(net, seq, mode)
    }

    fn keeps_precedence(net: &Net<'_, PointCost>, tour: &Tour) -> bool {
        (0..net.n_tasks as u32).all(|v| net.successors(v).iter().all(|&s| tour.pos[s as usize] > tour.pos[v as usize]))
    }

    /// The best reversal of `lo..=hi` by brute force: every mode of every task of the stretch
    /// turned round, priced arc by arc; `None` if two of its tasks are tied by precedence.
    fn brute_flip(net: &Net<'_, PointCost>, tour: &Tour, lo: usize, hi: usize) -> Option<Cost> {
        let stretch: Vec<u32> = tour.seq[lo..=hi].to_vec();
        for (i, &a) in stretch.iter().enumerate() {
            if stretch[i + 1..].iter().any(|&b| net.successors(a).contains(&b) || net.successors(b).contains(&a)) {
                return None;
            }
        }
        let (p, q) = (tour.seq[lo - 1], tour.next_of_pos(hi));
        let (mp, mq) = (tour.mode[p as usize], tour.mode[q as usize]);
        let mut old = tour.arc(net, p, stretch[0]) + tour.arc(net, stretch[stretch.len() - 1], q);
        for w in stretch.windows(2) {
            old += tour.arc(net, w[0], w[1]);
        }
        old += stretch.iter().map(|&x| net.mode_cost(x, tour.mode[x as usize])).sum::<Cost>();
        let turned: Vec<u32> = stretch.iter().rev().copied().collect();
        let mut best = Cost::INFINITY;
        for bits in 0..1u32 << turned.len() {
            let m = |k: usize| (bits >> k) & 1;
            let mut c = net.arc(p, mp, turned[0], m(0)) + net.arc(turned[turned.len() - 1], m(turned.len() - 1), q, mq);
            for k in 0..turned.len() {
                c += net.mode_cost(turned[k], m(k));
                if k + 1 < turned.len() {
                    c += net.arc(turned[k], m(k), turned[k + 1], m(k + 1));
                }
            }
            best = best.min(c);
        }
        Some(best - old)
    }

    /// From every task of random routes, the move finds the best reversal of a stretch of up
    /// to `WINDOW` tasks ending there (checked against every stretch and every choice of
    /// modes), applies exactly that gain, tracks the cost the route's arcs give, and never
    /// breaks the precedence.
    #[test]
    fn the_best_flip_is_found_and_priced_as_brute_force_says() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let mut applied = 0;
        for case in 0..40 {
            let n = rng.gen_range(6..16);
            let p = courses(&mut rng, n, if case % 2 == 0 { 0 } else { n });
            let net = Net::new(&p);
            assert!(applies(&net, false));
            let nb = Neighbors::build(&net, 5);
            let mut ls = LocalSearch::new(&net, &nb, 1e-9);
            assert!(ls.flip, "the move runs on courses whose reverse is no mode of theirs");
            for _ in 0..5 {
                let tour = random_tour(&net, &mut rng);
                for v in 0..net.n_tasks as u32 {
                    let pv = tour.pos[v as usize] as usize;
                    let mut best = Cost::INFINITY;
                    for len in 2..=WINDOW {
                        if pv + len - 1 < net.n {
                            best = best.min(brute_flip(&net, &tour, pv, pv + len - 1).unwrap_or(Cost::INFINITY));
                        }
                        if pv >= len {
                            best = best.min(brute_flip(&net, &tour, pv + 1 - len, pv).unwrap_or(Cost::INFINITY));
                        }
                    }
                    let mut t = tour.clone();
                    let found = ls.try_flip_window(&mut t, v);
                    ls.clear();
                    assert_eq!(found, best < -1e-9, "case {case}, task {v}: found {found}, brute force {best}");
                    if found {
                        applied += 1;
                        assert!((t.cost - tour.cost - best).abs() < 1e-9, "gain {} against {best}", t.cost - tour.cost);
                        assert!((t.cost - t.full_cost(&net)).abs() < 1e-9);
                        assert!(keeps_precedence(&net, &t));
                    }
                }
            }
        }
        assert!(applied > 100, "only {applied} flips applied");
    }

    /// A whole descent with the move (and Or-opt, the segment exchange, the mode change) ends
    /// where no reversal of a stretch of up to `WINDOW` tasks gains, with the cost tracked and
    /// the precedence kept.
    #[test]
    fn descents_end_where_no_short_reversal_gains() {
        let mut rng = Pcg64Mcg::seed_from_u64(12);
        for case in 0..30 {
            let n = rng.gen_range(8..20);
            let p = courses(&mut rng, n, n / 2 * (case % 3));
            let net = Net::new(&p);
            let nb = Neighbors::build(&net, 6);
            let mut tour = random_tour(&net, &mut rng);
            let mut ls = LocalSearch::new(&net, &nb, 1e-9);
            ls.push_all(&tour);
            ls.run(&mut tour);
            assert!((tour.cost - tour.full_cost(&net)).abs() < 1e-6);
            assert!(keeps_precedence(&net, &tour));
            for lo in 1..net.n {
                for hi in lo + 1..net.n.min(lo + WINDOW) {
                    if let Some(d) = brute_flip(&net, &tour, lo, hi) {
                        assert!(d >= -1e-6, "case {case}: reversing {lo}..={hi} still gains {d}");
                    }
                }
            }
        }
    }
}
