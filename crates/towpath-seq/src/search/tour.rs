//! Array representation of a tour with a journal for cheap undo.

use super::net::Net;
use crate::cost::{Cost, CostModel};

/// A tour: `seq[i]` is the node at position `i` (position 0 is fixed), `pos` its inverse, and
/// `mode[v]` the mode of node `v`.
#[derive(Clone, Debug)]
pub(crate) struct Tour {
    pub seq: Vec<u32>,
    pub pos: Vec<u32>,
    pub mode: Vec<u32>,
    pub cost: Cost,
    journal: Vec<Entry>,
    saved: Vec<u32>,
    journaling: bool,
    /// Room for a wrapped reversal (no allocation per move).
    scratch: Vec<u32>,
}

#[derive(Clone, Debug)]
enum Entry {
    /// seq[lo..lo+len] was overwritten; old values are at saved[at..at+len].
    Range { lo: u32, len: u32, at: u32 },
    /// seq[lo..=hi] was reversed (undone by reversing it again: no copy is kept).
    Reversed { lo: u32, hi: u32 },
    /// The cyclic stretch from position `a` forward to `b` was reversed.
    ReversedCyclic { a: u32, b: u32 },
    /// mode[node] was `old`.
    Mode { node: u32, old: u32 },
    /// cost was `old`.
    Cost(Cost),
}

impl Tour {
    pub fn new<C: CostModel>(net: &Net<C>, seq: Vec<u32>, mode: Vec<u32>) -> Self {
        let mut pos = vec![0u32; seq.len()];
        for (i, &v) in seq.iter().enumerate() {
            pos[v as usize] = i as u32;
        }
        let mut t = Tour {
            seq,
            pos,
            mode,
            cost: 0.0,
            journal: Vec::new(),
            saved: Vec::new(),
            journaling: false,
            scratch: Vec::new(),
        };
        t.cost = t.full_cost(net);
        t
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.seq.len()
    }

    /// Node after position `i` (cyclic).
    #[inline]
    pub fn next_of_pos(&self, i: usize) -> u32 {
        let j = i + 1;
        self.seq[if j == self.seq.len() { 0 } else { j }]
    }

    /// Node before position `i` (cyclic).
    #[inline]
    pub fn prev_of_pos(&self, i: usize) -> u32 {
        self.seq[if i == 0 { self.seq.len() - 1 } else { i - 1 }]
    }

    #[inline]
    pub fn next(&self, v: u32) -> u32 {
        self.next_of_pos(self.pos[v as usize] as usize)
    }

    #[inline]
    pub fn prev(&self, v: u32) -> u32 {
        self.prev_of_pos(self.pos[v as usize] as usize)
    }

    /// Arc cost from `a` to `b` in their current modes.
    #[inline]
    pub fn arc<C: CostModel>(&self, net: &Net<C>, a: u32, b: u32) -> Cost {
        net.arc(a, self.mode[a as usize], b, self.mode[b as usize])
    }

    /// Cost recomputed from scratch.
    pub fn full_cost<C: CostModel>(&self, net: &Net<C>) -> Cost {
        let n = self.seq.len();
        let mut c = 0.0;
        for i in 0..n {
            let a = self.seq[i];
            c += net.mode_cost(a, self.mode[a as usize]);
            if n > 1 || a == net.depot {
                c += self.arc(net, a, self.next_of_pos(i));
            }
        }
        if n == 1 && net.p.is_cyclic() {
            // a single task in a cycle still returns to its own entry
            let a = self.seq[0];
            c += self.arc(net, a, a);
        }
        c
    }

    /// Starts recording changes so that [`Tour::undo`] can restore the current state.
    pub fn begin(&mut self) {
        self.journal.clear();
        self.saved.clear();
        self.journaling = true;
        self.journal.push(Entry::Cost(self.cost));
    }

    /// Stops recording and keeps the changes.
    pub fn commit(&mut self) {
        self.journaling = false;
        self.journal.clear();
        self.saved.clear();
    }

    /// Restores the state saved by [`Tour::begin`].
    pub fn undo(&mut self) {
        self.undo_to(0);
        self.saved.clear();
        self.journaling = false;
    }

    /// True while changes are being recorded.
    pub fn journaling(&self) -> bool {
        self.journaling
    }

    /// A point in the journal to come back to with [`Tour::undo_to`] (journaling must be on).
    pub fn mark(&mut self) -> usize {
        debug_assert!(self.journaling);
        let m = self.journal.len();
        self.journal.push(Entry::Cost(self.cost));
        m
    }

    /// Undoes every change recorded after `mark` (the journal stays on).
    pub fn undo_to(&mut self, mark: usize) {
        while self.journal.len() > mark {
            match self.journal.pop() {
                Some(Entry::Range { lo, len, at }) => {
                    let (lo, len, at) = (lo as usize, len as usize, at as usize);
                    self.seq[lo..lo + len].copy_from_slice(&self.saved[at..at + len]);
                    self.refresh_pos(lo, lo + len - 1);
                    self.saved.truncate(at);
                }
                Some(Entry::Reversed { lo, hi }) => self.flip_range(lo as usize, hi as usize),
                Some(Entry::ReversedCyclic { a, b }) => self.flip_cyclic(a as usize, b as usize),
                Some(Entry::Mode { node, old }) => self.mode[node as usize] = old,
                Some(Entry::Cost(c)) => self.cost = c,
                None => break,
            }
        }
    }

    fn save_range(&mut self, lo: usize, hi: usize) {
        if self.journaling {
            let at = self.saved.len() as u32;
            self.saved.extend_from_slice(&self.seq[lo..=hi]);
            self.journal.push(Entry::Range { lo: lo as u32, len: (hi - lo + 1) as u32, at });
        }
    }

    fn refresh_pos(&mut self, lo: usize, hi: usize) {
        for (k, &v) in (lo as u32..).zip(&self.seq[lo..=hi]) {
            self.pos[v as usize] = k;
        }
    }

    /// Sets a node's mode.
    pub fn set_mode(&mut self, v: u32, m: u32) {
        if self.mode[v as usize] != m {
            if self.journaling {
                self.journal.push(Entry::Mode { node: v, old: self.mode[v as usize] });
            }
            self.mode[v as usize] = m;
        }
    }

    /// Moves the segment at positions `i..=j` so that it follows position `k`
    /// (`k < i - 1` or `k > j`), reversing it if asked. Positions are those before the move.
    pub fn move_segment(&mut self, i: usize, j: usize, k: usize, reversed: bool) {
        let len = j - i + 1;
        if k > j {
            self.save_range(i, k);
            self.seq[i..=k].rotate_left(len);
            let s = k + 1 - len;
            if reversed {
                self.seq[s..=k].reverse();
            }
            self.refresh_pos(i, k);
        } else {
            debug_assert!(k + 1 < i);
            self.save_range(k + 1, j);
            self.seq[k + 1..=j].rotate_right(len);
            if reversed {
                self.seq[k + 1..k + 1 + len].reverse();
            }
            self.refresh_pos(k + 1, j);
        }
    }

    /// Reverses positions `i..=j`.
    pub fn reverse(&mut self, i: usize, j: usize) {
        if self.journaling {
            self.journal.push(Entry::Reversed { lo: i as u32, hi: j as u32 });
        }
        self.flip_range(i, j);
    }

    /// Reverses positions `i..=j` without journaling (a reversal is its own undo).
    fn flip_range(&mut self, i: usize, j: usize) {
        self.seq[i..=j].reverse();
        self.refresh_pos(i, j);
    }

    /// Reverses the cyclic stretch from position `a` forward to position `b` (it may wrap past the
    /// end; position 0 then changes hands).
    pub fn reverse_cyclic(&mut self, a: usize, b: usize) {
        if a <= b {
            self.reverse(a, b);
            return;
        }
        if self.journaling {
            self.journal.push(Entry::ReversedCyclic { a: a as u32, b: b as u32 });
        }
        self.flip_cyclic(a, b);
    }

    /// Reverses the cyclic stretch from `a` forward to `b` (`a > b`) without journaling.
    fn flip_cyclic(&mut self, a: usize, b: usize) {
        // the stretch is seq[a..] then seq[..=b]: reversed through a scratch copy
        let mut stretch = std::mem::take(&mut self.scratch);
        stretch.clear();
        stretch.extend_from_slice(&self.seq[a..]);
        stretch.extend_from_slice(&self.seq[..=b]);
        stretch.reverse();
        let (tail, head) = stretch.split_at(self.seq.len() - a);
        self.seq[a..].copy_from_slice(tail);
        self.seq[..=b].copy_from_slice(head);
        self.scratch = stretch;
        self.refresh_pos(a, self.seq.len() - 1);
        self.refresh_pos(0, b);
    }

    /// Rotates so that `v` is at position 0 (journaled).
    pub fn rotate_to(&mut self, v: u32) {
        let p = self.pos[v as usize] as usize;
        if p != 0 {
            let n = self.seq.len();
            self.save_range(0, n - 1);
            self.seq.rotate_left(p);
            self.refresh_pos(0, n - 1);
        }
    }

    /// Exchanges the adjacent segments `i..=j` and `j+1..=k`.
    pub fn swap_adjacent(&mut self, i: usize, j: usize, k: usize) {
        self.save_range(i, k);
        self.seq[i..=k].rotate_left(j + 1 - i);
        self.refresh_pos(i, k);
    }

    /// The double bridge on the segments B = `i..=j`, C = `j+1..=k` and D = `k+1..=l` (`1 ≤ i`,
    /// `l < n`): they come back as D C B, each the same way round, and the cost is updated.
    /// Returns the eight nodes whose arcs changed (the segments' ends and their outer
    /// neighbours), for the local search's queue.
    pub fn double_bridge<C: CostModel>(&mut self, net: &Net<C>, i: usize, j: usize, k: usize, l: usize) -> [u32; 8] {
        let (p, b0, b1, c0, c1, d0, d1, e) = (
            self.seq[i - 1],
            self.seq[i],
            self.seq[j],
            self.seq[j + 1],
            self.seq[k],
            self.seq[k + 1],
            self.seq[l],
            self.next_of_pos(l),
        );
        let old = self.arc(net, p, b0) + self.arc(net, b1, c0) + self.arc(net, c1, d0) + self.arc(net, d1, e);
        let new = self.arc(net, p, d0) + self.arc(net, d1, c0) + self.arc(net, c1, b0) + self.arc(net, b1, e);
        // B C D reversed as a whole, then each piece turned back
        let (lc, ld) = (k - j, l - k);
        self.reverse(i, l);
        self.reverse(i, i + ld - 1);
        self.reverse(i + ld, i + ld + lc - 1);
        self.reverse(i + ld + lc, l);
        self.cost += new - old;
        [p, b0, b1, c0, c1, d0, d1, e]
    }

    /// Switches every node at positions `i..=j` to its reverse mode (which must exist).
    pub fn reverse_modes<C: CostModel>(&mut self, net: &Net<C>, i: usize, j: usize) {
        if net.modes_self_reverse {
            return;
        }
        for p in i..=j {
            let v = self.seq[p];
            let r = net.rev_mode(v, self.mode[v as usize]);
            self.set_mode(v, r);
        }
    }

    /// Replaces the whole sequence (same nodes, position 0 unchanged) and some modes, and
    /// recomputes the cost. Journaled.
    pub fn overwrite<C: CostModel>(&mut self, net: &Net<C>, seq: &[u32], modes: &[(u32, u32)]) {
        let n = self.seq.len();
        debug_assert_eq!(seq.len(), n);
        debug_assert_eq!(seq[0], self.seq[0]);
        self.save_range(1, n - 1);
        self.seq.copy_from_slice(seq);
        self.refresh_pos(1, n - 1);
        for &(v, m) in modes {
            self.set_mode(v, m);
        }
        self.cost = self.full_cost(net);
    }

    /// Steps as (node, mode) pairs in order starting at position 0.
    pub fn nodes(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.seq.iter().map(move |&v| (v, self.mode[v as usize]))
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::search::testing::random_tour_problem;

    /// `pos` is the inverse of `seq`.
    fn consistent(t: &Tour) -> bool {
        t.seq.iter().enumerate().all(|(i, &v)| t.pos[v as usize] as usize == i)
    }

    /// Random journaled changes (plain and wrapped reversals, segment moves and swaps, mode
    /// changes, nested marks) are undone exactly: back at a mark, and back at the start, the
    /// sequence, positions, modes and cost are what they were.
    #[test]
    fn journaled_changes_undo_exactly() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let p = random_tour_problem(&mut rng, 40, 100.0);
        let net = Net::new(&p);
        for round in 0..200 {
            let n = 3 + rng.gen_range(0..38usize);
            let mut seq: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                seq.swap(i, rng.gen_range(0..=i));
            }
            let mut tour = Tour::new(&net, seq, vec![0; 40]);
            let start = tour.clone();
            tour.begin();
            let mut snapshot: Option<(usize, Tour)> = None;
            for step in 0..12 {
                if step == 6 {
                    let m = tour.mark();
                    snapshot = Some((m, tour.clone()));
                }
                let (a, b) = (rng.gen_range(0..n), rng.gen_range(0..n));
                match rng.gen_range(0..5) {
                    0 => tour.reverse(a.min(b), a.max(b)),
                    1 => tour.reverse_cyclic(a, b),
                    2 if n >= 4 => {
                        let (i, j) = (a.min(b).max(2), a.max(b).max(2));
                        let k = rng.gen_range(0..i - 1);
                        tour.move_segment(i, j, k, rng.gen_bool(0.5));
                    }
                    3 if a.min(b) + 1 < a.max(b) => {
                        let (i, k) = (a.min(b), a.max(b));
                        tour.swap_adjacent(i, rng.gen_range(i..k), k);
                    }
                    _ => tour.set_mode(tour.seq[a], rng.gen_range(0..3)),
                }
                tour.cost += 1.0;
                assert!(consistent(&tour), "round {round} step {step}");
            }
            let (m, at_mark) = snapshot.expect("a mark was set");
            tour.undo_to(m);
            assert_eq!(
                (&tour.seq, &tour.pos, &tour.mode),
                (&at_mark.seq, &at_mark.pos, &at_mark.mode),
                "round {round}"
            );
            assert_eq!(tour.cost, at_mark.cost);
            tour.undo();
            assert_eq!((&tour.seq, &tour.pos, &tour.mode), (&start.seq, &start.pos, &start.mode), "round {round}");
            assert_eq!(tour.cost, start.cost);
        }
    }
}
