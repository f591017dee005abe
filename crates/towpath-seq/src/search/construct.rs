//! Construction heuristics: nearest neighbour (with Doherty et al.'s (2022) seed pool) and a space-filling
//! curve for very large instances. Both respect precedence and consecutive groups.

use std::time::Instant;

use super::neighbors::Neighbors;
use super::net::Net;
use crate::cost::{Cost, CostModel};
use crate::model::{TaskId, NO_GROUP};

/// A tour as (sequence with position 0 fixed, mode per node).
pub(crate) type Seq = (Vec<u32>, Vec<u32>);

/// Nearest-neighbour construction. `first` picks the first task when the route has no fixed
/// start (ignored otherwise; it must have no predecessors).
pub(crate) fn nearest_neighbor<C: CostModel>(
    net: &Net<C>,
    first: Option<u32>,
    deadline: Option<Instant>,
) -> Option<Seq> {
    let mut b = Builder::new(net);
    let has_depot = net.depot != u32::MAX;
    let mut cur = u32::MAX;
    if has_depot {
        b.seq.push(net.depot);
        cur = net.depot;
    }
    let first = if has_depot && net.p.start().is_some() { None } else { first };
    let first = net.p.first_task().map(|t| t.0).or(first);
    let first = first.or(if has_depot { None } else { Some(net.anchor) });
    if let Some(f) = first {
        if b.allowed(f) {
            let price = |m: u32| if has_depot { net.arc(net.depot, 0, f, m) } else { 0.0 } + net.mode_cost(f, m);
            let m = (0..net.num_modes(f)).min_by(|&a, &c| price(a).total_cmp(&price(c))).unwrap_or(0);
            b.take(f, m);
            cur = f;
        }
    }
    while b.seq.len() < net.n {
        if b.seq.len() % 64 == 0 && deadline.is_some_and(|d| Instant::now() >= d) {
            return None;
        }
        let cm = if cur == u32::MAX { 0 } else { b.mode[cur as usize] };
        let mut best: (Cost, u32, u32) = (Cost::INFINITY, u32::MAX, 0);
        for &u in b.avail.iter() {
            if !b.allowed(u) {
                continue;
            }
            for mu in 0..net.num_modes(u) {
                let c = if cur == u32::MAX { 0.0 } else { net.arc(cur, cm, u, mu) } + net.mode_cost(u, mu);
                if best.1 == u32::MAX || c < best.0 || (c == best.0 && (u, mu) < (best.1, best.2)) {
                    best = (c, u, mu);
                }
            }
        }
        let (_, u, mu) = best;
        debug_assert!(u != u32::MAX, "a feasible problem always has an available task");
        if u == u32::MAX {
            break;
        }
        b.take(u, mu);
        cur = u;
    }
    let mut seq = b.seq;
    let mode = b.mode;
    rotate_to_anchor(net, &mut seq);
    Some((seq, mode))
}

/// Nearest neighbour through candidate lists, for plain one-mode tours: from `first`, to the
/// nearest unvisited node on the current node's list (`nb`, sorted by cost), or when the whole
/// list is visited, to the nearest unvisited node of all. The lists make it about O(n·k) where
/// [`nearest_neighbor`] is O(n²) (at 10,000 points about 1.2 s against some 30 ms).
pub(crate) fn nearest_neighbor_by_lists<C: CostModel>(net: &Net<C>, nb: &Neighbors, first: u32) -> Vec<u32> {
    let n = net.n;
    // the unvisited nodes, and each node's place among them (u32::MAX once visited)
    let mut left: Vec<u32> = (0..n as u32).collect();
    let mut at: Vec<u32> = (0..n as u32).collect();
    let take = |left: &mut Vec<u32>, at: &mut Vec<u32>, v: u32| {
        let i = at[v as usize] as usize;
        let last = *left.last().expect("v is unvisited");
        left.swap_remove(i);
        at[last as usize] = i as u32;
        at[v as usize] = u32::MAX;
    };
    let mut seq = Vec::with_capacity(n);
    if n == 0 {
        return seq;
    }
    let mut cur = first.min(n as u32 - 1);
    take(&mut left, &mut at, cur);
    seq.push(cur);
    while !left.is_empty() {
        let mut best = (Cost::INFINITY, u32::MAX);
        for &u in nb.out(cur) {
            if at[u as usize] != u32::MAX {
                let c = net.arc(cur, 0, u, 0);
                if c < best.0 {
                    best = (c, u);
                }
            }
        }
        if best.1 == u32::MAX {
            for &u in &left {
                let c = net.arc(cur, 0, u, 0);
                if best.1 == u32::MAX || c < best.0 {
                    best = (c, u);
                }
            }
        }
        cur = best.1;
        take(&mut left, &mut at, cur);
        seq.push(cur);
    }
    rotate_to_anchor(net, &mut seq);
    seq
}

/// The tour that takes the tasks in the order of `pos` (a position per node), each as soon as
/// precedence and consecutive groups let it: of the tasks that may come next, the one earliest
/// in that order (a stable topological order). Every task keeps its mode 0.
pub(crate) fn follow_order<C: CostModel>(net: &Net<C>, pos: &[u32]) -> Option<Seq> {
    let mut b = Builder::new(net);
    if net.depot != u32::MAX {
        b.seq.push(net.depot);
    }
    while b.seq.len() < net.n {
        let next = b.avail.iter().copied().filter(|&u| b.allowed(u)).min_by_key(|&u| (pos[u as usize], u))?;
        b.take(next, 0);
    }
    let mut seq = b.seq;
    rotate_to_anchor(net, &mut seq);
    Some((seq, b.mode))
}

/// Bookkeeping for constructions that add tasks one at a time while keeping precedence and
/// consecutive groups.
struct Builder<'a, 'p, C> {
    net: &'a Net<'p, C>,
    seq: Vec<u32>,
    mode: Vec<u32>,
    indeg: Vec<u32>,
    avail: Vec<u32>,
    /// external predecessors not yet done, per group
    group_ext: Vec<u32>,
    group_left: Vec<u32>,
    current_group: u32,
    done: Vec<bool>,
}

impl<'a, 'p, C: CostModel> Builder<'a, 'p, C> {
    fn new(net: &'a Net<'p, C>) -> Self {
        let n_tasks = net.n_tasks;
        let indeg: Vec<u32> = (0..n_tasks as u32).map(|t| net.predecessors(t).len() as u32).collect();
        let mut group_ext = vec![0u32; net.p.groups().len()];
        for t in 0..n_tasks as u32 {
            let g = net.group(t);
            if g != NO_GROUP {
                group_ext[g as usize] += net.predecessors(t).iter().filter(|&&p| net.group(p) != g).count() as u32;
            }
        }
        let avail = (0..n_tasks as u32).filter(|&t| indeg[t as usize] == 0).collect();
        Builder {
            net,
            seq: Vec::with_capacity(net.n),
            mode: vec![0; net.n],
            indeg,
            avail,
            group_ext,
            group_left: net.p.groups().iter().map(|g| g.len() as u32).collect(),
            current_group: NO_GROUP,
            done: vec![false; n_tasks],
        }
    }

    /// May `u` (an available task) come next?
    fn allowed(&self, u: u32) -> bool {
        if self.indeg[u as usize] != 0 || self.done[u as usize] {
            return false;
        }
        let g = self.net.group(u);
        if self.current_group != NO_GROUP {
            return g == self.current_group;
        }
        g == NO_GROUP || self.group_ext[g as usize] == 0
    }

    fn take(&mut self, t: u32, m: u32) {
        let net = self.net;
        self.seq.push(t);
        self.mode[t as usize] = m;
        self.done[t as usize] = true;
        if let Some(i) = self.avail.iter().position(|&x| x == t) {
            self.avail.swap_remove(i);
        }
        let g = net.group(t);
        self.current_group = NO_GROUP;
        if g != NO_GROUP {
            self.group_left[g as usize] -= 1;
            if self.group_left[g as usize] > 0 {
                self.current_group = g;
            }
        }
        for &s in net.successors(t) {
            self.indeg[s as usize] -= 1;
            if self.indeg[s as usize] == 0 {
                self.avail.push(s);
            }
            let gs = net.group(s);
            if gs != NO_GROUP && gs != g {
                self.group_ext[gs as usize] -= 1;
            }
        }
    }
}

/// Rotates a cyclic sequence so that the anchor is at position 0.
pub(crate) fn rotate_to_anchor<C: CostModel>(net: &Net<C>, seq: &mut [u32]) {
    if let Some(i) = seq.iter().position(|&v| v == net.anchor) {
        seq.rotate_left(i);
    }
}

/// Doherty et al.'s (2022) seed pool: candidate first tasks for nearest neighbour. All tasks when the
/// instance is small; otherwise an evenly spread sample of `limit`. Always includes the task
/// whose total distance to all others is largest.
pub(crate) fn seed_pool<C: CostModel>(net: &Net<C>, limit: usize) -> Vec<u32> {
    let n = net.n_tasks as u32;
    if n == 0 {
        return Vec::new();
    }
    if (n as usize) <= limit {
        let mut v: Vec<u32> = (0..n).collect();
        v.push(farthest(net));
        v.dedup();
        return v;
    }
    let mut v = vec![farthest(net)];
    let step = n as usize / limit.max(1);
    for k in 0..limit.saturating_sub(1) {
        let t = (k * step) as u32;
        if !v.contains(&t) {
            v.push(t);
        }
    }
    v
}

/// The task with the largest total cost to all others (sampled when large).
fn farthest<C: CostModel>(net: &Net<C>) -> u32 {
    let n = net.n_tasks;
    let stride = (n / 512).max(1);
    let mut best = (Cost::NEG_INFINITY, 0u32);
    for t in 0..n as u32 {
        let mut total = 0.0;
        for u in (0..n as u32).step_by(stride) {
            if u != t {
                let c = net.arc(t, 0, u, 0);
                if c.is_finite() {
                    total += c;
                }
            }
        }
        if total > best.0 {
            best = (total, t);
        }
    }
    best.1
}

/// Orders tasks along a Hilbert curve through their first mode's entry position. Only for
/// instances without precedence or groups whose cost model has positions.
pub(crate) fn space_filling<C: CostModel>(net: &Net<C>) -> Option<Seq> {
    if net.has_prec || net.has_groups {
        return None;
    }
    let cm = net.p.cost_model();
    let pts: Option<Vec<[f64; 3]>> =
        (0..net.n_tasks as u32).map(|t| cm.position(net.p.modes(TaskId(t))[0].entry)).collect();
    let pts = pts?;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &pts {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-300);
    let scale = 65535.0 / span;
    let mut keyed: Vec<(u64, u32)> = pts
        .iter()
        .enumerate()
        .map(|(t, p)| {
            let x = ((p[0] - lo[0]) * scale) as u32;
            let y = ((p[1] - lo[1]) * scale) as u32;
            (hilbert_index(16, x, y), t as u32)
        })
        .collect();
    keyed.sort_unstable();
    let mut seq = Vec::with_capacity(net.n);
    if net.depot != u32::MAX {
        seq.push(net.depot);
    }
    seq.extend(keyed.into_iter().map(|(_, t)| t));
    rotate_to_anchor(net, &mut seq);
    Some((seq, vec![0; net.n]))
}

/// Position of (x, y) along a Hilbert curve of order `bits`.
fn hilbert_index(bits: u32, mut x: u32, mut y: u32) -> u64 {
    let n: u32 = 1 << bits;
    let mut d: u64 = 0;
    let mut s: u32 = n >> 1;
    while s > 0 {
        let rx = u32::from(x & s > 0);
        let ry = u32::from(y & s > 0);
        d += (s as u64) * (s as u64) * ((3 * rx) ^ ry) as u64;
        if ry == 0 {
            if rx == 1 {
                x = n - 1 - x;
                y = n - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s >>= 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::search::testing::random_tour_problem;

    /// With lists of every other node, the walk through the lists is the nearest-neighbour
    /// tour itself; with short lists it still visits every node once, anchor first.
    #[test]
    fn nearest_neighbor_through_lists_is_nearest_neighbor() {
        for seed in 0..20u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = 5 + seed as usize * 7;
            let p = random_tour_problem(&mut rng, n, 1000.0);
            let net = Net::new(&p);
            let first = (seed as u32 * 3) % n as u32;
            let full = Neighbors::build(&net, n - 1);
            let (expected, _) = nearest_neighbor(&net, Some(first), None).expect("no deadline");
            assert_eq!(nearest_neighbor_by_lists(&net, &full, first), expected, "seed {seed}");
            let short = Neighbors::build(&net, 3);
            let mut seq = nearest_neighbor_by_lists(&net, &short, first);
            assert_eq!(seq[0], net.anchor, "seed {seed}");
            seq.sort_unstable();
            assert_eq!(seq, (0..n as u32).collect::<Vec<_>>(), "seed {seed}");
        }
    }
}
