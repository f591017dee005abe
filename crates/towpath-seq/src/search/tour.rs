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
}

#[derive(Clone, Debug)]
enum Entry {
    /// seq[lo..lo+len] was overwritten; old values are at saved[at..at+len].
    Range { lo: u32, len: u32, at: u32 },
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
        let mut t = Tour { seq, pos, mode, cost: 0.0, journal: Vec::new(), saved: Vec::new(), journaling: false };
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
        while let Some(e) = self.journal.pop() {
            match e {
                Entry::Range { lo, len, at } => {
                    let (lo, len, at) = (lo as usize, len as usize, at as usize);
                    self.seq[lo..lo + len].copy_from_slice(&self.saved[at..at + len]);
                    for i in lo..lo + len {
                        self.pos[self.seq[i] as usize] = i as u32;
                    }
                }
                Entry::Mode { node, old } => self.mode[node as usize] = old,
                Entry::Cost(c) => self.cost = c,
            }
        }
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
                    for i in lo..lo + len {
                        self.pos[self.seq[i] as usize] = i as u32;
                    }
                    self.saved.truncate(at);
                }
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
        for i in lo..=hi {
            self.pos[self.seq[i] as usize] = i as u32;
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
        self.save_range(i, j);
        self.seq[i..=j].reverse();
        self.refresh_pos(i, j);
    }

    /// Reverses the cyclic stretch from position `a` forward to position `b` (it may wrap past the
    /// end; position 0 then changes hands).
    pub fn reverse_cyclic(&mut self, a: usize, b: usize) {
        let n = self.seq.len();
        if a <= b {
            self.reverse(a, b);
            return;
        }
        self.save_range(a, n - 1);
        self.save_range(0, b);
        let m = n - a + b + 1;
        let (mut x, mut y) = (a, b);
        for _ in 0..m / 2 {
            self.seq.swap(x, y);
            self.pos[self.seq[x] as usize] = x as u32;
            self.pos[self.seq[y] as usize] = y as u32;
            x = if x + 1 == n { 0 } else { x + 1 };
            y = if y == 0 { n - 1 } else { y - 1 };
        }
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
