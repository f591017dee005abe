//! Partition crossover of two tours on plain symmetric one-mode problems, in the spirit of
//! Whitley, Hains and Howe's GPX (2009): the arcs the two tours do not share fall into
//! connected components; inside each component one tour's arcs can replace the other's while
//! every node keeps two arcs. Starting from the cheaper tour, each component where the other
//! tour is cheaper is switched over, best gain first, and kept when the result is still one
//! cycle; when it is not (a reversal elsewhere turned the arcs round), it is tried together
//! with each other component whose switch keeps the sum of both gains positive.
//!
//! The search threads kick the same tour in different places, so at the end of an epoch their
//! improvements are mostly independent components: merging keeps both threads' work where
//! adopting the better tour would throw one away.

use super::net::Net;
use super::pieces::Pieces;
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

/// Most components switched over in one merge (each try costs a walk round the tour).
const MAX_TRIES: usize = 512;

/// The merge of `a` and `b` (same nodes, one mode each, symmetric arcs), when it is cheaper
/// than both by more than `eps`: its node sequence (anchor first) and the nodes whose arcs
/// changed from the cheaper tour's (for the local search to look at). `None` when no component
/// of the dearer tour pays off and still gives one cycle, alone or with one other component.
pub(crate) fn partition_crossover<C: CostModel>(
    net: &Net<C>,
    a: &Tour,
    b: &Tour,
    eps: Cost,
) -> Option<(Vec<u32>, Vec<u32>)> {
    let n = a.len();
    if n < 8 || b.len() != n {
        return None;
    }
    let (a, b) = if b.cost < a.cost { (b, a) } else { (a, b) };
    let adj = |t: &Tour, v: u32| [t.prev(v), t.next(v)];
    let shares = |t: &Tour, u: u32, v: u32| t.next(u) == v || t.prev(u) == v;
    let cost = |u: u32, v: u32| net.arc(u, 0, v, 0);

    // The arcs in one tour only, with the sign of their cost in the gain of switching from
    // a's arcs to b's (a's own arcs count for, b's against).
    let mut unshared: Vec<(u32, u32, Cost)> = Vec::new();
    for (t, other, sign) in [(a, b, 1.0), (b, a, -1.0)] {
        for i in 0..n {
            let (u, v) = (t.seq[i], t.next_of_pos(i));
            if !shares(other, u, v) {
                unshared.push((u, v, sign));
            }
        }
    }
    if unshared.is_empty() {
        return None;
    }
    // Their components (union-find over the end nodes) and each component's gain.
    let mut pieces = Pieces::new(n);
    let mut in_comp = vec![false; n];
    for &(u, v, _) in &unshared {
        pieces.join(u, v);
        in_comp[u as usize] = true;
        in_comp[v as usize] = true;
    }
    let mut gain: Vec<Cost> = vec![0.0; n];
    for &(u, v, sign) in &unshared {
        let r = pieces.root(u) as usize;
        gain[r] += sign * cost(u, v);
    }
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
    for v in 0..n as u32 {
        if in_comp[v as usize] {
            let r = pieces.root(v) as usize;
            members[r].push(v);
        }
    }
    // Every component, best gain first; the paying ones lead, and any may pair with a paying
    // one that cannot switch alone.
    let mut comps: Vec<usize> = (0..n).filter(|&r| !members[r].is_empty()).collect();
    comps.sort_by(|&x, &y| gain[y].total_cmp(&gain[x]).then(x.cmp(&y)));
    comps.truncate(MAX_TRIES);
    let paying = comps.iter().take_while(|&&r| gain[r] > eps).count();
    if paying == 0 {
        return None;
    }

    // The child's arcs, as a's to start with.
    let mut cur: Vec<[u32; 2]> = (0..n as u32).map(|v| adj(a, v)).collect();
    let shortcuts = Shortcuts::new(&cur, &in_comp);
    let mut done = vec![false; n];
    let mut switched: Vec<u32> = Vec::new();
    let mut total = 0.0;
    let mut tries = 0usize;
    let set = |cur: &mut Vec<[u32; 2]>, r: usize, t: &Tour| {
        for &v in &members[r] {
            cur[v as usize] = adj(t, v);
        }
    };
    for &r in &comps[..paying] {
        if done[r] {
            continue;
        }
        set(&mut cur, r, b);
        tries += 1;
        if shortcuts.one_cycle(&cur) {
            total += gain[r];
            done[r] = true;
            switched.extend_from_slice(&members[r]);
            continue;
        }
        // Switching one component can split the tour where another component's reversal
        // turned the arcs round; the two together may close again.
        let mut paired = false;
        for &o in &comps {
            if o == r || done[o] || gain[r] + gain[o] <= eps || tries >= MAX_TRIES * 4 {
                continue;
            }
            set(&mut cur, o, b);
            tries += 1;
            if shortcuts.one_cycle(&cur) {
                total += gain[r] + gain[o];
                done[r] = true;
                done[o] = true;
                switched.extend_from_slice(&members[r]);
                switched.extend_from_slice(&members[o]);
                paired = true;
                break;
            }
            set(&mut cur, o, a);
        }
        if !paired {
            set(&mut cur, r, a);
        }
    }
    if total <= eps {
        return None;
    }
    // Walk the child from the anchor.
    let mut seq = Vec::with_capacity(n);
    let (mut prev, mut x) = (u32::MAX, net.anchor);
    for _ in 0..n {
        seq.push(x);
        (prev, x) = (x, step(&cur, prev, x));
    }
    Some((seq, switched))
}

/// The node after `x` on a walk along the arcs (two per node) that came from `prev`.
#[inline]
fn step(adj: &[[u32; 2]], prev: u32, x: u32) -> u32 {
    let [p, q] = adj[x as usize];
    if p != prev {
        p
    } else {
        q
    }
}

/// The runs of arcs both tours share, for walking a child in steps between the nodes of the
/// components instead of node by node: a node outside every component keeps its two arcs in
/// any child, so from a component's node `v` on to such a neighbour `u` the walk always goes on
/// along the same run until it meets the next node of a component. At 10,000 points the
/// components of two local optima hold a fraction of the nodes, and each try of a component
/// walks only those.
struct Shortcuts {
    /// The first node of a component on the run, the node just before it, and the run's length
    /// in arcs, keyed by (component node, its neighbour outside the components) at `slot[v]`.
    runs: Vec<[(u32, u32, u32, u32); 2]>,
    /// A node of a component to start the walk from (`u32::MAX` when there is none).
    start: u32,
    /// Nodes in all.
    n: usize,
}

impl Shortcuts {
    /// The runs from every component node of `adj` (the arcs of one parent) along its
    /// neighbours outside the components (`in_comp[v]`: `v` is a node of some component).
    fn new(adj: &[[u32; 2]], in_comp: &[bool]) -> Self {
        let n = adj.len();
        let none = (u32::MAX, u32::MAX, u32::MAX, 0);
        let mut runs = vec![[none; 2]; n];
        let mut start = u32::MAX;
        for v in 0..n as u32 {
            if !in_comp[v as usize] {
                continue;
            }
            if start == u32::MAX {
                start = v;
            }
            for (k, &u) in adj[v as usize].iter().enumerate() {
                if in_comp[u as usize] {
                    continue;
                }
                let (mut prev, mut x, mut len) = (v, u, 1u32);
                while !in_comp[x as usize] {
                    (prev, x) = (x, step(adj, prev, x));
                    len += 1;
                }
                runs[v as usize][k] = (u, x, prev, len);
            }
        }
        Shortcuts { runs, start, n }
    }

    /// Whether the arcs (two per node) form one cycle through every node; the nodes outside the
    /// components must have the arcs they had when `self` was built.
    fn one_cycle(&self, adj: &[[u32; 2]]) -> bool {
        if self.start == u32::MAX {
            return one_cycle(adj);
        }
        let (mut prev, mut x) = (u32::MAX, self.start);
        let mut k = 0usize;
        loop {
            let y = step(adj, prev, x);
            let [r0, r1] = self.runs[x as usize];
            let run = if r0.0 == y {
                Some(r0)
            } else if r1.0 == y {
                Some(r1)
            } else {
                None
            };
            match run {
                Some((_, end, before, len)) => {
                    (prev, x) = (before, end);
                    k += len as usize;
                }
                None => {
                    (prev, x) = (x, y);
                    k += 1;
                }
            }
            if x == self.start {
                return k == self.n;
            }
            if k >= self.n {
                return false;
            }
        }
    }
}

/// Whether the arcs (two per node) form one cycle through every node.
fn one_cycle(adj: &[[u32; 2]]) -> bool {
    let n = adj.len();
    let (mut prev, mut x) = (u32::MAX, 0u32);
    for k in 1..=n {
        (prev, x) = (x, step(adj, prev, x));
        if x == 0 {
            return k == n;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::search::testing::random_tour_problem;

    /// Two tours that differ by improving 2-opt moves in different places merge into one tour
    /// holding both improvements: a single cycle through every node, anchor first, costing what
    /// its arcs sum to and less than either parent.
    #[test]
    fn independent_improvements_of_two_tours_are_both_kept() {
        let n = 200;
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let p = random_tour_problem(&mut rng, n, 1000.0);
        let net = Net::new(&p);
        let mut merged_some = 0;
        for trial in 0..50 {
            let seq: Vec<u32> = (0..n as u32).collect();
            let parent = Tour::new(&net, seq, vec![0; n]);
            // an improving reversal in the first half for a, in the second half for b
            let improve = |t: &mut Tour, lo_range: std::ops::Range<usize>, rng: &mut Pcg64Mcg| {
                for _ in 0..200 {
                    let i = rng.gen_range(lo_range.clone());
                    let j = rng.gen_range(i + 1..lo_range.end + 10);
                    let before = t.cost;
                    t.reverse(i, j);
                    t.cost = t.full_cost(&net);
                    if t.cost < before - 1e-9 {
                        return;
                    }
                    t.reverse(i, j);
                    t.cost = before;
                }
            };
            let mut a = parent.clone();
            let mut b = parent.clone();
            improve(&mut a, 1..80, &mut rng);
            improve(&mut b, 110..180, &mut rng);
            let Some((seq, switched)) = partition_crossover(&net, &a, &b, 1e-9) else {
                continue;
            };
            assert!(!switched.is_empty(), "trial {trial}");
            assert_eq!(seq[0], net.anchor);
            let mut seen = vec![false; n];
            for &v in &seq {
                assert!(!seen[v as usize], "trial {trial}: node {v} twice");
                seen[v as usize] = true;
            }
            let child = Tour::new(&net, seq, vec![0; n]);
            assert!(child.cost < a.cost.min(b.cost) - 1e-9, "trial {trial}");
            // both improvements are in: the child costs what the parent did less both gains
            let want = parent.cost - (parent.cost - a.cost) - (parent.cost - b.cost);
            assert!((child.cost - want).abs() < 1e-6, "trial {trial}: {} != {want}", child.cost);
            merged_some += 1;
        }
        assert!(merged_some >= 40, "only {merged_some} merges");
    }

    /// A child is only ever one cycle: on random pairs of tours (whose differences overlap
    /// everywhere) every merge returned is a permutation and no dearer than its parents.
    #[test]
    fn merges_of_unrelated_tours_are_tours() {
        let n = 60;
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        let p = random_tour_problem(&mut rng, n, 100.0);
        let net = Net::new(&p);
        let shuffled = |rng: &mut Pcg64Mcg| {
            let mut s: Vec<u32> = (0..n as u32).collect();
            for i in (2..n).rev() {
                s.swap(i, rng.gen_range(1..=i));
            }
            Tour::new(&net, s, vec![0; n])
        };
        for trial in 0..300 {
            let a = shuffled(&mut rng);
            let mut b = a.clone();
            // a few random reversals: overlapping, not necessarily improving
            for _ in 0..rng.gen_range(1..6) {
                let i = rng.gen_range(1..n - 1);
                let j = rng.gen_range(i + 1..n);
                b.reverse(i, j);
            }
            b.cost = b.full_cost(&net);
            if let Some((seq, _)) = partition_crossover(&net, &a, &b, 1e-9) {
                let mut sorted = seq.clone();
                sorted.sort_unstable();
                assert_eq!(sorted, (0..n as u32).collect::<Vec<_>>(), "trial {trial}");
                let child = Tour::new(&net, seq, vec![0; n]);
                assert!(child.cost < a.cost.min(b.cost) + 1e-9, "trial {trial}");
            }
        }
    }

    /// The walk along shared runs answers as the walk node by node does, on children that
    /// take each component of two tours' unshared arcs from either tour at random.
    #[test]
    fn shortcut_walks_agree_with_node_by_node_walks() {
        let mut rng = Pcg64Mcg::seed_from_u64(17);
        for trial in 0..400 {
            let n = rng.gen_range(8..80usize);
            let mut seq: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                seq.swap(i, rng.gen_range(0..=i));
            }
            let mut other = seq.clone();
            for _ in 0..rng.gen_range(1..5) {
                let i = rng.gen_range(0..n - 1);
                let j = rng.gen_range(i + 1..n);
                other[i..=j].reverse();
            }
            let adj_of = |s: &[u32]| {
                let mut adj = vec![[0u32; 2]; n];
                for i in 0..n {
                    adj[s[i] as usize] = [s[(i + n - 1) % n], s[(i + 1) % n]];
                }
                adj
            };
            let (a, b) = (adj_of(&seq), adj_of(&other));
            let has = |adj: &[[u32; 2]], u: u32, v: u32| adj[u as usize].contains(&v);
            let mut parent: Vec<usize> = (0..n).collect();
            fn root(parent: &[usize], mut x: usize) -> usize {
                while parent[x] != x {
                    x = parent[x];
                }
                x
            }
            let mut in_comp = vec![false; n];
            for (t, o) in [(&a, &b), (&b, &a)] {
                for u in 0..n as u32 {
                    for &v in &t[u as usize] {
                        if !has(o, u, v) {
                            in_comp[u as usize] = true;
                            in_comp[v as usize] = true;
                            let (ru, rv) = (root(&parent, u as usize), root(&parent, v as usize));
                            parent[ru] = rv;
                        }
                    }
                }
            }
            let shortcuts = Shortcuts::new(&a, &in_comp);
            for _ in 0..8 {
                let take_b: Vec<bool> = (0..n).map(|_| rng.gen_bool(0.5)).collect();
                let cur: Vec<[u32; 2]> =
                    (0..n).map(|v| if in_comp[v] && take_b[root(&parent, v)] { b[v] } else { a[v] }).collect();
                assert_eq!(shortcuts.one_cycle(&cur), one_cycle(&cur), "trial {trial}");
            }
            assert!(shortcuts.one_cycle(&a) && shortcuts.one_cycle(&b), "trial {trial}");
        }
    }
}
