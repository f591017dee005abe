//! Iterated local search: segment-swap (double-bridge) kicks followed by local search, accepted
//! when not worse, run on several threads in epochs that end by adopting the best tour. Under a
//! work budget the epochs are fixed counts of kicks, so a given seed and thread count always
//! produce the same answer.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::local::LocalSearch;
use super::modes::{optimize_modes, optimize_modes_noting};
use super::neighbors::Neighbors;
use super::net::Net;
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

/// Longest segment a segment-swap kick moves.
const KICK_SEGMENT: usize = 50;

/// Longest segment of a four-arc double bridge: long enough to move whole neighbourhoods on
/// tours of thousands of nodes (measured against 50, 100 and 500 on TSPLIB; see the history).
const BRIDGE_SEGMENT: usize = 200;

/// Kicks without a new best, per node, after which a restless [`Chain`] restarts.
const RESTLESS_AFTER: u64 = 1;

/// One kick in this many of a restless chain is a double bridge cut at four long arcs (see
/// [`Ils::long_arc_cuts`]).
const LONG_BRIDGE_ONE_IN: u32 = 16;

/// An arc is long when it costs more than this many times the tour's mean arc.
const LONG_ARC_FACTOR: Cost = 3.0;

/// Long-arc bridges on tours up to this size. On Gaussian clusters (10 s, 2 threads, medians of
/// 3-9 seeds) they gained 0.1 % at 2,000 points (40 clusters), were neutral at 5,000 (60) and
/// lost 0.17 % at 10,000 (100): four long arcs drawn among many reorder clusters too far apart.
const LONG_BRIDGE_UP_TO: usize = 5_000;

/// Ruin-and-recreate kicks are used on instances up to this size (they cost O(n) each).
const REBUILD_UP_TO: usize = 5000;

/// Mode of `v`: as just reinserted, else as in the tour.
fn mode_of(tour: &Tour, fresh: &[(u32, u32)], v: u32) -> u32 {
    fresh.iter().find(|&&(x, _)| x == v).map_or(tour.mode[v as usize], |&(_, m)| m)
}

/// One search chain (one per thread): its current and best tours, random state and how long it
/// has gone without improving.
pub(crate) struct Chain {
    pub cur: Tour,
    pub best: Tour,
    pub rng: Pcg64Mcg,
    pub stagnation: u64,
    /// Restarts from a perturbed best after [`RESTLESS_AFTER`] × n kicks without a new best
    /// (instead of 16 × n), and now and then kicks with a double bridge at long arcs: a chain
    /// that leaves its basin often, which pays on clustered geometry (whole clusters in the
    /// wrong order), where the other chains keep deepening.
    pub restless: bool,
    /// Builds a start of its own (see [`Ils::fresh_start`]) before its first kick: a chain of
    /// the population (see `population`).
    pub fresh: bool,
}

impl Chain {
    pub fn new(start: &Tour, seed: u64) -> Self {
        Chain {
            cur: start.clone(),
            best: start.clone(),
            rng: Pcg64Mcg::seed_from_u64(seed),
            stagnation: 0,
            restless: false,
            fresh: false,
        }
    }

    /// Adopts `tour` as both current and best.
    pub fn adopt(&mut self, tour: &Tour) {
        self.cur.clone_from(tour);
        self.best.clone_from(tour);
        // a restless chain keeps counting: its next restart perturbs the adopted tour
        if !self.restless {
            self.stagnation = 0;
        }
    }
}

/// What one ILS run may spend.
#[derive(Clone, Copy)]
pub(crate) struct Budget {
    pub kicks: u64,
    /// No new kick after this (the end of an epoch or of the search).
    pub deadline: Option<Instant>,
    /// The end of the search: a local search still running then is cut short and its kick
    /// undone, so that the best tour is always a local optimum.
    pub hard: Option<Instant>,
    /// Acceptance temperature: a kick that makes the tour dearer by Δ is kept with probability
    /// exp(-Δ / temperature) (0: only kicks that do not make it dearer).
    pub temperature: Cost,
    /// Record-to-record slack: a kick whose tour costs at most the chain's best plus this is
    /// kept even when dearer than the tour it was applied to (0: no slack).
    pub slack: Cost,
}

pub(crate) struct Ils<'a, 'p, C> {
    net: &'a Net<'p, C>,
    nb: &'a Neighbors,
    eps: Cost,
    /// Run the exact mode DP after each local search (when it is cheap enough).
    dp_each_kick: bool,
    /// Use ruin-and-recreate kicks (for precedence, groups or modes, where double bridges
    /// are often infeasible or blind to modes).
    rebuild: bool,
    /// Kick with a four-arc double bridge (the local search has sequential 3-opt steps).
    bridge4: bool,
    /// Kick with the precedence-keeping double bridge (the local search has the whole
    /// SOP-3-exchange neighbourhood, which undoes any segment swap that does not pay).
    sop3_bridge: bool,
    /// Kicks without a new best after which the chain restarts from a heavily perturbed copy
    /// of its best tour.
    restart_after: u64,
    /// First-level moves the kicks' 3-opt chains backtrack over (see
    /// [`SolveOptions::lk_breadth`]); the descents and polishes keep 1.
    ///
    /// [`SolveOptions::lk_breadth`]: crate::SolveOptions::lk_breadth
    breadth1: usize,
}

impl<'a, 'p, C: CostModel> Ils<'a, 'p, C> {
    pub fn new(net: &'a Net<'p, C>, nb: &'a Neighbors, eps: Cost) -> Self {
        let mm = net.p.max_modes();
        let dp_each_kick = net.multi_mode && net.n * mm * mm <= 20_000;
        let rebuild = net.n <= REBUILD_UP_TO && (net.has_prec || net.has_groups || net.multi_mode);
        let bridge4 = super::local::uses_or3(net);
        let sop3_bridge = super::sop3::applies(net);
        let restart_after = 16 * net.n as u64 + 200;
        Ils { net, nb, eps, dp_each_kick, rebuild, bridge4, sop3_bridge, restart_after, breadth1: 1 }
    }

    /// The same search with the kicks' chains backtracking over `breadth1` first-level moves.
    pub fn with_breadth(self, breadth1: usize) -> Self {
        Ils { breadth1, ..self }
    }

    /// Brings a tour to a local optimum of the moves and the mode DP.
    pub fn descend(&self, tour: &mut Tour, deadline: Option<Instant>) -> u64 {
        let mut ls = LocalSearch::new(self.net, self.nb, self.eps);
        ls.deadline = deadline;
        ls.push_all(tour);
        loop {
            ls.run(tour);
            if deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
            if !optimize_modes(self.net, tour, self.eps) {
                break;
            }
            ls.push_all(tour);
        }
        ls.moves
    }

    /// A start of its own for a chain of a plain tour: nearest neighbour from a random first
    /// node, looking only at candidate neighbours while one is unvisited (else at every
    /// unvisited node), brought to a local optimum.
    pub fn fresh_start(&self, rng: &mut Pcg64Mcg, deadline: Option<Instant>) -> Tour {
        let net = self.net;
        let n = net.n;
        let first = rng.gen_range(0..n as u32);
        let seq = super::construct::nearest_neighbor_by_lists(net, self.nb, first);
        let mut tour = Tour::new(net, seq, vec![0; n]);
        self.descend(&mut tour, deadline);
        tour
    }

    /// Brings a tour back to a local optimum after changes at `nodes` (only those are looked
    /// at first). Returns false when the deadline cut the search short.
    pub fn polish(&self, tour: &mut Tour, nodes: &[u32], deadline: Option<Instant>) -> bool {
        let mut ls = LocalSearch::new(self.net, self.nb, self.eps);
        ls.deadline = deadline;
        for &v in nodes {
            ls.push(v);
        }
        ls.run(tour);
        !ls.cut
    }

    /// Runs kicks on a chain's state and returns the kicks done.
    pub fn run(&self, state: &mut Chain, budget: Budget, cancel: Option<&AtomicBool>) -> u64 {
        let Chain { cur, best, rng, stagnation, restless, .. } = state;
        let restart_after = if *restless { RESTLESS_AFTER * cur.len() as u64 + 200 } else { self.restart_after };
        let mut ls = LocalSearch::new(self.net, self.nb, self.eps);
        ls.deadline = budget.hard;
        ls.breadth1 = self.breadth1;
        let n = cur.len();
        let long_bridges = *restless && self.bridge4 && n <= LONG_BRIDGE_UP_TO;
        let mut kicks = 0u64;
        let mut changed = Vec::new();
        if n < 3 {
            return 0;
        }
        while kicks < budget.kicks {
            // A kick costs microseconds at least, reading the clock tens of nanoseconds.
            if budget.deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                break;
            }
            kicks += 1;
            if *stagnation >= restart_after {
                // Long stagnation: restart from a heavily perturbed copy of the best tour.
                *stagnation = 0;
                cur.clone_from(best);
                cur.begin();
                for _ in 0..(n / 6).max(2) {
                    if self.rebuild {
                        self.ruin_recreate(cur, rng, &mut ls);
                    } else {
                        self.kick(cur, rng, &mut ls, false);
                    }
                }
                if self.dp_each_kick {
                    optimize_modes(self.net, cur, self.eps);
                }
                ls.run(cur);
                cur.commit();
                if ls.cut {
                    break;
                }
                continue;
            }
            let before = cur.cost;
            cur.begin();
            // Kicks grow stronger while the search stagnates.
            let strength = 1 + (*stagnation / (4 * n as u64 + 50)).min(3) as usize;
            let mut kicked = false;
            let rebuild = self.rebuild && rng.gen_bool(0.5);
            for _ in 0..strength {
                kicked |= if rebuild {
                    self.ruin_recreate(cur, rng, &mut ls)
                } else {
                    self.kick(cur, rng, &mut ls, long_bridges)
                };
            }
            if !kicked {
                cur.undo();
                continue;
            }
            if self.dp_each_kick {
                // give the kicked order its best modes before the local search can undo it
                optimize_modes(self.net, cur, self.eps);
            }
            ls.run(cur);
            if self.dp_each_kick {
                // re-examine only around the nodes whose mode the DP changed
                changed.clear();
                if optimize_modes_noting(self.net, cur, self.eps, &mut changed) {
                    for &v in &changed {
                        ls.push(v);
                        ls.push(cur.prev(v));
                        ls.push(cur.next(v));
                    }
                    ls.run(cur);
                }
            }
            if ls.cut {
                // out of time in the middle of the local search
                cur.undo();
                break;
            }
            *stagnation += 1;
            if cur.cost <= before + self.eps * 0.5 {
                cur.commit();
                if cur.cost < best.cost - self.eps {
                    *stagnation = 0;
                    best.seq.copy_from_slice(&cur.seq);
                    best.pos.copy_from_slice(&cur.pos);
                    best.mode.copy_from_slice(&cur.mode);
                    best.cost = cur.cost;
                }
            } else if budget.slack > 0.0 && cur.cost <= best.cost + budget.slack {
                // record-to-record travel: the walk may drift a little above its best
                cur.commit();
            } else if budget.temperature > 0.0 && self.accept_worse(cur.cost - before, budget.temperature, rng) {
                cur.commit();
            } else {
                cur.undo();
            }
        }
        kicks
    }

    /// Simulated-annealing acceptance of a kick that made the tour dearer by `delta`.
    fn accept_worse(&self, delta: Cost, temperature: Cost, rng: &mut Pcg64Mcg) -> bool {
        // a forbidden transition is never kept
        delta < 0.5 * self.net.forbidden && rng.gen::<f64>() < (-delta / temperature).exp()
    }

    /// A segment-swap kick: exchanges two short adjacent segments, if precedence and groups
    /// allow (the four-arc double bridge instead where the local search has 3-opt steps; with
    /// `long_bridges`, one in [`LONG_BRIDGE_ONE_IN`] of those is cut at long arcs). Dirty nodes
    /// go onto the local search queue.
    fn kick(&self, tour: &mut Tour, rng: &mut Pcg64Mcg, ls: &mut LocalSearch<'_, '_, C>, long_bridges: bool) -> bool {
        let net = self.net;
        let n = tour.len();
        if self.bridge4 && n >= 8 {
            let long = long_bridges && rng.gen_ratio(1, LONG_BRIDGE_ONE_IN);
            return self.double_bridge(tour, rng, ls, long);
        }
        if self.sop3_bridge {
            if let Some(ends) = super::sop3::bridge(net, tour, rng) {
                for x in ends {
                    ls.push(x);
                }
                return true;
            }
        }
        let max_len = (n / 2).clamp(1, KICK_SEGMENT);
        for _attempt in 0..20 {
            let l1 = rng.gen_range(1..=max_len);
            let l2 = rng.gen_range(1..=max_len);
            if l1 + l2 + 1 > n {
                continue;
            }
            let mut i = rng.gen_range(1..=n - l1 - l2);
            let mut j = i + l1 - 1;
            let mut k = j + l2;
            if net.has_groups {
                let (bs, be) = ls.block(tour, i);
                if be > bs && rng.gen_bool(0.5) {
                    // a kick inside one group block
                    i = rng.gen_range(bs..be);
                    j = rng.gen_range(i..be);
                    k = rng.gen_range(j + 1..=be);
                } else {
                    // cut only at block boundaries
                    i = bs;
                    j = ls.block(tour, j.max(i)).1;
                    if j + 1 >= n {
                        continue;
                    }
                    k = ls.block(tour, k.max(j + 1)).1;
                }
            }
            if net.has_prec {
                // grow the second segment only while it holds no successor of the first
                match self.feasible_end(tour, i, j, k) {
                    Some(kk) => k = kk,
                    None => continue,
                }
            }
            if !net.partner.is_empty() {
                let mut cuts = [i - 1, j, k];
                if !self.clear_of_fixed(tour, &mut cuts) {
                    continue;
                }
                (i, j, k) = (cuts[0] + 1, cuts[1], cuts[2]);
            }
            let (p, a, b, c, d, q) =
                (tour.seq[i - 1], tour.seq[i], tour.seq[j], tour.seq[j + 1], tour.seq[k], tour.next_of_pos(k));
            if !net.move_allowed(&tour.seq, &[(p, a), (b, c), (d, q)], i, k) {
                continue;
            }
            let old = tour.arc(net, p, a) + tour.arc(net, b, c) + tour.arc(net, d, q);
            let new = tour.arc(net, p, c) + tour.arc(net, d, a) + tour.arc(net, b, q);
            tour.swap_adjacent(i, j, k);
            tour.cost += new - old;
            for x in [p, a, b, c, d, q] {
                ls.push(x);
            }
            return true;
        }
        false
    }

    /// The double bridge of Martin, Otto and Felten on three short consecutive segments: A B C D
    /// becomes A D C B, four arcs changed in two alternating cycles, which no sequential move
    /// undoes in one step. Plain symmetric one-mode tours only (no precedence, groups or modes).
    /// With `long`, the cuts are at long arcs instead (see [`Ils::long_arc_cuts`]) where the
    /// tour has four.
    fn double_bridge(&self, tour: &mut Tour, rng: &mut Pcg64Mcg, ls: &mut LocalSearch<'_, '_, C>, long: bool) -> bool {
        let cuts = match long.then(|| self.long_arc_cuts(tour, rng)).flatten() {
            Some(cuts) => cuts,
            None => {
                let n = tour.len();
                let max_len = ((n - 2) / 3).clamp(1, BRIDGE_SEGMENT);
                let (l1, l2, l3) = (rng.gen_range(1..=max_len), rng.gen_range(1..=max_len), rng.gen_range(1..=max_len));
                let i = rng.gen_range(1..=n - l1 - l2 - l3);
                let mut cuts = [i - 1, i + l1 - 1, i + l1 + l2 - 1, i + l1 + l2 + l3 - 1];
                if !self.clear_of_fixed(tour, &mut cuts) {
                    return false;
                }
                cuts
            }
        };
        let [h, j, k, l] = cuts;
        for x in tour.double_bridge(self.net, h + 1, j, k, l) {
            ls.push(x);
        }
        true
    }

    /// Four cuts (increasing positions; `c` cuts the arc from position `c` to the next) at arcs
    /// drawn at random among those dearer than [`LONG_ARC_FACTOR`] × the mean arc, none on a
    /// fixed edge; `None` when there are fewer than four. On clustered points the long arcs join
    /// the clusters, and the double bridge on them puts three runs of whole clusters in another
    /// order, which the short bridges (and every sequential move whose arcs are on the candidate
    /// lists) cannot: on 2,000 points in 40 Gaussian clusters, two of three seeds ended 0.7 %
    /// above the third with the clusters in another order before these kicks.
    fn long_arc_cuts(&self, tour: &Tour, rng: &mut Pcg64Mcg) -> Option<[usize; 4]> {
        // (fixed edges are priced far below zero: the mean is over the others)
        let arcs: Vec<(usize, Cost)> = (0..tour.len())
            .filter_map(|p| {
                let (a, b) = (tour.seq[p], tour.next_of_pos(p));
                (!self.net.fixed(a, b)).then(|| (p, tour.arc(self.net, a, b)))
            })
            .collect();
        let limit = LONG_ARC_FACTOR * arcs.iter().map(|&(_, x)| x).sum::<Cost>() / arcs.len().max(1) as Cost;
        let long: Vec<usize> = arcs.iter().filter(|&&(_, x)| x > limit).map(|&(p, _)| p).collect();
        if long.len() < 4 {
            return None;
        }
        let mut picked = rand::seq::index::sample(rng, long.len(), 4).into_vec();
        picked.sort_unstable();
        Some([long[picked[0]], long[picked[1]], long[picked[2]], long[picked[3]]])
    }

    /// Moves each cut (`c` cuts the arc from position `c` to the next) off a fixed edge (see
    /// `Net::partner`; a neighbouring arc is never fixed too), keeping the cuts strictly
    /// increasing within the tour. False when they cannot be.
    fn clear_of_fixed(&self, tour: &Tour, cuts: &mut [usize]) -> bool {
        let net = self.net;
        if net.partner.is_empty() {
            return true;
        }
        let n = tour.len();
        for x in 0..cuts.len() {
            let c = cuts[x];
            if net.fixed(tour.seq[c], tour.next_of_pos(c)) {
                let lower = if x == 0 { 0 } else { cuts[x - 1] + 1 };
                cuts[x] = if c > lower { c - 1 } else { c + 1 };
            }
        }
        cuts.windows(2).all(|w| w[0] < w[1]) && cuts[cuts.len() - 1] < n
    }

    /// Ruin and recreate: removes a few neighbouring tasks and puts each back at its cheapest
    /// feasible place with its best mode (precedence windows and groups respected).
    fn ruin_recreate(&self, tour: &mut Tour, rng: &mut Pcg64Mcg, ls: &mut LocalSearch<'_, '_, C>) -> bool {
        let net = self.net;
        let n = tour.len();
        let k = rng.gen_range(2..=6usize).min(n / 3);
        if k == 0 {
            return false;
        }
        let free = |v: u32| {
            tour.pos[v as usize] != 0 && v != net.depot && (!net.has_groups || net.group(v) == crate::model::NO_GROUP)
        };
        let v = tour.seq[rng.gen_range(1..n)];
        if !free(v) {
            return false;
        }
        let mut removed = vec![v];
        for &u in self.nb.out(v).iter().chain(self.nb.inn(v)) {
            if removed.len() >= k {
                break;
            }
            if free(u) && !removed.contains(&u) && rng.gen_bool(0.7) {
                removed.push(u);
            }
        }
        for x in &removed {
            let (p, q) = (tour.prev(*x), tour.next(*x));
            ls.push(p);
            ls.push(q);
        }
        let mut rest: Vec<u32> = tour.seq.iter().copied().filter(|x| !removed.contains(x)).collect();
        // shuffle the insertion order, then put predecessors first
        for a in (1..removed.len()).rev() {
            removed.swap(a, rng.gen_range(0..=a));
        }
        if net.has_prec {
            removed.sort_by_key(|&x| net.topo_rank[x as usize]);
        }
        let mut modes: Vec<(u32, u32)> = Vec::with_capacity(removed.len());
        for (idx, &x) in removed.iter().enumerate() {
            let (lo, hi) = self.window(&rest, x, &removed[idx + 1..]);
            let mut best = (Cost::INFINITY, usize::MAX, 0u32);
            for at in lo..=hi {
                let c = rest[at];
                let d = rest[if at + 1 == rest.len() { 0 } else { at + 1 }];
                if net.has_groups && net.inside_group(c, d) {
                    continue;
                }
                let (mc, md) = (mode_of(tour, &modes, c), mode_of(tour, &modes, d));
                let base = net.arc(c, mc, d, md);
                for m in 0..net.num_modes(x) {
                    let add = net.arc(c, mc, x, m) + net.mode_cost(x, m) + net.arc(x, m, d, md) - base;
                    if add < best.0 {
                        best = (add, at, m);
                    }
                }
            }
            if best.1 == usize::MAX {
                return false;
            }
            rest.insert(best.1 + 1, x);
            modes.push((x, best.2));
        }
        tour.overwrite(net, &rest, &modes);
        for x in removed {
            ls.push(x);
        }
        true
    }

    /// Positions `lo..=hi` after which `x` may be inserted into `rest` (x not in it). `pending`
    /// are removed tasks still to be reinserted (all later in topological order): the successors
    /// of a pending successor count as successors of `x`.
    fn window(&self, rest: &[u32], x: u32, pending: &[u32]) -> (usize, usize) {
        let net = self.net;
        if !net.has_prec {
            return (0, rest.len() - 1);
        }
        let preds = net.predecessors(x);
        let mut succs: Vec<u32> = Vec::new();
        let mut stack: Vec<u32> = net.successors(x).to_vec();
        while let Some(y) = stack.pop() {
            if pending.contains(&y) {
                stack.extend_from_slice(net.successors(y));
            } else if !succs.contains(&y) {
                succs.push(y);
            }
        }
        let mut lo = 0;
        let mut hi = rest.len() - 1;
        for (i, &v) in rest.iter().enumerate() {
            if preds.contains(&v) {
                lo = i;
            }
            if succs.contains(&v) {
                hi = hi.min(i.saturating_sub(1));
            }
        }
        debug_assert!(lo <= hi, "precedence window empty for {x}: rest {rest:?} preds {preds:?} succs {succs:?}");
        (lo, hi.max(lo))
    }

    /// The largest `k' <= k` such that segments i..=j and j+1..=k' can trade places (nothing in
    /// the first precedes anything in the second), if any.
    fn feasible_end(&self, tour: &Tour, i: usize, j: usize, k: usize) -> Option<usize> {
        let net = self.net;
        let mut end = k;
        for t in i..=j {
            for &s in net.successors(tour.seq[t]) {
                let ps = tour.pos[s as usize] as usize;
                if ps > j && ps <= end {
                    end = ps - 1;
                }
            }
        }
        (end > j).then_some(end)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{Metric, PointCost, StateId};
    use crate::model::{Mode, Problem};

    /// `clusters` tight groups of `per` points on a circle of radius 1,000 (σ about 10).
    fn clustered(rng: &mut Pcg64Mcg, clusters: usize, per: usize) -> Problem<PointCost> {
        let mut pts = Vec::new();
        for c in 0..clusters {
            let a = c as f64 * std::f64::consts::TAU / clusters as f64;
            let (cx, cy) = (1000.0 * a.cos(), 1000.0 * a.sin());
            for _ in 0..per {
                pts.push([cx + rng.gen_range(-15.0..15.0), cy + rng.gen_range(-15.0..15.0), 0.0]);
            }
        }
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for k in 0..(clusters * per) as u32 {
            b.task(vec![Mode::point(StateId(k))]);
        }
        b.build().expect("a point per task is a valid problem")
    }

    fn arcs(tour: &Tour) -> BTreeSet<(u32, u32)> {
        (0..tour.len())
            .map(|p| {
                let (a, b) = (tour.seq[p], tour.next_of_pos(p));
                (a.min(b), a.max(b))
            })
            .collect()
    }

    /// The long-arc bridge cuts four arcs dearer than three times the mean arc, in increasing
    /// positions; the double bridge on them replaces exactly those four arcs, keeps every
    /// node once and tracks the cost.
    #[test]
    fn long_arc_bridges_cut_long_arcs_only() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let (clusters, per) = (12, 20);
        let p = clustered(&mut rng, clusters, per);
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 8);
        let ils = Ils::new(&net, &nb, 1e-9);
        let n = clusters * per;
        // the clusters in a scrambled order, each visited in one run
        let mut order: Vec<usize> = (0..clusters).collect();
        for i in (1..clusters).rev() {
            order.swap(i, rng.gen_range(0..=i));
        }
        let seq: Vec<u32> = order.iter().flat_map(|&c| (c * per..(c + 1) * per).map(|v| v as u32)).collect();
        let mut tour = Tour::new(&net, seq, vec![0; n]);
        for _ in 0..50 {
            let mean = tour.full_cost(&net) / n as Cost;
            let cuts = ils.long_arc_cuts(&tour, &mut rng).expect("the arcs between clusters are long");
            assert!(cuts.windows(2).all(|w| w[0] < w[1]), "{cuts:?}");
            let before = arcs(&tour);
            let mut cut_arcs = BTreeSet::new();
            for &c in &cuts {
                let (a, b) = (tour.seq[c], tour.next_of_pos(c));
                assert!(tour.arc(&net, a, b) > LONG_ARC_FACTOR * mean);
                cut_arcs.insert((a.min(b), a.max(b)));
            }
            let [h, j, k, l] = cuts;
            tour.double_bridge(&net, h + 1, j, k, l);
            let after = arcs(&tour);
            assert_eq!(before.difference(&after).copied().collect::<BTreeSet<_>>(), cut_arcs);
            assert_eq!(after.difference(&before).count(), 4);
            let mut seen = tour.seq.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
            assert!((tour.cost - tour.full_cost(&net)).abs() < 1e-6 * tour.cost);
        }
    }

    /// A tour with fewer than four long arcs gives no long-arc bridge.
    #[test]
    fn no_long_arc_bridge_without_four_long_arcs() {
        let n = 60u32;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / n as f64;
                [100.0 * a.cos(), 100.0 * a.sin(), 0.0]
            })
            .collect();
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for k in 0..n {
            b.task(vec![Mode::point(StateId(k))]);
        }
        let p = b.build().expect("valid");
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 8);
        let ils = Ils::new(&net, &nb, 1e-9);
        let tour = Tour::new(&net, (0..n).collect(), vec![0; n as usize]);
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        assert!(ils.long_arc_cuts(&tour, &mut rng).is_none());
    }

    /// Record-to-record acceptance: with a slack the walk goes above its best (some kicks are
    /// kept dearer) but never by more than the slack, and the best stays the cheapest tour the
    /// walk has had; with no slack the walk never goes above its best. Costs are checked
    /// against a full re-pricing after every kick (1,500 kicks: fewer than a restart needs).
    #[test]
    fn record_to_record_walks_stay_within_the_slack() {
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let p = clustered(&mut rng, 12, 20);
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 8);
        let ils = Ils::new(&net, &nb, 1e-9);
        let n = net.n as u32;
        let start = Tour::new(&net, (0..n).collect(), vec![0; n as usize]);
        let mean_arc = start.full_cost(&net) / n as Cost;
        for slack in [0.0, 0.5 * mean_arc] {
            let mut chain = Chain::new(&start, 7);
            let budget = Budget { kicks: 1, deadline: None, hard: None, temperature: 0.0, slack };
            let (mut above, mut cheapest) = (0, Cost::INFINITY);
            for _ in 0..1_500 {
                ils.run(&mut chain, budget, None);
                let (cur, best) = (chain.cur.full_cost(&net), chain.best.full_cost(&net));
                assert!((cur - chain.cur.cost).abs() < 1e-6 * cur && (best - chain.best.cost).abs() < 1e-6 * best);
                assert!(cur <= best + slack + 1e-6, "walk {cur} above best {best} + slack {slack}");
                cheapest = cheapest.min(cur);
                assert!(best <= cheapest + 1e-6, "best {best} dearer than a tour of the walk {cheapest}");
                above += usize::from(cur > best + 1e-6);
            }
            assert_eq!(above > 0, slack > 0.0, "slack {slack}: the walk was above its best {above} times");
        }
    }
}
