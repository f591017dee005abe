//! Local search driven by a queue of "dirty" nodes (don't-look bits): mode change; Lin–Kernighan
//! chains of 2-opt reversals (reversal-symmetric tours, also under precedence) or, on plain
//! symmetric one-mode tours, of sequential 3-opt moves (`lk3`); Or-opt (segments of 1–3 tasks
//! and whole group blocks, optionally reversed); and the segment exchange (path-preserving
//! 3-opt); where tasks have modes but no chains run, reversals of short stretches with their
//! modes chosen afresh (`window_flip`). Moves respect precedence (checked incrementally by marking the moved segment's
//! successors or predecessors while scanning outwards) and consecutive groups (see
//! [`Net::move_allowed`]).

use std::collections::VecDeque;
use std::time::Instant;

use super::neighbors::Neighbors;
use super::net::{Net, NO_REV};
use super::sop3::{self, Sop3};
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

pub(crate) mod lk3;
mod window_flip;

/// Longest segment Or-opt moves.
const MAX_SEGMENT: usize = 3;

/// With precedence, Or-opt scans positions near the segment (up to `SCAN_RADIUS` each way, stopping
/// at the first precedence conflict) on instances up to this size, and uses candidate lists above.
const SCAN_UP_TO: usize = 400;

/// How far the precedence scan looks each way. Short scans measured better per unit of time on
/// TSPLIB SOP and SOPLIB than full scans (more kicks, equal or better tours).
const SCAN_RADIUS: usize = 10;

/// Longest segments the segment exchange considers.
const SWAP_WINDOW: usize = 64;

/// Deepest chain of reversals in a Lin–Kernighan move.
const LK_DEPTH: usize = 6;

/// Alternatives tried at the first level of a Lin–Kernighan move on tours of at least
/// `LK_BREADTH_FROM` nodes without 3-opt steps (deeper levels, and every level on smaller
/// tours, are greedy): backtracking pays on tours of thousands of nodes, not on smaller ones.
const LK_BREADTH: usize = 3;
const LK_BREADTH_FROM: usize = 2000;
/// Above this size the first level stays greedy: backtracking from a space-filling-curve start
/// on 100,000-node tours takes most of a minute before the first kick.
const LK_BREADTH_UP_TO: usize = 20_000;
/// Largest tour searched with chains of sequential 3-opt moves. Uniform random points, 10 s, 2
/// threads, against 2-opt chains above 20,000 nodes: 30,000 points 125,211,317 -> 124,292,790,
/// 45,000 153,727,740 -> 152,538,292, 100,000 230,592,768 -> 228,328,860 (seed 1 each).
const OR3_UP_TO: usize = 100_000;

/// Longest tentative reversal of a Lin–Kernighan step on tours above `LK_BREADTH_UP_TO` nodes,
/// where an array reversal of half the tour costs more than the rest of the step.
const LK_TENTATIVE_HUGE: usize = 1000;

/// One 2-opt step of a Lin–Kernighan chain: reverses positions `lo..=hi` (adding t2–t3,
/// removing t3–t4, so that t4 is the chain's new end), changing the cost by `step`; `g2` is
/// the partial gain after it.
#[derive(Clone, Copy)]
struct LkStep {
    lo: usize,
    hi: usize,
    step: Cost,
    t3: u32,
    t4: u32,
    g2: Cost,
}

pub(crate) struct LocalSearch<'a, 'p, C> {
    net: &'a Net<'p, C>,
    nb: &'a Neighbors,
    pub eps: Cost,
    queue: VecDeque<u32>,
    queued: Vec<bool>,
    mark: Vec<u32>,
    stamp: u32,
    two_opt: bool,
    /// Scan at most this many positions each way when precedence forces scanning.
    scan_limit: usize,
    pub deadline: Option<Instant>,
    /// Set when a run stopped at the deadline with work left (the tour may not be a local
    /// optimum).
    pub cut: bool,
    /// Moves applied since creation (for statistics).
    pub moves: u64,
    /// Endpoints of the arcs changed by the current Lin–Kernighan chain.
    lk_touched: Vec<u32>,
    /// `touch_mark[v] == touch_stamp` while `v` is in `lk_touched`.
    touch_mark: Vec<u32>,
    touch_stamp: u32,
    /// Scratch list of (position, node) candidates for the segment exchange.
    cands: Vec<(usize, u32)>,
    /// Alternatives tried at the first level of a Lin–Kernighan move.
    lk_breadth: usize,
    /// Scratch lists of Lin–Kernighan steps: the first level's alternatives and a deeper
    /// level's best step.
    lk_alts: Vec<LkStep>,
    lk_one: Vec<LkStep>,
    /// Longest stretch a Lin–Kernighan step reverses tentatively (closings are priced whatever
    /// their length).
    lk_max_tentative: usize,
    /// Lin–Kernighan chains are made of sequential 3-opt moves (plain symmetric one-mode
    /// tours, see [`uses_or3`] and `lk3`).
    lk3: bool,
    /// Arcs the current chain of 3-opt moves added and removed.
    lk3_added: Vec<(u32, u32)>,
    lk3_removed: Vec<(u32, u32)>,
    /// First-level moves a 3-opt chain backtracks over.
    pub breadth1: usize,
    /// The exhaustive SOP-3-exchange, where it applies (see `sop3::applies`).
    sop3: Option<Sop3>,
    /// Short reversals with their modes chosen afresh (see `window_flip`).
    flip: bool,
}

/// Whether Or-opt and the segment exchange apply the positive-gain criterion: a move whose
/// first new arc costs at least what removing the old arcs gained is not tried (with symmetric
/// costs it cannot pay off; with asymmetric ones it rarely does, as in Lin–Kernighan searches).
/// Applied with one mode per task whatever the symmetry: on TSPLIB SOP, SOPLIB and ATSP
/// instances at 10 s on 2 cores it gave 2-6x more kicks and equal or better tours (prob.100
/// 1292 -> 1223, kro124p.3 50168 -> 49977, medians of 2 seeds; the ATSP and the other SOP
/// instances stayed at their optima or best knowns). With several modes only when they are a
/// task's orientations (measured faster at equal quality on rural-postman instances), not when
/// they are alternative places (GTSP clusters, where it cost quality).
fn prunes_by_gain<C: CostModel>(net: &Net<'_, C>) -> bool {
    !net.multi_mode || (net.reversal_symmetric && !net.modes_self_reverse)
}

/// Whether Lin–Kernighan chains use sequential 3-opt steps: plain symmetric one-mode tours
/// without precedence or groups, up to `OR3_UP_TO` nodes. The kicks must then change four
/// arcs (see `Ils::kick`): the segment exchange the other kicks make is such a step, and the
/// local search would simply undo it.
pub(crate) fn uses_or3<C: CostModel>(net: &Net<'_, C>) -> bool {
    net.plain_symmetric && !net.multi_mode && !net.has_prec && !net.has_groups && net.n <= OR3_UP_TO
}

/// Plain tours: the 3-opt chains' problems ([`uses_or3`]) with no two-way tasks (no fixed
/// partner edges). The population, the list start and the record-to-record acceptance are for
/// these.
pub(crate) fn plain_tour<C: CostModel>(net: &Net<'_, C>) -> bool {
    uses_or3(net) && net.partner.is_empty()
}

/// An improving Or-opt move found by the scans.
#[derive(Clone, Copy)]
struct Insertion {
    k: usize,
    reversed: bool,
    mode: u32,
    delta: Cost,
}

impl<'a, 'p, C: CostModel> LocalSearch<'a, 'p, C> {
    pub fn new(net: &'a Net<'p, C>, nb: &'a Neighbors, eps: Cost) -> Self {
        let or3 = uses_or3(net);
        let two_opt = net.reversal_symmetric && (!net.has_prec || !net.multi_mode);
        LocalSearch {
            net,
            nb,
            eps,
            queue: VecDeque::new(),
            queued: vec![false; net.n],
            mark: vec![0; net.n],
            stamp: 0,
            two_opt,
            scan_limit: SCAN_RADIUS,
            deadline: None,
            cut: false,
            moves: 0,
            lk_touched: Vec::new(),
            touch_mark: vec![0; net.n],
            touch_stamp: 1,
            cands: Vec::new(),
            lk_breadth: if !or3 && (LK_BREADTH_FROM..=LK_BREADTH_UP_TO).contains(&net.n) { LK_BREADTH } else { 1 },
            lk_max_tentative: if net.n > LK_BREADTH_UP_TO { LK_TENTATIVE_HUGE } else { usize::MAX },
            lk_alts: Vec::new(),
            lk_one: Vec::new(),
            lk3: or3,
            lk3_added: Vec::new(),
            lk3_removed: Vec::new(),
            breadth1: 1,
            sop3: sop3::applies(net).then(|| Sop3::new(net.n)),
            flip: window_flip::applies(net, two_opt),
        }
    }

    /// Marks a node dirty.
    #[inline]
    pub fn push(&mut self, v: u32) {
        if !self.queued[v as usize] {
            self.queued[v as usize] = true;
            self.queue.push_back(v);
        }
    }

    /// Marks every node dirty, in tour order.
    pub fn push_all(&mut self, tour: &Tour) {
        for i in 0..tour.len() {
            self.push(tour.seq[i]);
        }
    }

    /// Improves until no dirty node yields an improving move (or the deadline passes).
    /// Returns true if anything improved.
    pub fn run(&mut self, tour: &mut Tour) -> bool {
        let mut improved = false;
        let mut count = 0u32;
        // Every move gains at least `eps` in exact arithmetic, so a descent ends; with forbidden
        // arcs in the tour (priced at 10¹² or more) rounding can make a cycle of moves look
        // improving. A descent far longer than any real one is stopped.
        let max_moves = 100 * self.net.n as u64 + 10_000;
        let mut moves = 0u64;
        while let Some(v) = self.queue.pop_front() {
            self.queued[v as usize] = false;
            count += 1;
            // (every 16 steps: a step costs microseconds on plain tours but milliseconds on
            // large precedence problems such as Castelino's transformation of a machining
            // tool, where every 256 steps overran a 0.5 s limit by a second)
            if count & 15 == 0 {
                if let Some(d) = self.deadline {
                    if Instant::now() >= d {
                        self.clear();
                        self.cut = true;
                        break;
                    }
                }
            }
            if tour.len() < 3 && !self.net.multi_mode {
                continue;
            }
            if self.improve_node(tour, v) {
                debug_assert!(
                    (tour.cost - tour.full_cost(self.net)).abs() <= 1e-6 * tour.cost.abs().max(1.0),
                    "tracked cost {} != full cost {}",
                    tour.cost,
                    tour.full_cost(self.net)
                );
                improved = true;
                self.moves += 1;
                self.push(v);
                moves += 1;
                if moves >= max_moves {
                    self.clear();
                    break;
                }
            }
        }
        improved
    }

    /// Empties the queue.
    pub fn clear(&mut self) {
        while let Some(v) = self.queue.pop_front() {
            self.queued[v as usize] = false;
        }
    }

    fn improve_node(&mut self, tour: &mut Tour, v: u32) -> bool {
        if self.net.multi_mode && self.try_mode(tour, v) {
            return true;
        }
        let chain = self.two_opt && if self.lk3 { self.try_lk3(tour, v) } else { self.try_lk(tour, v) };
        if chain {
            return true;
        }
        // Position 0 never moves (its arcs change only through reversals).
        if tour.pos[v as usize] == 0 {
            return false;
        }
        if self.lk3 {
            // Or-opt and the segment exchange are sequential 3-opt moves the chains already try
            // (from the candidates); skipping them leaves time for more kicks.
            return false;
        }
        if self.try_or_opt(tour, v) || self.try_swap(tour, v) {
            return true;
        }
        if self.flip && self.try_flip_window(tour, v) {
            return true;
        }
        // the candidate-list moves first (cheap), then the whole 3-exchange neighbourhood
        let found = self.sop3.as_mut().and_then(|s| s.find(self.net, tour, v, self.eps));
        if let Some(ex) = found {
            for x in sop3::apply(tour, ex) {
                self.push(x);
            }
            return true;
        }
        false
    }

    /// Path-preserving 3-opt ("segment exchange", the SOP-3-exchange of Gambardella and Dorigo):
    /// swaps two adjacent segments L = h+1..=i and R = i+1..=j, one of them starting or ending
    /// at `v`. Candidate lists pick the new arcs, so only K² exchanges are priced; with
    /// precedence, segments are at most `SWAP_WINDOW` long, the tasks tied by precedence to the
    /// fixed segment are marked, and a scan away from it stops at the first marked task.
    fn try_swap(&mut self, tour: &mut Tour, v: u32) -> bool {
        let net = self.net;
        let n = tour.len();
        if n < 4 {
            return false;
        }
        let pv = tour.pos[v as usize] as usize;
        let window = if net.has_prec { SWAP_WINDOW } else { n };
        let prune = prunes_by_gain(net);
        // Forward: h = pv - 1, L starts at v, the new arc h -> i+1 goes to a neighbour of seq[h].
        if pv >= 1 {
            let h = pv - 1;
            let hv = tour.seq[h];
            let base_h = tour.arc(net, hv, v);
            let mut cands = std::mem::take(&mut self.cands);
            cands.clear();
            cands.extend(
                self.nb
                    .out(hv)
                    .iter()
                    .map(|&c| (tour.pos[c as usize] as usize, c))
                    .filter(|&(pc, _)| pc > h + 1 && pc - h - 1 <= window),
            );
            cands.sort_unstable();
            let max_j = self.nb.inn(v).iter().map(|&d| tour.pos[d as usize] as usize).max().unwrap_or(0);
            self.stamp += 1;
            let st = self.stamp;
            let mut ext = h; // the successors of L = h+1..=ext are marked
            for idx in 0..cands.len() {
                let (pc, c) = cands[idx];
                let i = pc - 1;
                let g1 = base_h - tour.arc(net, hv, c);
                if g1 <= self.eps && prune {
                    continue;
                }
                // R = i+1..=j may not hold a successor of L: scan right until one appears
                let mut bound = n;
                if net.has_prec {
                    while ext < i {
                        ext += 1;
                        for &x in net.successors(tour.seq[ext]) {
                            self.mark[x as usize] = st;
                        }
                    }
                    bound = i + 1;
                    while bound <= max_j && bound < n && self.mark[tour.seq[bound] as usize] != st {
                        bound += 1;
                    }
                }
                let iv = tour.seq[i];
                let g2 = g1 + tour.arc(net, iv, c);
                for &d in self.nb.inn(v) {
                    let j = tour.pos[d as usize] as usize;
                    if j < pc || j >= bound {
                        continue;
                    }
                    let q = tour.next_of_pos(j);
                    let delta = tour.arc(net, d, v) + tour.arc(net, iv, q) - tour.arc(net, d, q) - g2;
                    if delta < -self.eps && self.swap_cuts_ok(tour, h, i, j) {
                        self.apply_swap(tour, h, i, j, delta);
                        self.cands = cands;
                        return true;
                    }
                }
            }
            self.cands = cands;
        }
        // Backward: j = pv, R ends at v, the new arc i -> j+1 comes from a neighbour of seq[j+1].
        if pv >= 2 {
            let j = pv;
            let q = tour.next_of_pos(j);
            let base_j = tour.arc(net, v, q);
            let mut cands = std::mem::take(&mut self.cands);
            cands.clear();
            cands.extend(
                self.nb
                    .inn(q)
                    .iter()
                    .map(|&u| (tour.pos[u as usize] as usize, u))
                    .filter(|&(pu, _)| pu >= 1 && pu < j && j - pu <= window),
            );
            cands.sort_unstable_by(|a, b| b.cmp(a));
            let min_h =
                self.nb.out(v).iter().map(|&w| tour.pos[w as usize] as usize).filter(|&pw| pw >= 1).min().unwrap_or(1)
                    - 1;
            self.stamp += 1;
            let st = self.stamp;
            let mut ext = j + 1; // the predecessors of R = ext..=j are marked
            for idx in 0..cands.len() {
                let (i, iv) = cands[idx];
                let c = tour.seq[i + 1];
                let g1 = base_j + tour.arc(net, iv, c) - tour.arc(net, iv, q);
                if g1 <= self.eps && prune {
                    continue;
                }
                // L = h+1..=i may not hold a predecessor of R: scan left until one appears
                let mut floor = 0usize;
                if net.has_prec {
                    while ext > i + 1 {
                        ext -= 1;
                        for &x in net.predecessors(tour.seq[ext]) {
                            self.mark[x as usize] = st;
                        }
                    }
                    let mut p = i;
                    while p > min_h && self.mark[tour.seq[p] as usize] != st {
                        p -= 1;
                    }
                    // h >= p: L starts after the first tie (or after min_h, which bounds h anyway)
                    floor = p;
                }
                for &w in self.nb.out(v) {
                    // w = seq[h+1], the new arc j -> h+1
                    let pw = tour.pos[w as usize] as usize;
                    if pw == 0 || pw > i {
                        continue;
                    }
                    let h = pw - 1;
                    if h < floor {
                        continue;
                    }
                    let hv = tour.seq[h];
                    let delta = tour.arc(net, v, w) + tour.arc(net, hv, c) - tour.arc(net, hv, w) - g1;
                    if delta < -self.eps && self.swap_cuts_ok(tour, h, i, j) {
                        self.apply_swap(tour, h, i, j, delta);
                        self.cands = cands;
                        return true;
                    }
                }
            }
            self.cands = cands;
        }
        false
    }

    fn swap_cuts_ok(&self, tour: &Tour, h: usize, i: usize, j: usize) -> bool {
        !self.net.has_groups
            || self.net.move_allowed(
                &tour.seq,
                &[(tour.seq[h], tour.seq[h + 1]), (tour.seq[i], tour.seq[i + 1]), (tour.seq[j], tour.next_of_pos(j))],
                h + 1,
                j,
            )
    }

    fn apply_swap(&mut self, tour: &mut Tour, h: usize, i: usize, j: usize, delta: Cost) {
        let ends = [tour.seq[h], tour.seq[h + 1], tour.seq[i], tour.seq[i + 1], tour.seq[j], tour.next_of_pos(j)];
        tour.swap_adjacent(h + 1, i, j);
        tour.cost += delta;
        for x in ends {
            self.push(x);
        }
    }

    /// Best mode for `v` where it stands.
    fn try_mode(&mut self, tour: &mut Tour, v: u32) -> bool {
        let net = self.net;
        let nm = net.num_modes(v);
        if nm < 2 {
            return false;
        }
        let (p, q) = (tour.prev(v), tour.next(v));
        let (mp, mq) = (tour.mode[p as usize], tour.mode[q as usize]);
        let price = |m: u32| {
            if p == v {
                // single node tour
                net.arc(v, m, v, m) + net.mode_cost(v, m)
            } else {
                net.arc(p, mp, v, m) + net.mode_cost(v, m) + net.arc(v, m, q, mq)
            }
        };
        let cur_m = tour.mode[v as usize];
        let cur = price(cur_m);
        let mut best = (cur, cur_m);
        for m in 0..nm {
            if m != cur_m {
                let c = price(m);
                if c < best.0 - self.eps {
                    best = (c, m);
                }
            }
        }
        if best.1 != cur_m {
            tour.set_mode(v, best.1);
            tour.cost += best.0 - cur;
            self.push(p);
            self.push(q);
            return true;
        }
        false
    }

    fn try_or_opt(&mut self, tour: &mut Tour, v: u32) -> bool {
        let n = tour.len();
        let pv = tour.pos[v as usize] as usize;
        if self.net.has_groups {
            // a whole consecutive-group block moves as one segment
            let (bs, be) = self.block(tour, pv);
            if be - bs + 1 > MAX_SEGMENT
                && (bs == pv || be == pv)
                && bs >= 1
                && n >= be - bs + 4
                && self.try_segment(tour, bs, be)
            {
                return true;
            }
        }
        for len in 1..=MAX_SEGMENT {
            if n < len + 3 {
                break;
            }
            // v first in the segment
            if pv + len - 1 < n && self.try_segment(tour, pv, pv + len - 1) {
                return true;
            }
            // v last in the segment
            if len > 1 && pv >= len && self.try_segment(tour, pv + 1 - len, pv) {
                return true;
            }
        }
        false
    }

    /// Tries to move the segment at positions `i..=j` (never position 0) elsewhere.
    fn try_segment(&mut self, tour: &mut Tour, i: usize, j: usize) -> bool {
        let net = self.net;
        let n = tour.len();
        debug_assert!(i >= 1 && j < n && i <= j);
        let (s, e) = (tour.seq[i], tour.seq[j]);
        let p = tour.seq[i - 1];
        let q = tour.next_of_pos(j);
        let single = i == j;
        let ms = tour.mode[s as usize];
        let mut gain = tour.arc(net, p, s) + tour.arc(net, e, q) - tour.arc(net, p, q);
        if single {
            gain += net.mode_cost(s, ms);
        }
        if gain <= self.eps && !net.multi_mode {
            // a move needs a positive removal gain (see `prunes_by_gain`)
            return false;
        }
        // Inside cost change when the segment is reversed (without reverse modes).
        let rev_ok = !single && self.reversal_ok(tour, i, j);
        let rev_inside = if rev_ok && !net.reversal_symmetric {
            let mut d = 0.0;
            for t in i..j {
                let (a, b) = (tour.seq[t], tour.seq[t + 1]);
                d += tour.arc(net, b, a) - tour.arc(net, a, b);
            }
            d
        } else {
            0.0
        };
        let best = if net.has_prec && tour.len() <= SCAN_UP_TO {
            // near positions exhaustively, far ones through the candidate lists
            let near = self.scan_insertions(tour, i, j, gain, rev_ok, rev_inside);
            let far = self.candidate_insertions(tour, i, j, gain, rev_ok, rev_inside);
            match (near, far) {
                (Some(a), Some(b)) => Some(if b.delta < a.delta { b } else { a }),
                (a, b) => a.or(b),
            }
        } else {
            self.candidate_insertions(tour, i, j, gain, rev_ok, rev_inside)
        };
        let Some(ins) = best else { return false };
        let k = ins.k;
        let c = tour.seq[k];
        let d = tour.next_of_pos(k);
        debug_assert!(net.move_allowed(&tour.seq, &[(p, s), (e, q), (c, d)], i.min(k + 1), j.max(k)));
        tour.move_segment(i, j, k, ins.reversed);
        if single {
            tour.set_mode(s, ins.mode);
        } else if ins.reversed && net.reversal_symmetric {
            let (lo, hi) = (tour.pos[e as usize] as usize, tour.pos[s as usize] as usize);
            tour.reverse_modes(net, lo, hi);
        }
        tour.cost += ins.delta;
        for x in [p, q, c, d, s, e] {
            self.push(x);
        }
        true
    }

    /// Positions of the consecutive-group block around position `i` (just `i` if ungrouped).
    /// Stops at position 0 and at the end: blocks never wrap.
    pub fn block(&self, tour: &Tour, i: usize) -> (usize, usize) {
        let net = self.net;
        let (mut a, mut b) = (i, i);
        while a > 1 && net.inside_group(tour.seq[a - 1], tour.seq[a]) {
            a -= 1;
        }
        while b + 1 < tour.len() && net.inside_group(tour.seq[b], tour.seq[b + 1]) {
            b += 1;
        }
        (a, b)
    }

    /// Can the segment be traversed backwards: no precedence inside it, and modes reversible when
    /// the instance relies on reverse modes.
    fn reversal_ok(&self, tour: &Tour, i: usize, j: usize) -> bool {
        let net = self.net;
        if net.has_prec {
            for a in i..=j {
                for b in a + 1..=j {
                    if net.successors(tour.seq[a]).contains(&tour.seq[b]) {
                        return false;
                    }
                }
            }
        }
        if net.reversal_symmetric {
            return true;
        }
        // Without reverse modes the order can still be reversed, each task keeping its mode.
        let _ = NO_REV;
        true
    }

    /// Cost of putting the segment `s..e` between `c` and `d`, forward or reversed, minus the
    /// arc c→d. For a single node, also picks its best mode there.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn insertion_cost(
        &self,
        tour: &Tour,
        s: u32,
        e: u32,
        c: u32,
        d: u32,
        reversed: bool,
        rev_inside: Cost,
    ) -> (Cost, u32) {
        let net = self.net;
        let (mc, md) = (tour.mode[c as usize], tour.mode[d as usize]);
        let base = net.arc(c, mc, d, md);
        if s == e {
            let mut best = (Cost::INFINITY, tour.mode[s as usize]);
            for m in 0..net.num_modes(s) {
                let x = net.arc(c, mc, s, m) + net.mode_cost(s, m) + net.arc(s, m, d, md);
                if x < best.0 {
                    best = (x, m);
                }
            }
            return (best.0 - base, best.1);
        }
        let (ms, me) = (tour.mode[s as usize], tour.mode[e as usize]);
        let x = if !reversed {
            net.arc(c, mc, s, ms) + net.arc(e, me, d, md)
        } else if net.reversal_symmetric {
            net.arc(c, mc, e, net.rev_mode(e, me)) + net.arc(s, net.rev_mode(s, ms), d, md)
        } else {
            net.arc(c, mc, e, me) + net.arc(s, ms, d, md) + rev_inside
        };
        (x - base, 0)
    }

    /// Or-opt by scanning outwards from the segment, stopping at the first precedence conflict.
    fn scan_insertions(
        &mut self,
        tour: &Tour,
        i: usize,
        j: usize,
        gain: Cost,
        rev_ok: bool,
        rev_inside: Cost,
    ) -> Option<Insertion> {
        let net = self.net;
        let n = tour.len();
        let (s, e) = (tour.seq[i], tour.seq[j]);
        let mut best: Option<Insertion> = None;
        let mut best_delta = -self.eps;
        let (p, q) = (tour.seq[i - 1], tour.next_of_pos(j));
        let mut consider = |k: usize, c: u32, d: u32, this: &Self| {
            if net.has_groups && !net.move_allowed(&tour.seq, &[(p, s), (e, q), (c, d)], i.min(k + 1), j.max(k)) {
                return;
            }
            for reversed in [false, true] {
                if reversed && !rev_ok {
                    break;
                }
                let (x, m) = this.insertion_cost(tour, s, e, c, d, reversed, rev_inside);
                let delta = x - gain;
                if delta < best_delta {
                    best_delta = delta;
                    best = Some(Insertion { k, reversed, mode: m, delta });
                }
            }
        };
        // Forward: the nodes passed over must not be successors of the segment.
        self.stamp += 1;
        let st = self.stamp;
        for t in i..=j {
            for &x in net.successors(tour.seq[t]) {
                self.mark[x as usize] = st;
            }
        }
        let hi = (j + self.scan_limit).min(n - 1);
        for k in j + 1..=hi {
            let c = tour.seq[k];
            if self.mark[c as usize] == st {
                break;
            }
            consider(k, c, tour.next_of_pos(k), self);
        }
        // Backward: the nodes passed over must not be predecessors of the segment.
        self.stamp += 1;
        let st = self.stamp;
        for t in i..=j {
            for &x in net.predecessors(tour.seq[t]) {
                self.mark[x as usize] = st;
            }
        }
        let lo = i.saturating_sub(1 + self.scan_limit);
        let mut k = i - 1;
        while k > lo {
            k -= 1;
            let d = tour.seq[k + 1];
            if self.mark[d as usize] == st {
                break;
            }
            consider(k, tour.seq[k], d, self);
        }
        best
    }

    /// Where the segment at `i..=j` may go: after a position in `lo..hi`, where `lo` is the
    /// position of its last predecessor outside it and `hi` that of its first successor.
    fn precedence_window(&self, tour: &Tour, i: usize, j: usize) -> (usize, usize) {
        let net = self.net;
        let (mut lo, mut hi) = (0usize, tour.len());
        for t in i..=j {
            let v = tour.seq[t];
            for &x in net.predecessors(v) {
                let px = tour.pos[x as usize] as usize;
                if px < i && px > lo {
                    lo = px;
                }
            }
            for &x in net.successors(v) {
                let px = tour.pos[x as usize] as usize;
                if px > j && px < hi {
                    hi = px;
                }
            }
        }
        (lo, hi)
    }

    /// Or-opt over candidate neighbours, precedence checked against the segment's window.
    fn candidate_insertions(
        &mut self,
        tour: &Tour,
        i: usize,
        j: usize,
        gain: Cost,
        rev_ok: bool,
        rev_inside: Cost,
    ) -> Option<Insertion> {
        let net = self.net;
        let n = tour.len();
        let (s, e) = (tour.seq[i], tour.seq[j]);
        let mut best: Option<Insertion> = None;
        let mut best_delta = -self.eps;
        // k: insert after position k; valid if k < i - 1 or k > j, and with precedence only
        // between the segment's last predecessor and first successor
        let (lo_k, hi_k) = if net.has_prec { self.precedence_window(tour, i, j) } else { (0, n) };
        let valid = |k: usize| (k + 1 < i && k >= lo_k) || (k > j && k < hi_k);
        let (p, q) = (tour.seq[i - 1], tour.next_of_pos(j));
        let mut consider = |k: usize, reversed: bool| {
            if !valid(k) || (reversed && !rev_ok) {
                return;
            }
            let c = tour.seq[k];
            let d = tour.next_of_pos(k);
            if net.has_groups && !net.move_allowed(&tour.seq, &[(p, s), (e, q), (c, d)], i.min(k + 1), j.max(k)) {
                return;
            }
            let (x, m) = self.insertion_cost(tour, s, e, c, d, reversed, rev_inside);
            let delta = x - gain;
            if delta < best_delta {
                best_delta = delta;
                best = Some(Insertion { k, reversed, mode: m, delta });
            }
        };
        let before = |c: u32| {
            let pc = tour.pos[c as usize] as usize;
            if pc == 0 {
                n - 1
            } else {
                pc - 1
            }
        };
        // A new arc at least as long as the removal gain is not tried (`prunes_by_gain`);
        // neighbour lists are sorted, so stop. With several modes (when they are a task's
        // orientations) the lists' lower bounds (cheapest over mode pairs) stand in for the arc,
        // and a single task's cheapest mode cost joins it (its mode may change).
        let prune = prunes_by_gain(net);
        let slack = if net.multi_mode && i == j { net.min_mode_cost(s) } else { 0.0 };
        let too_long = |a: u32, b: u32, lb: Cost| {
            prune && if net.multi_mode { lb + slack >= gain } else { tour.arc(net, a, b) >= gain }
        };
        let nb = self.nb;
        for (&c, &lb) in nb.inn(s).iter().zip(nb.inn_lb(s)) {
            if too_long(c, s, lb) {
                break;
            }
            consider(tour.pos[c as usize] as usize, false); // c -> s
        }
        for (&c, &lb) in nb.out(e).iter().zip(nb.out_lb(e)) {
            if too_long(e, c, lb) {
                break;
            }
            consider(before(c), false); // e -> c
        }
        if rev_ok {
            for (&c, &lb) in nb.inn(e).iter().zip(nb.inn_lb(e)) {
                if too_long(c, e, lb) {
                    break;
                }
                consider(tour.pos[c as usize] as usize, true); // c -> e
            }
            for (&c, &lb) in nb.out(s).iter().zip(nb.out_lb(s)) {
                if too_long(s, c, lb) {
                    break;
                }
                consider(before(c), true); // s -> c
            }
        }
        if net.depot != u32::MAX {
            // next to the depot: start or end of an open route
            let pd = tour.pos[net.depot as usize] as usize;
            let before_depot = if pd == 0 { n - 1 } else { pd - 1 };
            consider(pd, false);
            consider(before_depot, false);
            if rev_ok {
                consider(pd, true);
                consider(before_depot, true);
            }
        }
        best
    }

    /// A Lin–Kernighan move built from a chain of 2-opt reversals (reversal-symmetric instances;
    /// under precedence, one mode per task and only reversals with no precedence pair inside,
    /// which is what SOP instances such as TSPLIB's prob.100 need). From t1 and its tour neighbour t2, a step adds an arc t2–t3 to a
    /// candidate t3, removes t3's arc to t4 (the neighbour that keeps a tour) and reverses the
    /// stretch between, so the tour stays closed. At each level every candidate's closing is
    /// priced exactly without touching the tour (that level is plain 2-opt); if none improves, the
    /// step with the largest partial gain is applied tentatively and the chain goes on from t4
    /// (depth up to `LK_DEPTH`); nothing improving means everything is undone. On large tours
    /// the first level backtracks: the chain is tried from each of its `lk_breadth` best steps.
    /// (Plain symmetric one-mode tours use chains of 3-opt moves instead, see `lk3`.)
    fn try_lk(&mut self, tour: &mut Tour, t1: u32) -> bool {
        if tour.len() < 5 {
            return false;
        }
        let own_journal = !tour.journaling();
        if own_journal {
            tour.begin();
        }
        let mut improved = false;
        let mut alts = std::mem::take(&mut self.lk_alts);
        'dirs: for first_forward in [true, false] {
            let start = tour.mark();
            let t2 = if first_forward { tour.next(t1) } else { tour.prev(t1) };
            let g = if first_forward { tour.arc(self.net, t1, t2) } else { tour.arc(self.net, t2, t1) };
            self.touch_start(t1, t2);
            // first level: close at once if that improves, else go deeper from each of the
            // best few steps in turn
            alts.clear();
            if let Some(c) = self.lk_level(tour, t1, t2, g, 0.0, 1, self.lk_breadth, &mut alts) {
                self.lk_apply(tour, &c);
                improved = true;
                break 'dirs;
            }
            for a in 0..alts.len() {
                let step = alts[a];
                self.lk_apply(tour, &step);
                if self.lk_deeper(tour, t1, step.t4, step.g2, step.step) {
                    improved = true;
                    break 'dirs;
                }
                // back to the start (the mark is used up by undoing to it)
                tour.undo_to(start);
                let again = tour.mark();
                debug_assert_eq!(again, start);
                self.touch_start(t1, t2);
            }
            tour.undo_to(start);
        }
        self.lk_alts = alts;
        self.end_chain(tour, improved, own_journal)
    }

    /// Greedy continuation of a Lin–Kernighan chain from level 2: t2 is now `t2`, the partial
    /// gain `g` and the cost change so far `so_far` (tentatively applied). Returns true when a
    /// closing improved the tour (left applied); false leaves the tentative steps for the
    /// caller to undo.
    fn lk_deeper(&mut self, tour: &mut Tour, t1: u32, mut t2: u32, mut g: Cost, mut so_far: Cost) -> bool {
        let mut one = std::mem::take(&mut self.lk_one);
        let mut improved = false;
        for depth in 2..=LK_DEPTH {
            one.clear();
            if let Some(c) = self.lk_level(tour, t1, t2, g, so_far, depth, 1, &mut one) {
                self.lk_apply(tour, &c);
                improved = true;
                break;
            }
            let Some(&step) = one.first() else { break };
            if depth == LK_DEPTH {
                break;
            }
            self.lk_apply(tour, &step);
            so_far += step.step;
            t2 = step.t4;
            g = step.g2;
        }
        self.lk_one = one;
        improved
    }

    /// One level of a Lin–Kernighan chain: prices every candidate t3 of `t2`. Returns the best
    /// improving closing, if any; otherwise `deeper` receives the steps with the largest partial
    /// gains (as many as it has capacity for), best first.
    #[allow(clippy::too_many_arguments)]
    fn lk_level(
        &mut self,
        tour: &Tour,
        t1: u32,
        t2: u32,
        g: Cost,
        so_far: Cost,
        depth: usize,
        cap: usize,
        deeper: &mut Vec<LkStep>,
    ) -> Option<LkStep> {
        let net = self.net;
        let forward = tour.next(t1) == t2;
        let mut close: Option<LkStep> = None;
        let mut close_total = -self.eps;
        // with one mode on a plain symmetric tour the lists' lower bounds are the arcs' costs
        let exact_lb = net.plain_symmetric && !net.multi_mode;
        for (&t3, &lb) in self.nb.out(t2).iter().zip(self.nb.out_lb(t2)) {
            if t3 == t1 || (depth > 1 && self.touch_mark[t3 as usize] == self.touch_stamp) {
                continue;
            }
            // the new arc joins t3 to t2 turned round (t2 ends the reversed stretch)
            let g1 = g - if exact_lb {
                lb
            } else {
                let (m2, m3) = (tour.mode[t2 as usize], tour.mode[t3 as usize]);
                let r2 = net.rev_mode(t2, m2);
                if forward {
                    net.arc(t2, r2, t3, m3)
                } else {
                    net.arc(t3, m3, t2, r2)
                }
            };
            if g1 <= self.eps {
                if net.multi_mode {
                    continue;
                }
                break;
            }
            let t4 = if forward { tour.prev(t3) } else { tour.next(t3) };
            if t4 == t2 || t4 == t1 {
                continue;
            }
            // removed arcs in array order: (a, next a) and (b, next b)
            let a = if forward { t1 } else { t2 };
            let b = if forward { t4 } else { t3 };
            let (pa, pb) = (tour.pos[a as usize] as usize, tour.pos[b as usize] as usize);
            let (lo, hi) = if pa < pb { (pa + 1, pb) } else { (pb + 1, pa) };
            if net.has_groups && !net.move_allowed(&tour.seq, &[(a, tour.next(a)), (b, tour.next(b))], lo, hi) {
                continue;
            }
            let g2 = g1 + if forward { tour.arc(net, t4, t3) } else { tour.arc(net, t3, t4) };
            // cost change of the tour closed by t4–t1: exact, or from the gains when every
            // arc costs the same both ways
            let total = if net.plain_symmetric {
                tour.arc(net, t4, t1) - g2
            } else {
                so_far + self.reversal_delta(tour, lo, hi)
            };
            let step = LkStep { lo, hi, step: total - so_far, t3, t4, g2 };
            // keep the `cap` largest partial gains, best first (on huge tours only short
            // stretches are reversed tentatively)
            let len = hi - lo + 1;
            let len = if net.wrap_ok { len.min(tour.len() - len) } else { len };
            let goes_deeper = len <= self.lk_max_tentative && ranks(deeper, cap, g2);
            if total >= close_total && !goes_deeper {
                continue;
            }
            if net.has_prec && !self.precedence_free(tour, lo, hi) {
                continue;
            }
            if total < close_total {
                close_total = total;
                close = Some(step);
            }
            if goes_deeper {
                offer(deeper, cap, step);
            }
        }
        close
    }

    /// A 2-opt move: removes the arcs x1–y1 and x2–y2 (y1 following x1 and y2 following x2 in
    /// the same direction round the tour) and adds x1–x2 and y1–y2.
    fn flip(&self, tour: &mut Tour, x1: u32, y1: u32, x2: u32, y2: u32) {
        let a = if tour.next(x1) == y1 { x1 } else { y1 };
        let c = if tour.next(x2) == y2 { x2 } else { y2 };
        debug_assert_eq!(tour.next(x1) == y1, tour.next(x2) == y2, "flip arcs not in one direction");
        let (pa, pc) = (tour.pos[a as usize] as usize, tour.pos[c as usize] as usize);
        let (lo, hi) = if pa < pc { (pa + 1, pc) } else { (pc + 1, pa) };
        self.reverse_short_way(tour, lo, hi);
    }

    /// No precedence edge joins two tasks of positions `lo..=hi`, so the stretch may be
    /// reversed (a task's successors always stand after it, so only their positions up to `hi`
    /// matter).
    fn precedence_free(&self, tour: &Tour, lo: usize, hi: usize) -> bool {
        (lo..hi).all(|p| self.net.successors(tour.seq[p]).iter().all(|&s| tour.pos[s as usize] as usize > hi))
    }

    /// Applies one step of a Lin–Kernighan chain started at `t1`.
    fn lk_apply(&mut self, tour: &mut Tour, step: &LkStep) {
        self.reverse_short_way(tour, step.lo, step.hi);
        tour.cost += step.step;
        self.touch(step.t3);
        self.touch(step.t4);
    }

    /// Ends a Lin–Kernighan chain: an improvement queues the ends of every arc it changed, and
    /// a journal the chain opened is closed. Returns `improved`.
    fn end_chain(&mut self, tour: &mut Tour, improved: bool, own_journal: bool) -> bool {
        if improved {
            let touched = std::mem::take(&mut self.lk_touched);
            for &x in &touched {
                self.push(x);
            }
            self.lk_touched = touched;
        }
        if own_journal {
            tour.commit();
        }
        improved
    }

    /// Notes a node as an endpoint of an arc the current chain changed.
    #[inline]
    fn touch(&mut self, v: u32) {
        self.lk_touched.push(v);
        self.touch_mark[v as usize] = self.touch_stamp;
    }

    /// Starts a new chain from the arc t1–t2: only its ends touched.
    fn touch_start(&mut self, t1: u32, t2: u32) {
        self.lk_touched.clear();
        self.touch_stamp = self.touch_stamp.wrapping_add(1);
        if self.touch_stamp == 0 {
            self.touch_mark.fill(0);
            self.touch_stamp = 1;
        }
        self.touch(t1);
        self.touch(t2);
    }

    /// Reverses positions `lo..=hi`, or the rest of the cycle when that is shorter and allowed
    /// (the same tour, read the other way), then turns the modes round.
    fn reverse_short_way(&self, tour: &mut Tour, lo: usize, hi: usize) {
        let n = tour.len();
        if self.net.wrap_ok && 2 * (hi - lo + 1) > n {
            let (a, b) = ((hi + 1) % n, lo - 1);
            tour.reverse_cyclic(a, b);
            if a <= b {
                tour.reverse_modes(self.net, a, b);
            } else {
                tour.reverse_modes(self.net, a, n - 1);
                tour.reverse_modes(self.net, 0, b);
            }
        } else {
            tour.reverse(lo, hi);
            tour.reverse_modes(self.net, lo, hi);
        }
    }

    /// Exact cost change of reversing positions `lo..=hi` (modes swapped to their reverses;
    /// the inside keeps its cost because the instance is reversal-symmetric).
    fn reversal_delta(&self, tour: &Tour, lo: usize, hi: usize) -> Cost {
        let net = self.net;
        let p = tour.seq[lo - 1];
        let l = tour.seq[lo];
        let h = tour.seq[hi];
        let q = tour.next_of_pos(hi);
        let (mp, ml, mh, mq) =
            (tour.mode[p as usize], tour.mode[l as usize], tour.mode[h as usize], tour.mode[q as usize]);
        let (rl, rh) = (net.rev_mode(l, ml), net.rev_mode(h, mh));
        if lo == hi {
            // a single node turned round
            return net.arc(p, mp, l, rl) + net.arc(l, rl, q, mq) - net.arc(p, mp, l, ml) - net.arc(l, ml, q, mq);
        }
        net.arc(p, mp, h, rh) + net.arc(l, rl, q, mq) - net.arc(p, mp, l, ml) - net.arc(h, mh, q, mq)
    }
}

/// Whether a step of partial gain `g2` belongs among the `cap` largest kept in `deeper`.
fn ranks(deeper: &[LkStep], cap: usize, g2: Cost) -> bool {
    deeper.len() < cap || deeper.last().is_some_and(|d| g2 > d.g2)
}

/// Puts a step among the `cap` largest partial gains, best first.
fn offer(deeper: &mut Vec<LkStep>, cap: usize, step: LkStep) {
    let at = deeper.iter().position(|d| step.g2 > d.g2).unwrap_or(deeper.len());
    deeper.insert(at, step);
    deeper.truncate(cap);
}
