//! Local search for stroke tours: pieces done one after the other, each with modes (entry,
//! exit) and a direction, the cost the pen-up (rapid) length between one piece's exit and the
//! next one's entry.
//!
//! The tour is an array over the pieces plus a depot node (the route's start and its free end)
//! with a direction bit per piece and, as in Lin–Kernighan implementations, an orientation bit
//! for the whole array, so that a reversal may be done on the shorter side of the cycle when
//! that is equivalent (no start point, no precedence, every piece reversible). Moves, all built
//! from segment reversals and mode changes, each leaving a valid tour:
//!
//! - **mode / direction**: a piece takes its best mode (a closed contour's entry) and
//!   direction between its neighbours;
//! - **2-opt**: a segment is reversed (every piece in it runs the other way), the new arcs
//!   joining a piece to one of its 16 nearest pieces (neighbour lists from an R-tree over the
//!   piece ends);
//! - **Or-opt**: a segment of 1–3 pieces moves next to a near piece, forwards or reversed (a
//!   single piece also with its best mode there);
//! - **perturbation**: segment-swap kicks (a double bridge of two adjacent segments of up to
//!   50 pieces; several at once while the search stagnates), each followed by local search from
//!   the changed arcs and undone when the tour got dearer, while the budget lasts or until
//!   every kick strength has failed [`STALL_CYCLES`] times over in a row.
//!
//! Dirty nodes are kept in a queue (don't-look bits). Precedence pairs are checked per move
//! (only the pieces a move passes or reverses are looked at). Every move is applied whole, so
//! the tour is valid whenever the search stops: the answer under a time limit is the best tour
//! so far, and under a work budget (`kicks`, no deadline) it depends only on the input and the
//! seed.

use std::collections::VecDeque;
use std::time::Instant;

use crate::geom::P2;
use crate::point_grid::PointGrid;

/// Near pieces each closed contour keeps (its entry candidates all lie on one loop).
const NEIGHBOURS: usize = 8;
/// Near pieces each open stroke keeps: its two ends share them, about eight each (eight in all
/// left the moves at either end starved on random strokes; sixteen for closed contours made the
/// search slower and worse on nested-part sheets).
const STROKE_NEIGHBOURS: usize = 16;

/// Longest segment a kick moves.
const KICK_SEGMENT: usize = 50;

/// Longest segment an Or-opt move moves.
const OR_SEGMENT: usize = 3;

/// The search stops when this many full cycles of the kick strengths (one to four swaps at
/// once, each tried for 2n + 50 kicks) have gone by without an improvement: a small drawing is
/// then done in milliseconds instead of waiting for its time limit (the 24 isolines of the
/// benchmark's contour map found their answer within 80 kicks and stop after about 470).
pub const STALL_CYCLES: u64 = 1;

/// What the search may spend.
#[derive(Clone, Copy, Debug, Default)]
pub struct Budget {
    /// Stop at this instant (the tour is valid whenever it stops).
    pub deadline: Option<Instant>,
    /// Most perturbation kicks (`None`: until the deadline; with neither, no kicks).
    pub kicks: Option<u64>,
    /// Seed of the kicks' random choices.
    pub seed: u64,
}

/// What the search did.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Pen-up length of the start tour.
    pub start_cost: f64,
    /// Pen-up length after the first descent.
    pub descent_cost: f64,
    /// Pen-up length of the answer.
    pub cost: f64,
    /// Kicks done.
    pub kicks: u64,
    /// Improving moves applied (descent and kicks).
    pub moves: u64,
    /// The search stopped because it stagnated (see [`STALL_CYCLES`]), before its budget ran out.
    pub stalled: bool,
}

/// One journal entry: a physical reversal (undone by doing it again), a rotation (undone by
/// the opposite one) or a piece's old state.
#[derive(Clone, Copy)]
enum Op {
    Rev { i: usize, j: usize, toggled: bool },
    Rot { lo: usize, hi: usize, k: usize, left: bool },
    State { v: u32, mode: u32, flipped: bool },
}

/// An Or-opt move: (delta, first and last piece of the segment, the piece it goes after,
/// reversed, a single piece's new mode and direction).
type OrMove = (f64, u32, u32, u32, bool, Option<(u32, bool)>);

/// Small deterministic random numbers (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The stroke tour and its search state.
pub struct StrokeSearch<'a> {
    ends: &'a [Vec<(P2, P2)>],
    start: Option<P2>,
    /// `rev[t][m]`: the mode that is mode `m` run backwards (a closed contour's mode is its own).
    rev: Vec<Vec<Option<u32>>>,
    succ: Vec<Vec<u32>>,
    pred: Vec<Vec<u32>>,
    has_prec: bool,
    /// Reversals may be done on the shorter side of the cycle.
    free: bool,
    nb: Vec<Vec<u32>>,
    n: usize,
    seq: Vec<u32>,
    pos: Vec<usize>,
    mode: Vec<u32>,
    flipped: Vec<bool>,
    orient: bool,
    cost: f64,
    eps: f64,
    journal: Vec<Op>,
    journaling: bool,
    queue: VecDeque<u32>,
    queued: Vec<bool>,
    deadline: Option<Instant>,
    cut: bool,
    moves: u64,
    /// Longest stretch a move may reverse or pass (with `free`, on the shorter side): bounds
    /// the work of a move on very large tours (none on up to about 30,000 pieces).
    span: usize,
}

impl<'a> StrokeSearch<'a> {
    /// A search over pieces with modes `ends[t]` (entry, exit), precedence `pairs` (before,
    /// after), the route starting at `start` (or at the first piece) and ending anywhere,
    /// starting from `initial` (every piece once, as (piece, mode)).
    pub fn new(
        ends: &'a [Vec<(P2, P2)>],
        pairs: &[(usize, usize)],
        start: Option<P2>,
        initial: &[(usize, u32)],
    ) -> Self {
        let n = ends.len();
        let rev: Vec<Vec<Option<u32>>> = ends
            .iter()
            .map(|ms| {
                ms.iter()
                    .map(|&(e, x)| {
                        if e == x {
                            return Some(u32::MAX);
                        }
                        ms.iter().position(|&(e2, x2)| e2 == x && x2 == e).map(|k| k as u32)
                    })
                    .collect()
            })
            .collect();
        // u32::MAX marks "its own reverse" (closed contours); resolved to the mode itself.
        let rev: Vec<Vec<Option<u32>>> = rev
            .into_iter()
            .map(|ms| {
                ms.into_iter().enumerate().map(|(m, r)| r.map(|r| if r == u32::MAX { m as u32 } else { r })).collect()
            })
            .collect();
        let mut succ = vec![Vec::new(); n];
        let mut pred = vec![Vec::new(); n];
        let mut has_prec = false;
        for &(a, b) in pairs {
            if a < n && b < n && a != b {
                succ[a].push(b as u32);
                pred[b].push(a as u32);
                has_prec = true;
            }
        }
        let all_rev = rev.iter().all(|ms| ms.iter().all(|r| r.is_some()));
        let free = start.is_none() && !has_prec && all_rev;
        let nb = neighbours(ends);
        let big = n + 1;
        let mut seq: Vec<u32> = Vec::with_capacity(big);
        seq.push(n as u32);
        let mut mode = vec![0u32; big];
        let mut seen = vec![false; n];
        for &(t, m) in initial {
            if t < n && !seen[t] {
                seen[t] = true;
                seq.push(t as u32);
                mode[t] = m.min(ends[t].len().saturating_sub(1) as u32);
            }
        }
        // Pieces the initial tour missed go at the end (precedence is the caller's concern).
        for (t, s) in seen.iter().enumerate() {
            if !s {
                seq.push(t as u32);
            }
        }
        let mut pos = vec![0usize; big];
        for (i, &v) in seq.iter().enumerate() {
            pos[v as usize] = i;
        }
        let typical =
            ends.iter().flatten().map(|&(e, x)| e[0].abs() + e[1].abs() + x[0].abs() + x[1].abs()).fold(0.0, f64::max);
        let mut s = StrokeSearch {
            ends,
            start,
            rev,
            succ,
            pred,
            has_prec,
            free,
            nb,
            n,
            seq,
            pos,
            mode,
            flipped: vec![false; big],
            orient: false,
            cost: 0.0,
            eps: 1e-12 * typical.max(1.0),
            journal: Vec::new(),
            journaling: false,
            queue: VecDeque::new(),
            queued: vec![false; big],
            deadline: None,
            cut: false,
            moves: 0,
            span: (1_000_000_000 / n.max(1)).max(1000),
        };
        s.cost = s.full_cost();
        s
    }

    fn depot(&self) -> u32 {
        self.n as u32
    }

    fn big(&self) -> usize {
        self.n + 1
    }

    #[inline]
    fn next(&self, v: u32) -> u32 {
        let p = self.pos[v as usize];
        let b = self.big();
        if self.orient {
            self.seq[(p + b - 1) % b]
        } else {
            self.seq[(p + 1) % b]
        }
    }

    #[inline]
    fn prev(&self, v: u32) -> u32 {
        let p = self.pos[v as usize];
        let b = self.big();
        if self.orient {
            self.seq[(p + 1) % b]
        } else {
            self.seq[(p + b - 1) % b]
        }
    }

    /// Logical direction bit of a piece.
    #[inline]
    fn flip(&self, v: u32) -> bool {
        self.flipped[v as usize] ^ self.orient
    }

    /// (entry, exit) of piece `v` in mode `m` and direction `f`.
    #[inline]
    fn ends_of(&self, v: u32, m: u32, f: bool) -> (P2, P2) {
        let (e, x) = self.ends[v as usize][m as usize];
        if f {
            (x, e)
        } else {
            (e, x)
        }
    }

    #[inline]
    fn entry(&self, v: u32) -> Option<P2> {
        if v == self.depot() {
            return None;
        }
        Some(self.ends_of(v, self.mode[v as usize], self.flip(v)).0)
    }

    #[inline]
    fn exit(&self, v: u32) -> Option<P2> {
        if v == self.depot() {
            return self.start;
        }
        Some(self.ends_of(v, self.mode[v as usize], self.flip(v)).1)
    }

    /// Entry of `v` when run the other way (its exit now).
    #[inline]
    fn rentry(&self, v: u32) -> Option<P2> {
        if v == self.depot() {
            return self.start;
        }
        Some(self.ends_of(v, self.mode[v as usize], self.flip(v)).1)
    }

    /// Exit of `v` when run the other way (its entry now).
    #[inline]
    fn rexit(&self, v: u32) -> Option<P2> {
        if v == self.depot() {
            return None;
        }
        Some(self.ends_of(v, self.mode[v as usize], self.flip(v)).0)
    }

    #[inline]
    fn arc(&self, a: u32, b: u32) -> f64 {
        link(self.exit(a), self.entry(b))
    }

    /// The pen-up length recomputed from scratch.
    pub fn full_cost(&self) -> f64 {
        let mut c = 0.0;
        let mut v = self.depot();
        for _ in 0..self.big() {
            let w = self.next(v);
            c += self.arc(v, w);
            v = w;
        }
        c
    }

    /// The tracked pen-up length.
    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// The tour as (piece, mode) from the start, each mode as the piece is run.
    pub fn steps(&self) -> Vec<(usize, u32)> {
        let mut out = Vec::with_capacity(self.n);
        let mut v = self.next(self.depot());
        while v != self.depot() {
            let m = self.mode[v as usize];
            let m = if self.flip(v) { self.rev[v as usize][m as usize].unwrap_or(m) } else { m };
            out.push((v as usize, m));
            v = self.next(v);
        }
        out
    }

    /// Whether piece `v` may be run backwards in its current mode.
    #[inline]
    fn revable(&self, v: u32) -> bool {
        v == self.depot() || self.rev[v as usize][self.mode[v as usize] as usize].is_some()
    }

    /// Logical length of the segment from `a` forward to `b`.
    fn seg_len(&self, a: u32, b: u32) -> usize {
        let (pa, pb, bg) = (self.pos[a as usize], self.pos[b as usize], self.big());
        if self.orient {
            (pa + bg - pb) % bg + 1
        } else {
            (pb + bg - pa) % bg + 1
        }
    }

    /// Whether the segment from `a` forward to `b` holds the depot.
    fn holds_depot(&self, a: u32, b: u32) -> bool {
        let d = self.depot();
        a == d || b == d || self.seg_len(a, d) <= self.seg_len(a, b)
    }

    /// Reverses the logical segment from `a` forward to `b` (every piece in it changes
    /// direction). Without `free`, the segment must not hold the depot.
    fn reverse(&mut self, a: u32, b: u32) {
        let bg = self.big();
        let (mut i, mut j) = if self.orient {
            (self.pos[b as usize], self.pos[a as usize])
        } else {
            (self.pos[a as usize], self.pos[b as usize])
        };
        let len = (j + bg - i) % bg + 1;
        let mut toggled = false;
        if self.free && 2 * len > bg && len < bg {
            // The complement, reversed, gives the same cycle read the other way.
            let (ni, nj) = ((j + 1) % bg, (i + bg - 1) % bg);
            i = ni;
            j = nj;
            toggled = true;
        }
        self.reverse_physical(i, j);
        if toggled {
            self.orient = !self.orient;
        }
        if self.journaling {
            self.journal.push(Op::Rev { i, j, toggled });
        }
    }

    fn reverse_physical(&mut self, i: usize, j: usize) {
        let bg = self.big();
        let len = (j + bg - i) % bg + 1;
        let (mut x, mut y) = (i, j);
        for _ in 0..len / 2 {
            self.seq.swap(x, y);
            self.pos[self.seq[x] as usize] = x;
            self.pos[self.seq[y] as usize] = y;
            x = (x + 1) % bg;
            y = (y + bg - 1) % bg;
        }
        let mut x = i;
        for _ in 0..len {
            let v = self.seq[x] as usize;
            self.flipped[v] = !self.flipped[v];
            x = (x + 1) % bg;
        }
    }

    fn set_state(&mut self, v: u32, m: u32, logical_flip: bool) {
        if self.journaling {
            self.journal.push(Op::State { v, mode: self.mode[v as usize], flipped: self.flipped[v as usize] });
        }
        self.mode[v as usize] = m;
        self.flipped[v as usize] = logical_flip ^ self.orient;
    }

    fn undo_all(&mut self, cost: f64) {
        self.journaling = false;
        while let Some(op) = self.journal.pop() {
            match op {
                Op::Rev { i, j, toggled } => {
                    self.reverse_physical(i, j);
                    if toggled {
                        self.orient = !self.orient;
                    }
                }
                Op::State { v, mode, flipped } => {
                    self.mode[v as usize] = mode;
                    self.flipped[v as usize] = flipped;
                }
                Op::Rot { lo, hi, k, left } => self.rotate_physical(lo, hi, k, !left),
            }
        }
        self.cost = cost;
    }

    fn push(&mut self, v: u32) {
        if v != self.depot() && !self.queued[v as usize] {
            self.queued[v as usize] = true;
            self.queue.push_back(v);
        }
    }

    /// Runs the local search until no dirty piece has an improving move (or the deadline).
    fn run(&mut self) {
        let mut count = 0u32;
        while let Some(v) = self.queue.pop_front() {
            self.queued[v as usize] = false;
            count = count.wrapping_add(1);
            if count & 63 == 0 && self.deadline.is_some_and(|d| Instant::now() >= d) {
                while let Some(w) = self.queue.pop_front() {
                    self.queued[w as usize] = false;
                }
                self.cut = true;
                return;
            }
            if self.try_state(v) || self.try_two_opt(v) || self.try_or_opt(v) {
                self.moves += 1;
                self.push(v);
            }
        }
    }

    fn touch(&mut self, nodes: &[u32]) {
        for &v in nodes {
            self.push(v);
        }
    }

    /// Best mode and direction of `v` between its neighbours.
    fn try_state(&mut self, v: u32) -> bool {
        let (p, q) = (self.prev(v), self.next(v));
        let (xp, eq) = (self.exit(p), self.entry(q));
        let cur = link(xp, self.entry(v)) + link(self.exit(v), eq);
        let mut best = (cur - self.eps, u32::MAX, false);
        for m in 0..self.ends[v as usize].len() as u32 {
            let canrev = self.rev[v as usize][m as usize].is_some();
            let (e, x) = self.ends[v as usize][m as usize];
            for f in [false, true] {
                // A flip is only needed where no mode is the reverse already.
                if f && (!canrev || e == x || self.rev[v as usize][m as usize] != Some(m)) {
                    continue;
                }
                let (e, x) = if f { (x, e) } else { (e, x) };
                let c = link(xp, Some(e)) + link(Some(x), eq);
                if c < best.0 {
                    best = (c, m, f);
                }
            }
        }
        if best.1 == u32::MAX {
            return false;
        }
        self.cost += best.0 - cur;
        self.set_state(v, best.1, best.2);
        self.touch(&[p, q]);
        true
    }

    /// Whether the logical segment `a..=b` may be reversed: every piece reversible, no
    /// precedence pair inside it, and (without `free`) no depot in it.
    fn reversal_ok(&self, a: u32, b: u32) -> bool {
        if self.free {
            let len = self.seg_len(a, b);
            return len.min(self.big() - len) <= self.span;
        }
        if self.holds_depot(a, b) {
            return false;
        }
        // Depot fixed at position 0 and orientation never toggled: positions are linear.
        let (lo, hi) = (self.pos[a as usize], self.pos[b as usize]);
        if hi - lo > self.span {
            return false;
        }
        for k in lo..=hi {
            let v = self.seq[k];
            if !self.revable(v) {
                return false;
            }
            if self.has_prec && self.succ[v as usize].iter().any(|&s| (lo..=hi).contains(&self.pos[s as usize])) {
                return false;
            }
        }
        true
    }

    /// 2-opt: the new arcs join `v` and a near piece exit to exit or entry to entry.
    fn try_two_opt(&mut self, v: u32) -> bool {
        let mut best: Option<(f64, u32, u32)> = None; // (delta, a, b): reverse a..=b
        let nv = self.next(v);
        let pv = self.prev(v);
        let out_v = self.arc(v, nv);
        let in_v = self.arc(pv, v);
        for k in 0..self.nb[v as usize].len() {
            let c = self.nb[v as usize][k];
            // exit–exit: v, [next(v) .. c], next(c)
            let nc = self.next(c);
            if c != nv && nc != v && c != v {
                let d =
                    link(self.exit(v), self.rentry(c)) + link(self.rexit(nv), self.entry(nc)) - out_v - self.arc(c, nc);
                let (a, b) = (nv, c);
                let (a, b, d) = self.pick_side(a, b, d, v, nc);
                if d < -self.eps && best.is_none_or(|x| d < x.0) {
                    best = Some((d, a, b));
                }
            }
            // entry–entry: prev(v), [v .. prev(c)], c  (prev(c) reversed ends at... ) i.e. the
            // new arcs prev(v)→prev(c)' and v'→c.
            let pc = self.prev(c);
            if c != pv && pc != v && c != v {
                let d =
                    link(self.exit(pv), self.rentry(pc)) + link(self.rexit(v), self.entry(c)) - in_v - self.arc(pc, c);
                let (a, b, d) = self.pick_side(v, pc, d, pv, c);
                if d < -self.eps && best.is_none_or(|x| d < x.0) {
                    best = Some((d, a, b));
                }
            }
        }
        let Some((d, a, b)) = best else { return false };
        if !self.reversal_ok(a, b) {
            return false;
        }
        let (pa, nb) = (self.prev(a), self.next(b));
        self.reverse(a, b);
        self.cost += d;
        self.touch(&[pa, a, b, nb]);
        true
    }

    /// A reversal of `a..=b` between `p` and `q` (delta `d`): without `free`, when the segment
    /// holds the depot, the equivalent reversal of the other side `q..=p` instead (its delta
    /// recomputed, as the depot's arcs are not symmetric).
    fn pick_side(&self, a: u32, b: u32, d: f64, p: u32, q: u32) -> (u32, u32, f64) {
        if self.free || !self.holds_depot(a, b) {
            return (a, b, d);
        }
        // Other side: q .. p, between b and a.
        if q == self.depot() || p == self.depot() {
            return (a, b, f64::INFINITY);
        }
        let d2 =
            link(self.exit(b), self.rentry(p)) + link(self.rexit(q), self.entry(a)) - self.arc(b, q) - self.arc(p, a);
        (q, p, d2)
    }

    /// Or-opt: segments of 1–3 pieces starting or ending at `v` moved next to a near piece.
    fn try_or_opt(&mut self, v: u32) -> bool {
        let dep = self.depot();
        // (delta, s1, sk, c, reversed, single mode/flip)
        let mut best: Option<OrMove> = None;
        for k in 1..=OR_SEGMENT {
            for forward in [true, false] {
                if k == 1 && !forward {
                    continue;
                }
                // the segment s1..sk
                let (mut s1, mut sk) = (v, v);
                let mut ok = true;
                for _ in 1..k {
                    if forward {
                        sk = self.next(sk);
                        if sk == dep {
                            ok = false;
                        }
                    } else {
                        s1 = self.prev(s1);
                        if s1 == dep {
                            ok = false;
                        }
                    }
                }
                if !ok || self.seg_len(s1, sk) != k || k >= self.n {
                    continue;
                }
                let (p, q) = (self.prev(s1), self.next(sk));
                let removed = self.arc(p, s1) + self.arc(sk, q) - self.arc(p, q);
                for end in [s1, sk] {
                    for idx in 0..self.nb[end as usize].len() {
                        let c0 = self.nb[end as usize][idx];
                        for c in [c0, self.prev(c0)] {
                            let d = self.next(c);
                            if c == p || self.in_segment(c, s1, k) || self.in_segment(d, s1, k) {
                                continue;
                            }
                            let (xc, ed) = (self.exit(c), self.entry(d));
                            let base = -removed - self.arc(c, d);
                            if k == 1 {
                                for m in 0..self.ends[v as usize].len() as u32 {
                                    let (e, x) = self.ends[v as usize][m as usize];
                                    let canrev = self.rev[v as usize][m as usize].is_some();
                                    for f in [false, true] {
                                        if f && (!canrev || e == x || self.rev[v as usize][m as usize] != Some(m)) {
                                            continue;
                                        }
                                        let (e, x) = if f { (x, e) } else { (e, x) };
                                        let delta = base + link(xc, Some(e)) + link(Some(x), ed);
                                        if delta < -self.eps && best.is_none_or(|b| delta < b.0) {
                                            best = Some((delta, s1, sk, c, false, Some((m, f))));
                                        }
                                    }
                                }
                            } else {
                                let fwd = base + link(xc, self.entry(s1)) + link(self.exit(sk), ed);
                                if fwd < -self.eps && best.is_none_or(|b| fwd < b.0) {
                                    best = Some((fwd, s1, sk, c, false, None));
                                }
                                let bwd = base + link(xc, self.rentry(sk)) + link(self.rexit(s1), ed);
                                if bwd < -self.eps && best.is_none_or(|b| bwd < b.0) {
                                    best = Some((bwd, s1, sk, c, true, None));
                                }
                            }
                        }
                    }
                }
            }
        }
        let Some((delta, s1, sk, c, reversed, state)) = best else { return false };
        if !self.move_ok(s1, sk, c, reversed) {
            return false;
        }
        let (p, q, d) = (self.prev(s1), self.next(sk), self.next(c));
        self.move_segment(s1, sk, c, reversed);
        if let Some((m, f)) = state {
            self.set_state(s1, m, f);
        }
        self.cost += delta;
        self.touch(&[p, q, c, d, s1, sk]);
        true
    }

    fn in_segment(&self, x: u32, s1: u32, k: usize) -> bool {
        x != self.depot() && self.seg_len(s1, x) <= k
    }

    /// Whether moving `s1..=sk` between `c` and `next(c)` (reversed or not) keeps precedence
    /// and directions (checked on linear positions; with `free` there is nothing to check).
    fn move_ok(&self, s1: u32, sk: u32, c: u32, reversed: bool) -> bool {
        if self.free {
            let (p, q, d) = (self.prev(s1), self.next(sk), self.next(c));
            return self.seg_len(q, c).min(self.seg_len(d, p)) <= self.span;
        }
        let (lo, hi) = (self.pos[s1 as usize], self.pos[sk as usize]);
        let seg = lo..=hi;
        if reversed && seg.clone().any(|k| !self.revable(self.seq[k])) {
            return false;
        }
        let pc = self.pos[c as usize];
        if pc.abs_diff(lo) > self.span {
            return false;
        }
        if !self.has_prec {
            return true;
        }
        for k in seg.clone() {
            let s = self.seq[k] as usize;
            if reversed && self.succ[s].iter().any(|&t| seg.contains(&self.pos[t as usize])) {
                return false;
            }
            if pc > hi {
                // moves forward past hi+1..=pc
                if self.succ[s].iter().any(|&t| (hi + 1..=pc).contains(&self.pos[t as usize])) {
                    return false;
                }
            } else if self.pred[s].iter().any(|&t| (pc + 1..lo).contains(&self.pos[t as usize])) {
                return false;
            }
        }
        true
    }

    /// Moves `s1..=sk` between `c` and `next(c)`, reversed or not: by rotating the stretch it
    /// passes (one pass over it) when that stretch does not wrap round the array's end, else by
    /// reversals.
    fn move_segment(&mut self, s1: u32, sk: u32, c: u32, reversed: bool) {
        let (p, q, d) = (self.prev(s1), self.next(sk), self.next(c));
        let forward = if self.free {
            // the shorter way round
            self.seg_len(q, c) <= self.seg_len(d, p)
        } else {
            c != self.depot() && self.pos[c as usize] > self.pos[sk as usize]
        };
        let k = self.seg_len(s1, sk);
        let pos = |v: u32| self.pos[v as usize];
        // The physical stretch [lo, hi] holding the segment and what it passes, and whether the
        // segment goes to its high end (rotate left) or its low end (rotate right).
        let (lo, hi, left) = match (forward, self.orient) {
            (true, false) => (pos(s1), pos(c), true),
            (true, true) => (pos(c), pos(s1), false),
            (false, false) => (pos(d), pos(sk), false),
            (false, true) => (pos(sk), pos(d), true),
        };
        if lo < hi && hi - lo + 1 > k {
            self.rotate_physical(lo, hi, k, left);
            if self.journaling {
                self.journal.push(Op::Rot { lo, hi, k, left });
            }
            if reversed {
                self.reverse(s1, sk);
            }
            return;
        }
        if forward {
            // p S q .. c d  →  p c .. q S^r d  →  p q .. c S^r d
            self.reverse(s1, c);
            self.reverse(c, q);
        } else {
            // c d .. p S q  →  c S^r p .. d q  →  c S^r d .. p q
            self.reverse(d, sk);
            self.reverse(p, d);
        }
        if !reversed {
            self.reverse(sk, s1);
        }
    }

    /// Rotates `seq[lo..=hi]` by `k` places (left: the first `k` go to the end), keeping `pos`.
    fn rotate_physical(&mut self, lo: usize, hi: usize, k: usize, left: bool) {
        let part = &mut self.seq[lo..=hi];
        if left {
            part.rotate_left(k);
        } else {
            part.rotate_right(k);
        }
        for i in lo..=hi {
            self.pos[self.seq[i] as usize] = i;
        }
    }

    /// A segment-swap kick: two adjacent segments of up to `KICK_SEGMENT` pieces change
    /// places. Returns the nodes next to the changed arcs, or `None` when no legal kick was
    /// found.
    fn kick(&mut self, rng: &mut Rng) -> Option<[u32; 6]> {
        let n = self.n;
        if n < 4 {
            return None;
        }
        let maxl = KICK_SEGMENT.min(n / 3).max(1);
        let a1 = rng.below(n) as u32;
        let (l1, l2) = (1 + rng.below(maxl), 1 + rng.below(maxl));
        let dep = self.depot();
        let mut a2 = a1;
        for _ in 1..l1 {
            a2 = self.next(a2);
            if a2 == dep {
                return None;
            }
        }
        let b1 = self.next(a2);
        if b1 == dep {
            return None;
        }
        let mut b2 = b1;
        for _ in 1..l2 {
            b2 = self.next(b2);
            if b2 == dep {
                return None;
            }
        }
        if !self.free && self.has_prec {
            let (alo, ahi, bhi) = (self.pos[a1 as usize], self.pos[a2 as usize], self.pos[b2 as usize]);
            for k in alo..=ahi {
                let s = self.seq[k] as usize;
                if self.succ[s].iter().any(|&t| (ahi + 1..=bhi).contains(&self.pos[t as usize])) {
                    return None;
                }
            }
        }
        let (p, q) = (self.prev(a1), self.next(b2));
        let before = self.arc(p, a1) + self.arc(a2, b1) + self.arc(b2, q);
        let after = self.arc(p, b1) + self.arc(b2, a1) + self.arc(a2, q);
        // A B → B^r A^r (whole) → B A; every piece runs as before.
        self.reverse(a1, b2);
        self.reverse(b2, b1);
        self.reverse(a2, a1);
        self.cost += after - before;
        Some([p, a1, a2, b1, b2, q])
    }

    /// Descends to a local optimum, then kicks while the budget lasts and the search has not
    /// stagnated ([`STALL_CYCLES`]). The tour is valid (and
    /// never dearer than the start) whenever this returns.
    pub fn optimize(&mut self, budget: &Budget) -> Stats {
        let mut stats = Stats { start_cost: self.cost, ..Stats::default() };
        self.deadline = budget.deadline;
        let mut v = self.next(self.depot());
        while v != self.depot() {
            self.push(v);
            v = self.next(v);
        }
        self.run();
        stats.descent_cost = self.cost;
        let mut rng = Rng(budget.seed ^ 0x5EED_0FC0_FFEE_0000);
        let max_kicks = match (budget.kicks, budget.deadline) {
            (Some(k), _) => k,
            (None, Some(_)) => u64::MAX,
            (None, None) => 0,
        };
        let mut tries = 0u64;
        let mut stagnation = 0u64;
        let cycle = 2 * self.n as u64 + 50;
        while stats.kicks < max_kicks && !self.cut {
            if stagnation >= STALL_CYCLES * 4 * cycle {
                stats.stalled = true;
                break;
            }
            if tries & 15 == 0 && self.deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
            tries += 1;
            let before = self.cost;
            self.journal.clear();
            self.journaling = true;
            // Kicks grow stronger (several swaps at once) while the search stagnates.
            let strength = 1 + (stagnation / cycle) % 4;
            let mut kicked = false;
            for _ in 0..strength {
                if let Some(nodes) = self.kick(&mut rng) {
                    self.touch(&nodes);
                    kicked = true;
                }
            }
            // Kicks that found no legal place still count, so a work budget always ends.
            stats.kicks += 1;
            if !kicked {
                self.undo_all(before);
                continue;
            }
            self.run();
            if self.cost > before {
                self.undo_all(before);
            }
            // An improvement is one above the rounding the tracked deltas add (a kick undone by
            // the descent often comes back a few ulps cheaper).
            if self.cost < before - self.eps.max(1e-9 * before.abs()) {
                stagnation = 0;
            } else {
                stagnation += 1;
            }
            self.journaling = false;
        }
        self.journal.clear();
        self.journaling = false;
        // Re-anchor the tracked cost on the exact one (the deltas add rounding).
        self.cost = self.full_cost();
        stats.cost = self.cost;
        stats.moves = self.moves;
        stats
    }
}

/// Distance between an exit and an entry; a missing end (the free start or end) costs nothing.
#[inline]
fn link(a: Option<P2>, b: Option<P2>) -> f64 {
    match (a, b) {
        // Plain sqrt of squares (`hypot` guards against overflow no drawing reaches, at
        // several times the price).
        (Some(a), Some(b)) => ((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])).sqrt(),
        _ => 0.0,
    }
}

/// The nearest pieces of each piece ([`NEIGHBOURS`] for a closed contour, [`STROKE_NEIGHBOURS`] for an
/// open stroke; by the distance between any of their ends), from
/// a grid over every distinct entry and exit.
fn neighbours(ends: &[Vec<(P2, P2)>]) -> Vec<Vec<u32>> {
    let mut pts: Vec<(P2, u32)> = Vec::new();
    for (t, ms) in ends.iter().enumerate() {
        for &(e, x) in ms {
            pts.push((e, t as u32));
            if x != e {
                pts.push((x, t as u32));
            }
        }
    }
    pts.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal).then(a.1.cmp(&b.1)));
    pts.dedup();
    let grid = PointGrid::new(pts.iter().map(|p| p.0).collect());
    let mut found = Vec::new();
    let mut out = Vec::with_capacity(ends.len());
    for (t, ms) in ends.iter().enumerate() {
        let want = if ms.iter().all(|&(e, x)| e == x) { NEIGHBOURS } else { STROKE_NEIGHBOURS };
        let mut best: Vec<(f64, u32)> = Vec::new();
        let mut qs: Vec<P2> = ms.iter().flat_map(|&(e, x)| [e, x]).collect();
        qs.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        qs.dedup();
        for q in qs {
            // the `want` nearest points of other pieces: more points while this piece's own
            // entry candidates crowd them out (at most as many as the R-tree query took)
            let k_max = 4 * want + 2 * ms.len();
            let mut k = want + 2;
            loop {
                grid.nearest(q, k, &mut found);
                let others = found.iter().filter(|&&(_, i)| pts[i as usize].1 as usize != t).count();
                if others >= want || found.len() < k || k >= k_max {
                    break;
                }
                k = (2 * k).min(k_max);
            }
            let mut got = 0;
            for &(d2, i) in &found {
                let piece = pts[i as usize].1;
                if piece as usize == t {
                    continue;
                }
                best.push((d2, piece));
                got += 1;
                if got >= want {
                    break;
                }
            }
        }
        best.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut list: Vec<u32> = Vec::with_capacity(want);
        for (_, u) in best {
            if !list.contains(&u) {
                list.push(u);
                if list.len() == want {
                    break;
                }
            }
        }
        out.push(list);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random job: open strokes (some not reversible), closed contours with several entry
    /// candidates, optional start and precedence pairs (from lower to higher index, so acyclic).
    type Job = (Vec<Vec<(P2, P2)>>, Vec<(usize, usize)>, Option<P2>);

    fn job(seed: u64, n: usize, start: bool, prec: bool) -> Job {
        let mut rng = Rng(seed);
        let mut p = || [rng.below(1000) as f64 / 10.0, rng.below(1000) as f64 / 10.0];
        let mut ends = Vec::new();
        for t in 0..n {
            let kind = t % 4;
            let (a, b) = (p(), p());
            ends.push(match kind {
                0 | 1 => vec![(a, b), (b, a)],
                2 => vec![(a, b)],
                _ => vec![(a, a), (b, b), (p(), p())].into_iter().map(|(e, _)| (e, e)).collect(),
            });
        }
        let mut pairs = Vec::new();
        if prec {
            let mut r = Rng(seed ^ 77);
            for _ in 0..n / 3 {
                let (x, y) = (r.below(n), r.below(n));
                if x < y {
                    pairs.push((x, y));
                }
            }
        }
        (ends, pairs, if start { Some(p()) } else { None })
    }

    /// The route's pen-up length, recomputed from the steps alone.
    fn route_cost(ends: &[Vec<(P2, P2)>], start: Option<P2>, steps: &[(usize, u32)]) -> f64 {
        crate::greedy_match::pen_up(ends, start, steps)
    }

    fn feasible(ends: &[Vec<(P2, P2)>], pairs: &[(usize, usize)], steps: &[(usize, u32)]) -> bool {
        let mut at = vec![usize::MAX; ends.len()];
        for (k, &(t, m)) in steps.iter().enumerate() {
            if t >= ends.len() || at[t] != usize::MAX || m as usize >= ends[t].len() {
                return false;
            }
            at[t] = k;
        }
        at.iter().all(|&k| k != usize::MAX) && pairs.iter().all(|&(a, b)| at[a] < at[b])
    }

    /// The optimum by enumerating every order and every mode.
    fn brute(ends: &[Vec<(P2, P2)>], pairs: &[(usize, usize)], start: Option<P2>) -> f64 {
        fn go(
            ends: &[Vec<(P2, P2)>],
            pairs: &[(usize, usize)],
            at: Option<P2>,
            done: &mut Vec<bool>,
            left: usize,
            acc: f64,
            best: &mut f64,
        ) {
            if left == 0 {
                *best = best.min(acc);
                return;
            }
            for t in 0..ends.len() {
                if done[t] || pairs.iter().any(|&(a, b)| b == t && !done[a]) {
                    continue;
                }
                done[t] = true;
                for &(e, x) in &ends[t] {
                    let d = at.map_or(0.0, |a| ((a[0] - e[0]).powi(2) + (a[1] - e[1]).powi(2)).sqrt());
                    go(ends, pairs, Some(x), done, left - 1, acc + d, best);
                }
                done[t] = false;
            }
        }
        let mut best = f64::INFINITY;
        go(ends, pairs, start, &mut vec![false; ends.len()], ends.len(), 0.0, &mut best);
        best
    }

    /// A feasible start: pieces in index order (precedence pairs go from lower to higher).
    fn start_tour(n: usize) -> Vec<(usize, u32)> {
        (0..n).map(|t| (t, 0)).collect()
    }

    #[test]
    fn every_move_keeps_a_valid_tour_and_its_cost() {
        for seed in 0..60u64 {
            let n = 12 + (seed as usize % 25);
            let (ends, pairs, start) = job(seed, n, seed % 2 == 0, seed % 3 == 0);
            let mut s = StrokeSearch::new(&ends, &pairs, start, &start_tour(n));
            // Each node's moves one at a time, checked after every applied move.
            for round in 0..4 {
                for v in 0..n as u32 {
                    let before = s.cost();
                    let moved = s.try_state(v) || s.try_two_opt(v) || s.try_or_opt(v);
                    let steps = s.steps();
                    assert!(feasible(&ends, &pairs, &steps), "seed {seed} round {round}: infeasible after a move");
                    let exact = route_cost(&ends, start, &steps);
                    assert!((exact - s.cost()).abs() < 1e-7, "seed {seed}: tracked {} != {}", s.cost(), exact);
                    if moved {
                        assert!(s.cost() < before, "seed {seed}: a move made the tour dearer");
                    }
                }
            }
            // A kick, then undo: the same tour again.
            let mut rng = Rng(seed);
            let (steps0, cost0) = (s.steps(), s.cost());
            for _ in 0..20 {
                s.journal.clear();
                s.journaling = true;
                if s.kick(&mut rng).is_some() {
                    let steps = s.steps();
                    assert!(feasible(&ends, &pairs, &steps), "seed {seed}: infeasible kick");
                    assert!((route_cost(&ends, start, &steps) - s.cost()).abs() < 1e-7, "seed {seed}: kick cost");
                }
                s.undo_all(cost0);
                assert_eq!(s.steps(), steps0, "seed {seed}: undo did not restore the tour");
            }
        }
    }

    #[test]
    fn reaches_the_optimum_on_small_jobs() {
        let mut missed = Vec::new();
        for seed in 0..60u64 {
            let n = if seed % 6 == 0 { 7 } else { 4 + (seed as usize % 3) };
            let (ends, pairs, start) = job(seed + 1000, n, seed % 2 == 0, seed % 3 == 0);
            let mut s = StrokeSearch::new(&ends, &pairs, start, &start_tour(n));
            let stats = s.optimize(&Budget { deadline: None, kicks: Some(400), seed });
            let steps = s.steps();
            assert!(feasible(&ends, &pairs, &steps));
            let got = route_cost(&ends, start, &steps);
            assert!((got - stats.cost).abs() < 1e-7);
            let opt = brute(&ends, &pairs, start);
            assert!(got >= opt - 1e-7, "seed {seed}: below the optimum?");
            if got > opt + 1e-7 {
                missed.push((seed, got, opt));
            }
        }
        // A local search with kicks is not exact: under precedence with a one-way stroke it can
        // miss a move that needs a neighbour's entry changed at the same time (seen on 1 job of
        // 60, 4 pieces). In use, groups of up to 10 pieces are solved exactly instead.
        assert!(missed.len() <= 2, "not optimal on {} of 60 jobs: {missed:?}", missed.len());
    }

    #[test]
    fn a_small_job_stops_when_it_stagnates_not_at_its_deadline() {
        let (ends, pairs, start) = job(21, 30, true, false);
        let t0 = Instant::now();
        let mut s = StrokeSearch::new(&ends, &pairs, start, &start_tour(30));
        let stats =
            s.optimize(&Budget { deadline: Some(t0 + std::time::Duration::from_secs(60)), kicks: None, seed: 3 });
        assert!(stats.stalled, "{stats:?}");
        // at least one full cycle of the four kick strengths without an improvement
        assert!(stats.kicks >= STALL_CYCLES * 4 * (2 * 31 + 50), "{stats:?}");
        assert!(t0.elapsed().as_secs() < 30);
        assert!((route_cost(&ends, start, &s.steps()) - stats.cost).abs() < 1e-6);
    }

    #[test]
    fn same_budget_same_answer() {
        let (ends, pairs, start) = job(5, 300, false, false);
        let run = || {
            let mut s = StrokeSearch::new(&ends, &pairs, start, &start_tour(300));
            s.optimize(&Budget { deadline: None, kicks: Some(2000), seed: 9 });
            s.steps()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn improves_random_strokes_well_below_the_input_order() {
        // 2-opt and Or-opt on 400 random strokes: far below the random input order.
        let (ends, pairs, start) = job(11, 400, false, false);
        let mut s = StrokeSearch::new(&ends, &pairs, start, &start_tour(400));
        let stats = s.optimize(&Budget { deadline: None, kicks: Some(3000), seed: 1 });
        assert!(stats.descent_cost < 0.5 * stats.start_cost, "{stats:?}");
        assert!(stats.cost <= stats.descent_cost);
        assert!((route_cost(&ends, start, &s.steps()) - stats.cost).abs() < 1e-6);
    }
}
