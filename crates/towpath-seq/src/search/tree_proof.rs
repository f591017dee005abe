//! Branch and bound over spanning trees, which proves a small route over reversible segments
//! optimal or finds the optimum, for [`super::solve_reversible`].
//!
//! A route's transits join home (if any) and the tasks in a path: a spanning tree over them in
//! which every task has at most two neighbours (home one), and in which the two transits at a
//! task use its two different ends (it is entered at one and left at the other). Relaxing all
//! but the tree gives a lower bound: the minimum spanning tree whose edge between two tasks
//! costs the cheapest arc between their ends. When that tree is a path, the cheapest route
//! through the tasks in its order (each task's direction chosen by dynamic programming along
//! the path) is a route; when that route costs what the tree does, no route in the branch is
//! cheaper. Otherwise (a task with three neighbours, or a zigzag whose even number of passes
//! makes it leave by the far end) every cheaper route leaves out one of the tree's edges, and
//! the children partition the routes by the first edge they leave out: child *i* forbids edge
//! *i* and requires edges 1 to *i* − 1 (Held & Karp 1971; Volgenant & Jonker 1982's branching on
//! 1-trees). At a task with three or more neighbours only its edges need branching (a route
//! keeps at most two of them).
//!
//! The search is depth first, prunes a branch whose tree is not cheaper than the best route
//! known, and gives up after a budget of trees: it then says nothing about optimality, but a
//! better route found on the way is returned.

use crate::cost::Cost;

/// What the search found.
#[derive(Debug, Default)]
pub(super) struct Proof {
    /// No route costs less than the best one known (the incumbent or `better`) less the
    /// tolerance.
    pub proven: bool,
    /// A route cheaper than the incumbent: tasks in order and whether each runs backwards
    /// (entered at its end `2t + 1`).
    pub better: Option<(Vec<u32>, Vec<bool>)>,
    /// Trees priced.
    pub nodes: usize,
}

/// The dense instance as [`super::solve_reversible`] builds it: `d` is an `m × m` matrix over
/// the task ends (end `2t` is where task `t` is entered running forwards, `2t + 1` where it is
/// left), then home (`2n`), whose arcs count only when there is a home.
pub(super) struct Trees<'a> {
    d: &'a [Cost],
    m: usize,
    n: usize,
    has_home: bool,
    /// Nodes of the tree: the tasks, then home when there is one.
    k: usize,
    /// Cheapest arc between two nodes' ends, `k × k`.
    w: Vec<Cost>,
}

impl<'a> Trees<'a> {
    pub(super) fn new(d: &'a [Cost], m: usize, n: usize, has_home: bool) -> Trees<'a> {
        let k = n + usize::from(has_home);
        let mut w = vec![Cost::INFINITY; k * k];
        let home = 2 * n;
        for a in 0..n {
            for b in a + 1..n {
                let (x, y) = (2 * a, 2 * b);
                let c = d[x * m + y].min(d[x * m + y + 1]).min(d[(x + 1) * m + y]).min(d[(x + 1) * m + y + 1]);
                w[a * k + b] = c;
                w[b * k + a] = c;
            }
            if has_home {
                let c = d[home * m + 2 * a].min(d[home * m + 2 * a + 1]);
                w[a * k + n] = c;
                w[n * k + a] = c;
            }
        }
        Trees { d, m, n, has_home, k, w }
    }

    /// The cost of the minimum spanning tree: no route's transits cost less.
    pub(super) fn bound(&self) -> Cost {
        prim(self.w.clone(), None, self.k).map_or(Cost::INFINITY, |t| t.total)
    }

    #[inline]
    fn arc(&self, u: usize, v: usize) -> Cost {
        self.d[u * self.m + v]
    }

    /// Searches for a route cheaper than `incumbent - tol`, pricing at most `node_limit` trees;
    /// gives up at once when the best route known after the first tree costs more than
    /// `1 + max_gap` times that tree.
    pub(super) fn prove(&self, incumbent: Cost, tol: Cost, max_gap: f64, node_limit: usize) -> Proof {
        let k = self.k;
        let mut s = Search {
            trees: self,
            best: incumbent,
            tol,
            max_gap,
            limit: node_limit,
            proof: Proof::default(),
            excluded: Vec::new(),
            required: Vec::new(),
            aborted: false,
            req: vec![false; k * k],
        };
        s.node();
        s.proof.proven = !s.aborted;
        s.proof
    }

    /// The cheapest route that visits the tasks in `order` (home first when there is one), and
    /// its cost: each task's direction by dynamic programming over the path.
    fn route_along(&self, order: &[usize]) -> (Cost, Vec<u32>, Vec<bool>) {
        let tasks: &[usize] = if self.has_home { &order[1..] } else { order };
        let len = tasks.len();
        // cost[i][r]: cheapest way to have done tasks[..=i] with tasks[i] run backwards iff r.
        let mut cost = vec![[0.0; 2]; len];
        let mut from = vec![[0u8; 2]; len];
        for r in 0..2 {
            let entry = 2 * tasks[0] + r;
            cost[0][r] = if self.has_home { self.arc(2 * self.n, entry) } else { 0.0 };
        }
        for i in 1..len {
            for r in 0..2 {
                let entry = 2 * tasks[i] + r;
                let (c0, c1) = (
                    cost[i - 1][0] + self.arc(2 * tasks[i - 1] + 1, entry),
                    cost[i - 1][1] + self.arc(2 * tasks[i - 1], entry),
                );
                let pick = u8::from(c1 < c0);
                cost[i][r] = c0.min(c1);
                from[i][r] = pick;
            }
        }
        let mut r = u8::from(cost[len - 1][1] < cost[len - 1][0]);
        let total = cost[len - 1][r as usize];
        let mut dir = vec![false; self.n];
        for i in (0..len).rev() {
            dir[tasks[i]] = r == 1;
            r = from[i][r as usize];
        }
        (total, tasks.iter().map(|&t| t as u32).collect(), dir)
    }
}

struct Search<'t, 'a> {
    trees: &'t Trees<'a>,
    best: Cost,
    tol: Cost,
    max_gap: f64,
    limit: usize,
    proof: Proof,
    /// Edges (node pairs) forbidden and required on the way from the root to this node.
    excluded: Vec<(usize, usize)>,
    required: Vec<(usize, usize)>,
    aborted: bool,
    /// Scratch: the required edges as a matrix.
    req: Vec<bool>,
}

impl Search<'_, '_> {
    fn node(&mut self) {
        if self.aborted {
            return;
        }
        if self.proof.nodes >= self.limit {
            self.aborted = true;
            return;
        }
        self.proof.nodes += 1;
        let Some(tree) = self.tree() else {
            return; // no spanning tree keeps the rules: no route in this branch
        };
        let (total, parent) = (tree.total, &tree.parent);
        if total >= self.best - self.tol {
            return;
        }
        let t = self.trees;
        let k = t.k;
        let mut degree = vec![0u32; k];
        for v in 1..k {
            degree[v] += 1;
            degree[parent[v]] += 1;
        }
        let cap = |a: usize| if t.has_home && a == t.n { 1 } else { 2 };
        let edges: Vec<(usize, usize)> = (1..k).map(|v| (parent[v], v)).collect();
        let branch_on: Vec<(usize, usize)> = match (0..k).find(|&a| degree[a] > cap(a)) {
            Some(a) => edges.iter().copied().filter(|&(p, v)| p == a || v == a).collect(),
            None => {
                let order = path_order(parent, &degree, if t.has_home { Some(t.n) } else { None });
                let (cost, seq, dir) = t.route_along(&order);
                if cost < self.best - self.tol {
                    self.best = cost;
                    self.proof.better = Some((seq, dir));
                }
                if cost <= total + self.tol {
                    return; // the tree is a route: nothing in this branch is cheaper
                }
                edges
            }
        };
        if self.proof.nodes == 1 && self.best - total > self.max_gap * total {
            // Far from the bound: branching would take more trees than the budget allows.
            self.aborted = true;
            return;
        }
        let before = self.required.len();
        for &(a, b) in &branch_on {
            if self.is_required(a, b) {
                continue;
            }
            // The child's tree is this one with the edge swapped for the cheapest across its
            // cut: priced without Prim, most children end here.
            if tree.without(b) < self.best - self.tol {
                self.excluded.push((a, b));
                self.node();
                self.excluded.pop();
            }
            self.required.push((a, b));
            if self.aborted || !self.required_fits(a) || !self.required_fits(b) {
                break;
            }
        }
        self.required.truncate(before);
    }

    fn is_required(&self, a: usize, b: usize) -> bool {
        self.required.iter().any(|&(x, y)| (x, y) == (a, b) || (x, y) == (b, a))
    }

    /// Whether node `a` has no more required edges than a route allows it.
    fn required_fits(&self, a: usize) -> bool {
        let t = self.trees;
        let cap = if t.has_home && a == t.n { 1 } else { 2 };
        self.required.iter().filter(|&&(x, y)| x == a || y == a).count() <= cap
    }

    /// The minimum spanning tree with every required edge and no excluded one (Prim's
    /// algorithm, required edges first), or `None` when there is none.
    fn tree(&mut self) -> Option<Tree> {
        let t = self.trees;
        let k = t.k;
        let mut w = t.w.clone();
        self.req.fill(false);
        for &(a, b) in &self.excluded {
            w[a * k + b] = Cost::INFINITY;
            w[b * k + a] = Cost::INFINITY;
        }
        for &(a, b) in &self.required {
            self.req[a * k + b] = true;
            self.req[b * k + a] = true;
        }
        prim(w, Some(&self.req), k)
    }
}

/// Prim's algorithm over the `k × k` edge costs `w`, the `req`uired edges first: the minimum
/// spanning tree that holds every required edge, or `None` when no spanning tree avoids the
/// infinite (excluded) edges.
fn prim(w: Vec<Cost>, req: Option<&[bool]>, k: usize) -> Option<Tree> {
    // key: (not required, cost), smallest first
    let mut key = vec![(true, Cost::INFINITY); k];
    let mut parent = vec![0usize; k];
    let mut done = vec![false; k];
    let mut order = Vec::with_capacity(k);
    key[0] = (false, 0.0);
    let mut total = 0.0;
    for _ in 0..k {
        let mut u = usize::MAX;
        for v in 0..k {
            if !done[v] && (u == usize::MAX || key[v] < key[u]) {
                u = v;
            }
        }
        if !key[u].1.is_finite() {
            return None;
        }
        done[u] = true;
        order.push(u);
        total += key[u].1;
        for v in 0..k {
            let cand = (!req.is_some_and(|r| r[u * k + v]), w[u * k + v]);
            if !done[v] && cand < key[v] {
                key[v] = cand;
                parent[v] = u;
            }
        }
    }
    // The required edges all come from one tree (each child's constraints are its parent's
    // tree's edges), so they form a forest and the tree holds every one of them.
    Some(Tree { total, parent, order, w })
}

/// A node's minimum spanning tree: its cost, each node's parent (node 0 is the root), the
/// nodes in the order they joined (parents first) and the edge costs it was priced with.
struct Tree {
    total: Cost,
    parent: Vec<usize>,
    order: Vec<usize>,
    w: Vec<Cost>,
}

impl Tree {
    /// The cost of the minimum spanning tree without the edge from `v` to its parent (all
    /// else as for this tree): this tree less that edge plus the cheapest other edge across
    /// the cut it leaves (`v`'s subtree against the rest).
    fn without(&self, v: usize) -> Cost {
        let k = self.parent.len();
        let mut below = vec![false; k];
        below[v] = true;
        let start = self.order.iter().position(|&u| u == v).unwrap_or(k);
        for &u in &self.order[start..] {
            if u != v && below[self.parent[u]] {
                below[u] = true;
            }
        }
        let p = self.parent[v];
        let mut cheapest = Cost::INFINITY;
        for a in (0..k).filter(|&a| below[a]) {
            for b in (0..k).filter(|&b| !below[b]) {
                if (a, b) != (v, p) && self.w[a * k + b] < cheapest {
                    cheapest = self.w[a * k + b];
                }
            }
        }
        self.total - self.w[p * k + v] + cheapest
    }
}

/// The nodes of a tree with no node of degree above two, from one end of the path to the
/// other (from `start` when given: home is an end).
fn path_order(parent: &[usize], degree: &[u32], start: Option<usize>) -> Vec<usize> {
    let k = parent.len();
    let mut adj = vec![[usize::MAX; 2]; k];
    for v in 1..k {
        for (a, b) in [(v, parent[v]), (parent[v], v)] {
            let slot = if adj[a][0] == usize::MAX { 0 } else { 1 };
            adj[a][slot] = b;
        }
    }
    let first = start.unwrap_or_else(|| (0..k).find(|&a| degree[a] <= 1).unwrap_or(0));
    let mut order = Vec::with_capacity(k);
    let (mut prev, mut cur) = (usize::MAX, first);
    while cur != usize::MAX && order.len() < k {
        order.push(cur);
        let next = if adj[cur][0] != prev { adj[cur][0] } else { adj[cur][1] };
        prev = cur;
        cur = next;
    }
    order
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;

    /// The dense matrix over `segments`' ends, then home (if any) and an unused tail.
    fn matrix(segments: &[([f64; 2], [f64; 2])], home: Option<[f64; 2]>) -> (Vec<Cost>, usize) {
        let mut pts: Vec<[f64; 2]> = segments.iter().flat_map(|&(a, b)| [a, b]).collect();
        pts.push(home.unwrap_or([0.0, 0.0]));
        pts.push([0.0, 0.0]);
        let m = pts.len();
        let mut d = vec![0.0; m * m];
        for u in 0..m - 1 {
            for v in 0..m - 1 {
                d[u * m + v] = (pts[u][0] - pts[v][0]).hypot(pts[u][1] - pts[v][1]);
            }
        }
        (d, m)
    }

    /// The transit cost of a route (tasks in order, direction of each), summed arc by arc.
    fn cost_of(d: &[Cost], m: usize, n: usize, home: bool, seq: &[u32], dir: &[bool]) -> Cost {
        let mut prev = if home { Some(2 * n) } else { None };
        let mut total = 0.0;
        for &t in seq {
            let entry = 2 * t as usize + usize::from(dir[t as usize]);
            if let Some(p) = prev {
                total += d[p * m + entry];
            }
            prev = Some(entry ^ 1);
        }
        total
    }

    /// The optimum by trying every order and every direction.
    fn brute_force(d: &[Cost], m: usize, n: usize, home: bool) -> Cost {
        fn go(d: &[Cost], m: usize, n: usize, at: Option<usize>, used: &mut Vec<bool>, depth: usize) -> Cost {
            if depth == n {
                return 0.0;
            }
            let mut best = Cost::INFINITY;
            for t in 0..n {
                if used[t] {
                    continue;
                }
                used[t] = true;
                for r in 0..2 {
                    let entry = 2 * t + r;
                    let arc = at.map_or(0.0, |a| d[a * m + entry]);
                    best = best.min(arc + go(d, m, n, Some(entry ^ 1), used, depth + 1));
                }
                used[t] = false;
            }
            best
        }
        go(d, m, n, if home { Some(2 * n) } else { None }, &mut vec![false; n], 0)
    }

    #[test]
    fn finds_and_proves_the_optimum_of_small_plans() {
        for seed in 0..60u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = 2 + (seed % 5) as usize;
            let segments: Vec<_> = (0..n)
                .map(|_| {
                    let a = [rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0)];
                    (a, [a[0] + rng.gen_range(-30.0..30.0), a[1] + rng.gen_range(-30.0..30.0)])
                })
                .collect();
            let home = (seed % 2 == 0).then_some([50.0, -20.0]);
            let (d, m) = matrix(&segments, home);
            let optimum = brute_force(&d, m, n, home.is_some());
            let trees = Trees::new(&d, m, n, home.is_some());
            // From no route at all: it finds the optimum and proves it.
            let proof = trees.prove(Cost::INFINITY, 1e-9, Cost::INFINITY, 1_000_000);
            assert!(proof.proven, "seed {seed}: not proven");
            let (seq, dir) = proof.better.expect("a route");
            let mut seen = seq.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>(), "seed {seed}: not every task once");
            let cost = cost_of(&d, m, n, home.is_some(), &seq, &dir);
            assert!((cost - optimum).abs() < 1e-9, "seed {seed}: {cost} vs optimum {optimum}");
            // Given the optimum: it proves it and finds nothing better.
            let proof = trees.prove(optimum, 1e-9, Cost::INFINITY, 1_000_000);
            assert!(proof.proven && proof.better.is_none(), "seed {seed}");
            // Given a worse route and a tiny budget: whatever it returns is a route no dearer.
            let proof = trees.prove(optimum * 1.5 + 1.0, 1e-9, Cost::INFINITY, 1);
            if let Some((seq, dir)) = proof.better {
                assert!(cost_of(&d, m, n, home.is_some(), &seq, &dir) <= optimum * 1.5 + 1.0);
            }
        }
    }

    #[test]
    fn a_zigzag_that_must_leave_by_the_far_end_is_proven_in_a_tree_per_pass() {
        // Six passes 50 apart, entered from home on the left; pass 3's left end is tucked up
        // towards pass 2 (49 apart there), but the zigzag reaches pass 3 on the right: the
        // spanning tree takes the short left arc, no route can.
        let mut segments: Vec<([f64; 2], [f64; 2])> =
            (0..6).map(|i| ([0.0, 50.0 * i as f64], [500.0, 50.0 * i as f64])).collect();
        segments[3].0 = [0.0, 149.0];
        let (d, m) = matrix(&segments, Some([-50.0, 0.0]));
        let n = segments.len();
        let optimum = brute_force(&d, m, n, true);
        let trees = Trees::new(&d, m, n, true);
        let root = Search {
            trees: &trees,
            best: Cost::INFINITY,
            tol: 0.0,
            max_gap: 0.0,
            limit: 1,
            proof: Proof::default(),
            excluded: Vec::new(),
            required: Vec::new(),
            aborted: false,
            req: vec![false; trees.k * trees.k],
        }
        .tree()
        .expect("a tree")
        .total;
        assert!(root < optimum - 1.0, "the tree ({root}) should be below the optimum ({optimum})");
        let zigzag = cost_of(&d, m, n, true, &[0, 1, 2, 3, 4, 5], &[false, true, false, true, false, true]);
        let proof = trees.prove(zigzag, 1e-9, 0.02, 2 * n);
        assert!(proof.proven, "not proven in {} trees (root {root}, zigzag {zigzag}, optimum {optimum})", proof.nodes);
        let best = proof.better.map_or(zigzag, |(seq, dir)| cost_of(&d, m, n, true, &seq, &dir));
        assert!((best - optimum).abs() < 1e-9, "{best} vs optimum {optimum}");
    }
}
