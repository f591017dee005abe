//! Lin–Kernighan chains whose every step is a sequential 3-opt move (LKH's basic move, Helsgaun
//! 2000, section 5.1 and "Best3OptMove"), for plain symmetric one-mode tours.
//!
//! From the removed arc t1–t2 a level chooses t3 among t2's candidates, t4 on either side of t3,
//! t5 among t4's candidates and t6 beside t5 such that removing t1–t2, t3–t4, t5–t6 and adding
//! t2–t3, t4–t5 leaves a Hamiltonian path from t1 to t6. Any closing by t6–t1 (or, when t4 lies
//! on the 2-opt side, t4–t1 at once) that gains is applied at once; otherwise the 3-opt move of
//! the largest partial gain G4 is applied tentatively and the chain goes on from t6. An arc the
//! chain removed is never added back and an arc it added is never removed. When a chain
//! fails, it starts again from the next-best first-level moves in turn, up to `breadth1` in all
//! (LKH's backtracking, here at the first level only).

use super::LocalSearch;
use crate::cost::{Cost, CostModel};
use crate::search::tour::Tour;

/// Deepest chain, in 3-opt moves: deeper chains find more but leave less time for kicks
/// (15, 35 and 50 were measured against 25 on TSPLIB; see the history of this constant).
const DEPTH: usize = 25;

/// Candidates of t4 tried as t5 (the nearest few; every candidate of t2 is tried as t3).
const T5_BREADTH: usize = 5;

/// No node.
const NONE: u32 = u32::MAX;

/// Most first-level moves a chain backtracks over (see [`SolveOptions::lk_breadth`]).
///
/// [`SolveOptions::lk_breadth`]: crate::SolveOptions::lk_breadth
pub(crate) const MAX_BREADTH1: usize = 4;

/// How a level's 3-opt move reconnects the tour.
#[derive(Clone, Copy)]
enum Kind {
    /// t4 on the 2-opt side of t3: two 2-opt moves in a row.
    Flips,
    /// t4 on the far side of t3 (removing t3–t4 would cut t2..t3 off as a cycle): a segment
    /// exchange (t6 after t5) or a double reversal (t6 before t5).
    Or3,
}

/// A level's best continuation.
#[derive(Clone, Copy)]
struct Move {
    kind: Kind,
    t3: u32,
    t4: u32,
    t5: u32,
    t6: u32,
    g4: Cost,
}

/// What a level found.
enum Level {
    /// An improving move was applied; the tour's cost falls by this gain.
    Improved(Cost),
    /// No closing gains; the best continuations, largest partial gain first (the first always
    /// present).
    Deeper([Option<Move>; MAX_BREADTH1]),
    /// Nothing to close or continue with.
    Stuck,
}

/// An undirected arc as a key.
#[inline]
fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

impl<C: CostModel> LocalSearch<'_, '_, C> {
    /// A chain of sequential 3-opt moves from `t1`, over both of its tour arcs. Returns true
    /// when the tour improved (the ends of every changed arc are queued); otherwise the tour is
    /// as it was.
    pub(super) fn try_lk3(&mut self, tour: &mut Tour, t1: u32) -> bool {
        if tour.len() < 8 {
            return self.try_lk(tour, t1);
        }
        let own_journal = !tour.journaling();
        if own_journal {
            tour.begin();
        }
        let cost0 = tour.cost;
        let mut improved = false;
        let breadth = self.breadth1.clamp(1, MAX_BREADTH1);
        'dirs: for forward in [true, false] {
            let start = tour.mark();
            let first = if forward { tour.next(t1) } else { tour.prev(t1) };
            self.touch_start(t1, first);
            self.lk3_added.clear();
            self.lk3_removed.clear();
            self.lk3_removed.push(key(t1, first));
            let g0 = self.net.arc(t1, 0, first, 0);
            let alts = match self.lk3_level(tour, t1, first, g0, breadth) {
                Level::Improved(gain) => {
                    tour.cost = cost0 - gain;
                    improved = true;
                    break 'dirs;
                }
                Level::Deeper(alts) => alts,
                Level::Stuck => continue,
            };
            for m in alts.into_iter().flatten() {
                tour.undo_to(start);
                self.lk3_added.clear();
                self.lk3_removed.truncate(1);
                self.lk3_apply(tour, t1, first, &m);
                self.lk3_push(first, &m);
                let mut t2 = m.t6;
                let mut g = m.g4;
                for _ in 1..DEPTH {
                    match self.lk3_level(tour, t1, t2, g, 1) {
                        Level::Improved(gain) => {
                            tour.cost = cost0 - gain;
                            improved = true;
                            break 'dirs;
                        }
                        Level::Deeper([Some(m), ..]) => {
                            self.lk3_apply(tour, t1, t2, &m);
                            self.lk3_push(t2, &m);
                            t2 = m.t6;
                            g = m.g4;
                        }
                        _ => break,
                    }
                }
            }
            tour.undo_to(start);
        }
        self.end_chain(tour, improved, own_journal)
    }

    /// Notes the arcs a level's move added and removed.
    fn lk3_push(&mut self, t2: u32, m: &Move) {
        self.lk3_added.push(key(t2, m.t3));
        self.lk3_added.push(key(m.t4, m.t5));
        self.lk3_removed.push(key(m.t3, m.t4));
        self.lk3_removed.push(key(m.t5, m.t6));
    }

    /// One level from the open arc t1–t2 with partial gain `g` (the cost of the arcs removed
    /// less that of the arcs added so far, t1–t2 included); keeps the `keep` best continuations.
    fn lk3_level(&mut self, tour: &mut Tour, t1: u32, t2: u32, g: Cost, keep: usize) -> Level {
        let net = self.net;
        let nb = self.nb;
        let eps = self.eps;
        let c = |a: u32, b: u32| net.arc(a, 0, b, 0);
        let forward = tour.next(t1) == t2;
        let succ = |tour: &Tour, x: u32| if forward { tour.next(x) } else { tour.prev(x) };
        let pred = |tour: &Tour, x: u32| if forward { tour.prev(x) } else { tour.next(x) };
        let n = tour.len();
        let p2 = tour.pos[t2 as usize] as usize;
        // steps from t2 to x along the direction t1 -> t2
        let along = |tour: &Tour, x: u32| {
            let px = tour.pos[x as usize] as usize;
            // positions are below n, so one conditional subtraction replaces a division
            let d = if forward { px + n - p2 } else { p2 + n - px };
            if d >= n {
                d - n
            } else {
                d
            }
        };
        let succ2 = succ(tour, t2);
        let mut best: [Option<Move>; MAX_BREADTH1] = [None; MAX_BREADTH1];
        for (&t3, &c23) in nb.out(t2).iter().zip(nb.out_lb(t2)) {
            let g1 = g - c23;
            if g1 <= eps {
                break;
            }
            if t3 == t1 || t3 == succ2 {
                continue;
            }
            let span3 = along(tour, t3);
            for t4_after in [false, true] {
                let t4 = if t4_after { succ(tour, t3) } else { pred(tour, t3) };
                if t4 == t1 {
                    continue;
                }
                let g2 = g1 + c(t3, t4);
                if !t4_after {
                    // t1 t2 .. t4 t3: closing by t4–t1 is a 2-opt move
                    let gain = g2 - c(t4, t1);
                    if gain > eps {
                        self.flip(tour, t1, t2, t4, t3);
                        self.touch(t3);
                        self.touch(t4);
                        return Level::Improved(gain);
                    }
                }
                let (t4s, t4p) = (succ(tour, t4), pred(tour, t4));
                let span4 = along(tour, t4);
                for (&t5, &c45) in nb.out(t4).iter().zip(nb.out_lb(t4)).take(T5_BREADTH) {
                    let g3 = g2 - c45;
                    if g3 <= eps {
                        break;
                    }
                    if t5 == t1 || t5 == t4s || t5 == t4p {
                        continue;
                    }
                    let a5 = along(tour, t5);
                    let mut t6s = [NONE; 2];
                    if !t4_after {
                        // after the first flip t5 must follow t6 as t4 follows t1
                        t6s[0] = if a5 <= span4 { succ(tour, t5) } else { pred(tour, t5) };
                    } else {
                        // t5 inside the cycle t2..t3 that adding t2–t3 closes
                        if a5 > span3 {
                            continue;
                        }
                        t6s[0] = succ(tour, t5);
                        if t5 != t2 {
                            t6s[1] = pred(tour, t5);
                        }
                    }
                    for t6 in t6s {
                        if t6 == NONE || t6 == t1 {
                            continue;
                        }
                        let g4 = g3 + c(t5, t6);
                        let m = Move { kind: if t4_after { Kind::Or3 } else { Kind::Flips }, t3, t4, t5, t6, g4 };
                        let gain = g4 - c(t6, t1);
                        if gain > eps {
                            self.lk3_apply(tour, t1, t2, &m);
                            return Level::Improved(gain);
                        }
                        if best[keep - 1].is_some_and(|b| g4 <= b.g4) {
                            continue;
                        }
                        // no t7 could keep the gain positive
                        if nb.out_lb(t6).first().is_none_or(|&lb| g4 <= lb) {
                            continue;
                        }
                        if self.lk3_removed.contains(&key(t2, t3))
                            || self.lk3_removed.contains(&key(t4, t5))
                            || self.lk3_added.contains(&key(t3, t4))
                            || self.lk3_added.contains(&key(t5, t6))
                        {
                            continue;
                        }
                        // keep the list in order of g4, largest first, dropping the last
                        let mut at = keep - 1;
                        while at > 0 && best[at - 1].is_none_or(|b| b.g4 < g4) {
                            best[at] = best[at - 1];
                            at -= 1;
                        }
                        best[at] = Some(m);
                    }
                }
            }
        }
        if best[0].is_some() {
            Level::Deeper(best)
        } else {
            Level::Stuck
        }
    }

    /// Applies a level's 3-opt move (the cost is not tracked: the chain sets it when it closes).
    fn lk3_apply(&mut self, tour: &mut Tour, t1: u32, t2: u32, m: &Move) {
        match m.kind {
            Kind::Flips => {
                self.flip(tour, t1, t2, m.t4, m.t3);
                self.flip(tour, t1, m.t4, m.t6, m.t5);
            }
            Kind::Or3 => {
                let (t3, t4, t5, t6) = (m.t3, m.t4, m.t5, m.t6);
                let forward = tour.next(t1) == t2;
                if (if forward { tour.next(t5) } else { tour.prev(t5) }) == t6 {
                    // the stretches t2..t5 and t6..t3 trade places
                    self.flip(tour, t1, t2, t3, t4);
                    self.flip(tour, t1, t3, t6, t5);
                    self.flip(tour, t3, t5, t2, t4);
                } else {
                    // both stretches reversed in place
                    self.flip(tour, t1, t2, t6, t5);
                    self.flip(tour, t2, t5, t3, t4);
                }
            }
        }
        for x in [m.t3, m.t4, m.t5, m.t6] {
            self.touch(x);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::search::neighbors::Neighbors;
    use crate::search::net::Net;
    use crate::search::testing::random_tour_problem;

    fn edges(tour: &Tour) -> BTreeSet<(u32, u32)> {
        (0..tour.len()).map(|i| key(tour.seq[i], tour.next_of_pos(i))).collect()
    }

    fn shuffled(rng: &mut Pcg64Mcg, n: usize) -> Vec<u32> {
        let mut seq: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            seq.swap(i, rng.gen_range(0..=i));
        }
        seq
    }

    /// Every kind of 3-opt move a level can make gives the tour whose arcs are the old ones less
    /// t1–t2, t3–t4, t5–t6 plus t2–t3, t4–t5, t6–t1 (one cycle): both traversal directions,
    /// t4 on either side of t3, both choices of t6 where there are two, stretches across
    /// position 0.
    #[test]
    fn three_opt_moves_make_the_tour_their_arcs_say() {
        let n = 40;
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let p = random_tour_problem(&mut rng, n, 100.0);
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 10);
        let mut ls = LocalSearch::new(&net, &nb, 1e-9);
        let mut checked = [0usize; 2];
        for trial in 0..800 {
            let mut tour = Tour::new(&net, shuffled(&mut rng, n), vec![0; n]);
            let forward = trial % 2 == 0;
            let succ = |t: &Tour, x: u32| if forward { t.next(x) } else { t.prev(x) };
            let pred = |t: &Tour, x: u32| if forward { t.prev(x) } else { t.next(x) };
            let t1 = tour.seq[rng.gen_range(0..n)];
            let t2 = succ(&tour, t1);
            // the tour read from t2 onwards: walk[i] is i steps from t2
            let walk: Vec<u32> = std::iter::successors(Some(t2), |&x| Some(succ(&tour, x))).take(n).collect();
            let along = |x: u32| walk.iter().position(|&y| y == x).expect("on the tour");
            let t3 = walk[rng.gen_range(2..n - 2)];
            let or3 = rng.gen_bool(0.5);
            let (kind, t4, t5, t6) = if or3 {
                let t4 = succ(&tour, t3);
                let t5 = walk[rng.gen_range(0..along(t3))];
                let t6 = if t5 != t2 && rng.gen_bool(0.5) { pred(&tour, t5) } else { succ(&tour, t5) };
                (Kind::Or3, t4, t5, t6)
            } else {
                let t4 = pred(&tour, t3);
                let t5 = walk[rng.gen_range(0..n - 1)];
                if [t1, t3, pred(&tour, t4)].contains(&t5) || t5 == t4 {
                    continue;
                }
                let t6 = if along(t5) <= along(t4) { succ(&tour, t5) } else { pred(&tour, t5) };
                (Kind::Flips, t4, t5, t6)
            };
            if t6 == t1 {
                continue;
            }
            let mut want = edges(&tour);
            for (a, b) in [(t1, t2), (t3, t4), (t5, t6)] {
                assert!(want.remove(&key(a, b)), "trial {trial}: {a}-{b} not a tour arc");
            }
            for (a, b) in [(t2, t3), (t4, t5), (t6, t1)] {
                want.insert(key(a, b));
            }
            let m = Move { kind, t3, t4, t5, t6, g4: 0.0 };
            ls.lk3_apply(&mut tour, t1, t2, &m);
            assert_eq!(edges(&tour), want, "trial {trial}");
            let visited = std::iter::successors(Some(t1), |&x| Some(tour.next(x))).take(n).collect::<BTreeSet<_>>();
            assert_eq!(visited.len(), n, "trial {trial}: not one cycle");
            checked[or3 as usize] += 1;
        }
        assert!(checked[0] > 200 && checked[1] > 200, "{checked:?}");
    }

    /// Chains improve by exactly what they claim and leave the tour as it was when they do not,
    /// and once no chain from any node improves, no 2-opt move does either (every node a
    /// candidate of every other, checked by brute force): at every first-level breadth.
    #[test]
    fn chains_gain_what_they_claim_and_end_two_opt_optimal() {
        for (seed, breadth) in (0..12).map(|s| (s, 1 + s as usize % MAX_BREADTH1)) {
            let n = 60;
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let p = random_tour_problem(&mut rng, n, 1000.0);
            let net = Net::new(&p);
            let nb = Neighbors::build(&net, n - 1);
            let mut ls = LocalSearch::new(&net, &nb, 1e-9);
            ls.breadth1 = breadth;
            let mut tour = Tour::new(&net, shuffled(&mut rng, n), vec![0; n]);
            let mut moves = 0;
            loop {
                let mut any = false;
                for t1 in 0..n as u32 {
                    let before = tour.cost;
                    let seq_before = tour.seq.clone();
                    if ls.try_lk3(&mut tour, t1) {
                        any = true;
                        moves += 1;
                        let full = tour.full_cost(&net);
                        assert!((tour.cost - full).abs() < 1e-6, "seed {seed}: tracked {} != {full}", tour.cost);
                        assert!(full < before - 1e-9, "seed {seed}: no gain");
                    } else {
                        assert_eq!(tour.cost, before);
                        assert_eq!(tour.seq, seq_before, "seed {seed}: a failed chain changed the tour");
                    }
                }
                if !any {
                    break;
                }
            }
            assert!(moves > 10, "seed {seed}: only {moves} moves from a random tour");
            let mut sorted = tour.seq.clone();
            sorted.sort_unstable();
            assert!(sorted.iter().enumerate().all(|(i, &v)| v == i as u32), "seed {seed}: not a permutation");
            let c = |a: u32, b: u32| net.arc(a, 0, b, 0);
            for i in 0..n {
                for j in i + 2..n {
                    let (a, a2, b, b2) = (tour.seq[i], tour.next_of_pos(i), tour.seq[j], tour.next_of_pos(j));
                    if a == b2 {
                        continue;
                    }
                    let gain = c(a, a2) + c(b, b2) - c(a, b) - c(a2, b2);
                    assert!(gain <= 1e-6, "seed {seed}: 2-opt move at positions {i}, {j} gains {gain}");
                }
            }
        }
    }
}
