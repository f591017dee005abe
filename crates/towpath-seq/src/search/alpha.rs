//! α-nearness candidate lists (Helsgaun, "An effective implementation of the Lin–Kernighan
//! traveling salesman heuristic", EJOR 126, 2000, sections 4.1–4.2).
//!
//! A subgradient ascent (Held and Karp) looks for node penalties π that make the minimum
//! 1-tree under the costs c(i,j) + π(i) + π(j) as close to a tour as it can (every degree 2).
//! The α-value of an edge is then how much dearer the minimum 1-tree becomes when it is forced
//! to contain that edge: the edge's penalised cost less the dearest edge on the tree path
//! between its ends. Edges of optimal tours have small α far more reliably than they are short:
//! the few lowest-α edges per node make better candidates than the nearest neighbours.
//!
//! Used for symmetric one-mode closed tours (TSP). The ascent works on a sparse graph (the
//! nearest-neighbour lists, both ways, joined where they fall apart); the α-values are exact
//! for that tree, over all node pairs (an O(n²) pass, which on planar points prices only the
//! pairs close enough to enter a list).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::neighbors::{self, Neighbors};
use super::net::Net;
use super::pieces::Pieces;
use crate::cost::{Cost, CostModel, PlanarEuclid};

/// The sparse graph in compressed rows, with each edge's plain cost.
struct Graph {
    off: Vec<u32>,
    to: Vec<u32>,
    cost: Vec<Cost>,
}

impl Graph {
    /// True when the graph holds the edge a–b.
    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.to[self.off[a as usize] as usize..self.off[a as usize + 1] as usize].contains(&b)
    }

    /// The graph with the edges `extra` added (both ways), rebuilt in one pass.
    fn with_edges(&self, extra: &[(u32, u32)], arc: &impl Fn(u32, u32) -> Cost) -> Graph {
        let n = self.off.len() - 1;
        let mut edges: Vec<(u32, u32)> = (0..n as u32)
            .flat_map(|a| {
                self.to[self.off[a as usize] as usize..self.off[a as usize + 1] as usize].iter().map(move |&b| (a, b))
            })
            .collect();
        for &(a, b) in extra {
            edges.extend([(a, b), (b, a)]);
        }
        csr(n, edges, arc)
    }
}

/// A minimum spanning tree: each node's parent (the root's is itself), the order in which Prim
/// reached the nodes (parents before children) and the degrees.
struct Tree {
    parent: Vec<u32>,
    order: Vec<u32>,
    degree: Vec<u32>,
    /// Penalised cost of the tree plus the 1-tree's extra edge.
    cost: Cost,
}

#[derive(PartialEq)]
struct Item(Cost, u32, u32);

impl Eq for Item {}

impl Ord for Item {
    fn cmp(&self, other: &Self) -> Ordering {
        // a min-heap on the key, then the node
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Item {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Lowest-α neighbours per node.
const ALPHA_K: usize = 8;

/// Nearest neighbours kept beside them: α alone misses neighbours among clusters of coincident
/// points (fl1577); the measurements are in the history of this constant and BENCHMARKS.md.
const NEAREST_KEPT: usize = 5;

/// Largest ascent: Polyak steps usually stop improving the bound well before this.
const MAX_ASCENT: usize = 300;

/// Estimated time of one ascent step per node (a heap-based Prim over ~13 edges a node) and of
/// one α pair (a cost and a tree step), used to decide whether the lists fit the budget.
///
/// Since the pruned pass (see [`lowest_alpha`]) a pair costs about 9 ns, not 15, but the
/// estimate was kept on purpose: it sets where α lists stop and how many steps the ascent
/// gets, and both were measured best as they are. With 9 ns, gauss-5000 (60 clusters) would
/// get 110 steps instead of 89 and gauss-10000 (100 clusters) α lists instead of quadrant
/// lists; on three instances of each (10 s, two threads, 6-20 seeds) 110 steps gave the worse
/// median on all three and α lists at 10,000 points on two of three (BENCHMARKS.md,
/// fourteenth round).
const STEP_SECONDS_PER_NODE: f64 = 7e-7;
const PAIR_SECONDS: f64 = 1.5e-8;

/// Share of a time limit the lists may take.
const TIME_SHARE: f64 = 0.05;

/// Largest instance without a time limit (the α pass is O(n²)).
const MAX_NODES: usize = 8000;

/// How many ascent steps to take on `n` nodes with `threads` threads within `seconds`, or
/// `None` when the lists would cost too much of the limit (or of the work, without one).
pub(crate) fn plan(n: usize, threads: usize, seconds: Option<f64>) -> Option<usize> {
    let Some(s) = seconds else {
        return (n <= MAX_NODES).then_some(MAX_ASCENT);
    };
    let budget = s * TIME_SHARE;
    let pairs = (n as f64).powi(2) * PAIR_SECONDS / threads.max(1) as f64;
    if pairs > budget {
        return None;
    }
    Some(MAX_ASCENT.min(((budget - pairs) / (n as f64 * STEP_SECONDS_PER_NODE)) as usize))
}

/// Candidate lists of the [`ALPHA_K`] lowest-α neighbours of each node and its
/// [`NEAREST_KEPT`] nearest in `nb`, sorted by cost as the local search expects; the ascent
/// takes at most `steps` steps over the graph of `nb`, and `ub` is the cost of a tour (for the
/// step length). `None` unless the instance is a closed tour with one mode per task and
/// symmetric costs.
pub(crate) fn candidates<C: CostModel>(
    net: &Net<C>,
    nb: &Neighbors,
    steps: usize,
    ub: Cost,
    threads: usize,
) -> Option<Neighbors> {
    let n = net.n;
    if !net.plain_symmetric || net.multi_mode || net.depot != u32::MAX || net.has_prec || net.has_groups {
        return None;
    }
    if n <= ALPHA_K + 1 || !ub.is_finite() {
        return None;
    }
    let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
    let mut g = sparse_graph(net, nb, &arc);
    let pi = ascent(&mut g, vec![0.0; n], steps, ub, &arc);
    let tree = prim(&mut g, &pi, &arc);
    let mut lists = lowest_alpha(net, nb, &tree, &pi, ALPHA_K, threads, &arc);
    // add the nearest, then order by cost (the one sort the lists get)
    for (v, list) in lists.iter_mut().enumerate() {
        let v = v as u32;
        for &u in nb.out(v).iter().take(NEAREST_KEPT) {
            if !list.contains(&u) {
                list.push(u);
            }
        }
        list.sort_by(|&x, &y| arc(v, x).total_cmp(&arc(v, y)).then(x.cmp(&y)));
    }
    Some(Neighbors::from_lists(net, lists))
}

/// Largest tour [`held_karp_bound`] takes: its last 1-tree is over the complete graph (n² arc
/// evaluations per round: about 13 s in all at 20,000 nodes on one core).
pub(crate) const BOUND_MAX_NODES: usize = 50_000;

/// Most ascents of [`held_karp_bound`] (each followed by a complete-graph 1-tree).
const BOUND_ROUNDS: usize = 4;

/// A lower bound on the cost of every tour of a symmetric one-mode closed tour (a TSP, or the
/// ends of two-way tasks with their fixed edges): the Held–Karp 1-tree bound
/// w(π) = (minimum 1-tree under c(i,j) + π(i) + π(j)) − 2 Σ π, which holds for every π
/// (Held and Karp 1970). π comes from the ascent on the sparse graph of `nb`; the last 1-tree
/// is then taken over the **complete** graph, so the bound does not rest on the candidate lists
/// holding the minimum tree. Where that tree uses edges the sparse graph lacks, they are added
/// and the ascent goes on from the same π (at most [`BOUND_ROUNDS`] times, while a round
/// raises the bound); the best w(π) seen is the bound. Adds the nodes' own costs. `ub` is a
/// tour's cost (the ascent's step length). `None` when the problem is not of that form or has
/// more than [`BOUND_MAX_NODES`] nodes.
pub(crate) fn held_karp_bound<C: CostModel>(net: &Net<C>, nb: &Neighbors, ub: Cost) -> Option<Cost> {
    let n = net.n;
    if !net.plain_symmetric || net.multi_mode || net.has_prec || net.has_groups {
        return None;
    }
    if !(3..=BOUND_MAX_NODES).contains(&n) || !ub.is_finite() {
        return None;
    }
    let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
    let own: Cost = (0..n as u32).map(|v| net.mode_cost(v, 0)).sum();
    let mut g = sparse_graph(net, nb, &arc);
    let mut pi = vec![0.0; n];
    let mut best = Cost::NEG_INFINITY;
    for round in 0..BOUND_ROUNDS {
        // later rounds go on from the last π: a third of the steps
        let steps = if round == 0 { MAX_ASCENT } else { MAX_ASCENT / 3 };
        pi = ascent(&mut g, pi, steps, ub, &arc);
        let (w, edges) = complete_one_tree(&pi, &arc);
        let gained = w > best + 1e-9 * w.abs().max(1.0);
        best = best.max(w);
        let missing: Vec<(u32, u32)> = edges.into_iter().filter(|&(a, b)| !g.has_edge(a, b)).collect();
        if missing.is_empty() || (round > 0 && !gained) {
            break;
        }
        g = g.with_edges(&missing, &arc);
    }
    Some(best + own)
}

/// w(π) of the minimum 1-tree of the complete graph: a minimum spanning tree (Prim, O(n²))
/// plus the second-cheapest edge of the leaf where that edge is dearest, less 2 Σ π. For a
/// leaf v the tree less v spans the other nodes at least cost (v's tree edge is its cheapest),
/// so this is the 1-tree with v as the special node. Every edge is priced once, by the end
/// Prim reaches first, and counts towards both ends' two cheapest.
fn complete_one_tree(pi: &[Cost], arc: &impl Fn(u32, u32) -> Cost) -> (Cost, Vec<(u32, u32)>) {
    let n = pi.len();
    let mut key = vec![Cost::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut reached = vec![false; n];
    let mut degree = vec![0u32; n];
    // the two cheapest penalised edges at each node, with their other ends
    let mut two = vec![[(Cost::INFINITY, u32::MAX); 2]; n];
    let push = |t: &mut [(Cost, u32); 2], c: Cost, to: usize| {
        if c < t[0].0 {
            *t = [(c, to as u32), t[0]];
        } else if c < t[1].0 {
            t[1] = (c, to as u32);
        }
    };
    let mut total = 0.0;
    let mut u = 0usize;
    for _ in 0..n {
        reached[u] = true;
        if parent[u] != u32::MAX {
            total += key[u];
            degree[u] += 1;
            degree[parent[u] as usize] += 1;
        }
        let (mut next, mut next_key) = (usize::MAX, Cost::INFINITY);
        for w in 0..n {
            if reached[w] {
                continue;
            }
            let c = arc(u as u32, w as u32) + pi[u] + pi[w];
            push(&mut two[u], c, w);
            push(&mut two[w], c, u);
            if c < key[w] {
                key[w] = c;
                parent[w] = u as u32;
            }
            if key[w] < next_key || next == usize::MAX {
                next_key = key[w];
                next = w;
            }
        }
        if next == usize::MAX {
            break;
        }
        u = next;
    }
    let extra = (0..n)
        .filter(|&v| degree[v] == 1)
        .map(|v| (two[v][1].0, v as u32, two[v][1].1))
        .fold((Cost::NEG_INFINITY, 0, 0), |x, y| if y.0 > x.0 { y } else { x });
    let mut edges: Vec<(u32, u32)> =
        (0..n as u32).filter(|&v| parent[v as usize] != u32::MAX).map(|v| (v, parent[v as usize])).collect();
    edges.push((extra.1, extra.2));
    (total + extra.0 - 2.0 * pi.iter().sum::<Cost>(), edges)
}

/// The nearest-neighbour lists as an undirected graph, joined where it falls apart (clusters
/// further apart than their points' nearest neighbours): on tasks in a plane, by the cheapest
/// links between the pieces among each node's [`LINK_PER_QUADRANT`] nearest in each quadrant
/// around it, taken cheapest first while they join two pieces (Kruskal). Where pieces are left,
/// [`prim`] joins them by a full scan, which costs O(n²) a time (seconds on 10,000 clustered
/// points).
fn sparse_graph<C: CostModel>(net: &Net<C>, nb: &Neighbors, arc: &impl Fn(u32, u32) -> Cost) -> Graph {
    let n = net.n;
    let mut edges: Vec<(u32, u32)> =
        (0..n as u32).flat_map(|v| nb.out(v).iter().flat_map(move |&u| [(v, u), (u, v)])).collect();
    let mut pieces = Pieces::new(n);
    let apart = edges.iter().filter(|&&(a, b)| pieces.join(a, b)).count() + 1 < n;
    if apart {
        if let Some(q) = neighbors::quadrant_lists(net, 1, LINK_PER_QUADRANT) {
            let mut links: Vec<(Cost, u32, u32)> =
                (0..n as u32).flat_map(|v| q.out(v).iter().map(move |&u| (arc(v, u), v, u))).collect();
            links.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
            for (_, a, b) in links {
                if pieces.join(a, b) {
                    edges.extend([(a, b), (b, a)]);
                }
            }
        }
    }
    csr(n, edges, arc)
}

/// Neighbours per quadrant among which the links between pieces are sought.
const LINK_PER_QUADRANT: usize = 2;

/// The graph of directed `edges` (each edge given both ways) in compressed rows.
fn csr(n: usize, mut edges: Vec<(u32, u32)>, arc: &impl Fn(u32, u32) -> Cost) -> Graph {
    edges.sort_unstable();
    edges.dedup();
    let mut off = vec![0u32; n + 1];
    for &(a, _) in &edges {
        off[a as usize + 1] += 1;
    }
    for i in 0..n {
        off[i + 1] += off[i];
    }
    let to: Vec<u32> = edges.iter().map(|&(_, b)| b).collect();
    let cost = edges.iter().map(|&(a, b)| arc(a, b)).collect();
    Graph { off, to, cost }
}

/// Minimum spanning tree of the sparse graph under the penalised costs (Prim from node 0). If
/// the graph falls apart, the cheapest edge from the tree to the rest is found by a full scan
/// and added to the graph for good.
fn prim(g: &mut Graph, pi: &[Cost], arc: &impl Fn(u32, u32) -> Cost) -> Tree {
    let n = pi.len();
    let mut parent = vec![u32::MAX; n];
    let mut key = vec![Cost::INFINITY; n];
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut degree = vec![0u32; n];
    let mut heap = BinaryHeap::new();
    let mut cost = 0.0;
    parent[0] = 0;
    key[0] = 0.0;
    heap.push(Item(0.0, 0, 0));
    while order.len() < n {
        let Some(Item(c, v, p)) = heap.pop() else {
            // disconnected: join the cheapest outside node by a full scan
            let (c, v, p) = cheapest_link(&done, pi, arc);
            add_edge(g, p, v, arc(p, v));
            heap.push(Item(c, v, p));
            continue;
        };
        if done[v as usize] {
            continue;
        }
        done[v as usize] = true;
        order.push(v);
        if v != p {
            parent[v as usize] = p;
            degree[v as usize] += 1;
            degree[p as usize] += 1;
            cost += c;
        }
        let (a, b) = (g.off[v as usize] as usize, g.off[v as usize + 1] as usize);
        for e in a..b {
            let u = g.to[e];
            if done[u as usize] {
                continue;
            }
            let cu = g.cost[e] + pi[v as usize] + pi[u as usize];
            if cu < key[u as usize] {
                key[u as usize] = cu;
                heap.push(Item(cu, u, v));
            }
        }
    }
    // the 1-tree's extra edge: from the leaf whose cheapest non-tree edge is dearest
    let mut extra: Option<(Cost, u32, u32)> = None;
    for v in 0..n as u32 {
        if degree[v as usize] != 1 {
            continue;
        }
        let (a, b) = (g.off[v as usize] as usize, g.off[v as usize + 1] as usize);
        let mut second: Option<(Cost, u32)> = None;
        for e in a..b {
            let u = g.to[e];
            if parent[v as usize] == u || parent[u as usize] == v {
                continue;
            }
            let cu = g.cost[e] + pi[v as usize] + pi[u as usize];
            if second.is_none_or(|s| cu < s.0) {
                second = Some((cu, u));
            }
        }
        if let Some((c, u)) = second {
            if extra.is_none_or(|x| c > x.0) {
                extra = Some((c, v, u));
            }
        }
    }
    if let Some((c, v, u)) = extra {
        degree[v as usize] += 1;
        degree[u as usize] += 1;
        cost += c;
    }
    Tree { parent, order, degree, cost }
}

/// The cheapest edge from a reached node to an unreached one, as (penalised cost, outside
/// node, tree node).
fn cheapest_link(done: &[bool], pi: &[Cost], arc: &impl Fn(u32, u32) -> Cost) -> (Cost, u32, u32) {
    let mut best = (Cost::INFINITY, u32::MAX, u32::MAX);
    for (v, _) in done.iter().enumerate().filter(|(_, &d)| !d) {
        for (p, _) in done.iter().enumerate().filter(|(_, &d)| d) {
            let c = arc(p as u32, v as u32) + pi[v] + pi[p];
            if c < best.0 {
                best = (c, v as u32, p as u32);
            }
        }
    }
    best
}

fn add_edge(g: &mut Graph, a: u32, b: u32, c: Cost) {
    for (x, y) in [(a, b), (b, a)] {
        let at = g.off[x as usize + 1] as usize;
        g.to.insert(at, y);
        g.cost.insert(at, c);
        for o in &mut g.off[x as usize + 1..] {
            *o += 1;
        }
    }
}

/// Steps without a better bound before the step factor halves.
const PATIENCE: usize = 10;

/// Subgradient ascent on the 1-tree bound (Held and Karp): π moves along the degree excess
/// (0.7 of this step's and 0.3 of the last, as in Helsgaun's implementation) by Polyak's step
/// λ (ub − w) / |d|²; after `PATIENCE` steps without a better bound λ halves and the search
/// goes back to the best π. Returns the best π found in at most `steps` steps.
fn ascent(g: &mut Graph, start: Vec<Cost>, steps: usize, ub: Cost, arc: &impl Fn(u32, u32) -> Cost) -> Vec<Cost> {
    let n = start.len();
    let mut pi = start;
    let tree = prim(g, &pi, arc);
    let excess = |t: &Tree| t.degree.iter().map(|&d| d as f64 - 2.0).collect::<Vec<f64>>();
    let mut w = tree.cost;
    let mut v = excess(&tree);
    let mut last_v = v.clone();
    let (mut best_w, mut best_pi, mut best_v) = (w, pi.clone(), v.clone());
    let mut lambda = 1.0;
    let mut since = 0;
    let mut d = vec![0.0; n];
    for _ in 0..steps {
        for i in 0..n {
            d[i] = 0.7 * v[i] + 0.3 * last_v[i];
        }
        let norm: f64 = d.iter().map(|x| x * x).sum();
        if norm == 0.0 || lambda < 1e-6 {
            break; // a tour (the bound is optimal), or the steps no longer move
        }
        let t = lambda * (ub - w).max(0.0) / norm;
        for i in 0..n {
            pi[i] += t * d[i];
        }
        last_v.copy_from_slice(&v);
        let tree = prim(g, &pi, arc);
        w = tree.cost - 2.0 * pi.iter().sum::<f64>();
        v = excess(&tree);
        if w > best_w + 1e-12 * best_w.abs() {
            best_w = w;
            best_pi.copy_from_slice(&pi);
            best_v.copy_from_slice(&v);
            since = 0;
        } else {
            since += 1;
            if since >= PATIENCE {
                lambda *= 0.5;
                since = 0;
                pi.copy_from_slice(&best_pi);
                v.copy_from_slice(&best_v);
                last_v.copy_from_slice(&best_v);
                w = best_w;
            }
        }
    }
    best_pi
}

/// The `k` lowest-α neighbours of every node, lowest α first, computed on `threads` threads
/// (the answer does not depend on how many). Planar points are copied into the tree walk's
/// order, so that the pass reads them front to back, and most pairs are ruled out by their
/// squared distance alone (see [`PlacedCost`]).
fn lowest_alpha<C: CostModel>(
    net: &Net<C>,
    nb: &Neighbors,
    tree: &Tree,
    pi: &[Cost],
    k: usize,
    threads: usize,
    arc: &(impl Fn(u32, u32) -> Cost + Sync),
) -> Vec<Vec<u32>> {
    let walk = TreeWalk::new(tree, pi, arc);
    let walk = &walk;
    // the places of a node's nearest neighbours and of its parent in the tree
    let near = |at: u32| {
        let v = walk.node[at as usize];
        let mut near: Vec<u32> = nb.out(v).iter().map(|&u| walk.place[u as usize]).collect();
        near.push(walk.parent[at as usize]);
        // each place once: a place counted twice would make the bound too low
        near.sort_unstable();
        near.dedup();
        near
    };
    match net.planar() {
        Some(pl) => {
            let placed = PlacedPoints {
                points: PlanarEuclid {
                    xy: walk.node.iter().map(|&v| pl.xy[v as usize]).collect(),
                    rounding: pl.rounding,
                },
                forbidden: net.forbidden,
            };
            split_rows(walk, k, threads, &near, &placed)
        }
        None => split_rows(walk, k, threads, &near, &PlacedArcs { walk, arc }),
    }
}

/// Costs between places of the tree walk, for the α pass.
trait PlacedCost: Sync {
    /// The cost between the nodes at places `a` and `b`.
    fn cost(&self, a: u32, b: u32) -> Cost;

    /// True only if the cost between places `a` and `b` is surely above `room`; false when it
    /// cannot tell cheaply.
    fn surely_above(&self, a: u32, b: u32, room: Cost) -> bool;
}

/// Any costs, through the net's arcs.
struct PlacedArcs<'a, F> {
    walk: &'a TreeWalk,
    arc: &'a F,
}

impl<F: Fn(u32, u32) -> Cost + Sync> PlacedCost for PlacedArcs<'_, F> {
    #[inline(always)]
    fn cost(&self, a: u32, b: u32) -> Cost {
        (self.arc)(self.walk.node[a as usize], self.walk.node[b as usize])
    }

    #[inline(always)]
    fn surely_above(&self, _: u32, _: u32, _: Cost) -> bool {
        false
    }
}

/// Rounded distances in a plane, the points in the walk's order.
struct PlacedPoints {
    points: PlanarEuclid,
    /// The net's price of a forbidden arc, which caps every arc.
    forbidden: Cost,
}

impl PlacedCost for PlacedPoints {
    #[inline(always)]
    fn cost(&self, a: u32, b: u32) -> Cost {
        self.points.cost(a as usize, b as usize).min(self.forbidden)
    }

    /// Every rounding gives at least the distance less ½, so a squared distance above
    /// (room + 1)² (with a margin for the sums' rounding) settles it without a square root.
    #[inline(always)]
    fn surely_above(&self, a: u32, b: u32, room: Cost) -> bool {
        if room >= self.forbidden {
            return false;
        }
        let (p, q) = (self.points.xy[a as usize], self.points.xy[b as usize]);
        let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
        let reach = room + 1.0 + 1e-9 * room.abs();
        reach < 0.0 || dx * dx + dy * dy > reach * reach
    }
}

/// [`alpha_rows`] of every node, the rows split between `threads` threads.
fn split_rows(
    walk: &TreeWalk,
    k: usize,
    threads: usize,
    near: &(impl Fn(u32) -> Vec<u32> + Sync),
    cost: &impl PlacedCost,
) -> Vec<Vec<u32>> {
    let n = walk.node.len();
    let threads = threads.clamp(1, 64).min(n);
    if threads == 1 {
        return alpha_rows(0..n as u32, walk, k, near, cost);
    }
    let chunk = n.div_ceil(threads) as u32;
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads as u32)
            .map(|t| {
                let rows = (t * chunk).min(n as u32)..((t + 1) * chunk).min(n as u32);
                s.spawn(move || alpha_rows(rows, walk, k, near, cost))
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("α thread panicked")).collect()
    })
}

/// The minimum spanning tree laid out by Prim's order (parents before children) for the α
/// pass, which walks the whole tree once per node: each place's node, its parent's place, the
/// penalised cost of the edge to the parent and the node's π, in arrays read front to back.
struct TreeWalk {
    node: Vec<u32>,
    place: Vec<u32>,
    parent: Vec<u32>,
    up: Vec<Cost>,
    pi: Vec<Cost>,
}

impl TreeWalk {
    fn new(tree: &Tree, pi: &[Cost], arc: &impl Fn(u32, u32) -> Cost) -> TreeWalk {
        let node = tree.order.clone();
        let mut place = vec![0u32; node.len()];
        for (q, &v) in node.iter().enumerate() {
            place[v as usize] = q as u32;
        }
        let parent: Vec<u32> = node.iter().map(|&v| place[tree.parent[v as usize] as usize]).collect();
        let up = node
            .iter()
            .map(|&v| {
                let d = tree.parent[v as usize];
                if d == v {
                    Cost::NEG_INFINITY
                } else {
                    arc(v, d) + pi[v as usize] + pi[d as usize]
                }
            })
            .collect();
        let pi = node.iter().map(|&v| pi[v as usize]).collect();
        TreeWalk { node, place, parent, up, pi }
    }
}

/// Candidate lists of the nodes in `rows`; `cost` prices two places of the walk and `near`
/// gives a few places near each node's. β(i,j), the dearest tree edge on the path from i to j,
/// comes for every j in one pass over the tree in Prim's order (parents first) after marking
/// i's path to the root. The k-th lowest α among the near places bounds the list from the
/// start, so that the scan of all pairs prices only the few that can enter it.
fn alpha_rows(
    rows: std::ops::Range<u32>,
    walk: &TreeWalk,
    k: usize,
    near: &(impl Fn(u32) -> Vec<u32> + Sync),
    cost: &impl PlacedCost,
) -> Vec<Vec<u32>> {
    let n = walk.node.len();
    let k = k.min(n - 1);
    let mut beta = vec![Cost::NEG_INFINITY; n];
    let mut mark = vec![u32::MAX; n];
    let mut lists = Vec::with_capacity(rows.len());
    let mut best: Vec<(Cost, Cost, u32)> = Vec::with_capacity(k + 1);
    let mut seed: Vec<Cost> = Vec::new();
    for i in rows {
        let at = walk.place[i as usize];
        let mut q = at as usize;
        let pi_i = walk.pi[q];
        beta[q] = Cost::NEG_INFINITY;
        mark[q] = i;
        while q != 0 {
            let d = walk.parent[q] as usize;
            beta[d] = beta[q].max(walk.up[q]);
            mark[d] = i;
            q = d;
        }
        for q in 1..n {
            if mark[q] != i {
                let (b, u) = (beta[walk.parent[q] as usize], walk.up[q]);
                beta[q] = if u > b { u } else { b };
            }
        }
        let alpha = |q: usize, c: Cost| c + pi_i + walk.pi[q] - beta[q];
        // the k-th lowest α so far, first among the near places: a pair above it cannot enter
        seed.clear();
        seed.extend(near(at).into_iter().filter(|&q| q != at).map(|q| alpha(q as usize, cost.cost(at, q))));
        let mut worst =
            if seed.len() >= k { *seed.select_nth_unstable_by(k - 1, |x, y| x.total_cmp(y)).1 } else { Cost::INFINITY };
        best.clear();
        for q in 0..n {
            if q == at as usize {
                continue;
            }
            // the dearest cost with which the pair could still enter
            let room = worst - pi_i - walk.pi[q] + beta[q];
            if cost.surely_above(at, q as u32, room) {
                continue;
            }
            let c = cost.cost(at, q as u32);
            let a = alpha(q, c);
            if a > worst {
                continue;
            }
            let j = walk.node[q];
            if best.len() == k && !better((a, c, j), best[k - 1]) {
                continue;
            }
            let slot = best.iter().position(|&b| better((a, c, j), b)).unwrap_or(best.len());
            best.insert(slot, (a, c, j));
            best.truncate(k);
            if best.len() == k {
                worst = worst.min(best[k - 1].0);
            }
        }
        lists.push(best.iter().map(|b| b.2).collect());
    }
    lists
}

/// Lower α first, then lower cost, then lower id.
fn better(x: (Cost, Cost, u32), y: (Cost, Cost, u32)) -> bool {
    x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)) == Ordering::Less
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::PointCost;
    use crate::exact::solve_exact;
    use crate::model::Problem;

    fn random_tour_problem(n: usize, seed: u64) -> Problem<PointCost> {
        super::super::testing::random_tour_problem(&mut Pcg64Mcg::seed_from_u64(seed), n, 100.0)
    }

    /// Cost of a minimum spanning tree of the complete graph under the penalised costs that
    /// must contain the edge (i, j) (Kruskal from that edge), or without a forced edge.
    fn forced_mst(n: usize, c: &dyn Fn(u32, u32) -> Cost, forced: Option<(u32, u32)>) -> Cost {
        let mut edges: Vec<(Cost, u32, u32)> = Vec::new();
        for a in 0..n as u32 {
            for b in a + 1..n as u32 {
                edges.push((c(a, b), a, b));
            }
        }
        edges.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut root: Vec<usize> = (0..n).collect();
        fn find(r: &mut [usize], x: usize) -> usize {
            let mut x = x;
            while r[x] != x {
                r[x] = r[r[x]];
                x = r[x];
            }
            x
        }
        let mut total = 0.0;
        if let Some((i, j)) = forced {
            total += c(i, j);
            root[i as usize] = j as usize;
        }
        for (w, a, b) in edges {
            let (ra, rb) = (find(&mut root, a as usize), find(&mut root, b as usize));
            if ra != rb {
                root[ra] = rb;
                total += w;
            }
        }
        total
    }

    /// The plan gives α lists only when the estimated pass fits its share of the limit, with
    /// as many ascent steps as fit the rest, up to [`MAX_ASCENT`]; without a limit, up to
    /// [`MAX_NODES`] nodes.
    #[test]
    fn the_plan_fits_the_pass_in_its_share() {
        for n in (500..=30_000).step_by(500) {
            for threads in 1..=4 {
                for seconds in [1.0, 3.0, 10.0, 30.0, 60.0] {
                    let pass = (n as f64).powi(2) * PAIR_SECONDS / threads as f64;
                    let budget = seconds * TIME_SHARE;
                    let at = format!("{n} nodes, {threads} threads, {seconds} s");
                    match plan(n, threads, Some(seconds)) {
                        None => assert!(pass > budget, "{at}"),
                        Some(steps) => {
                            assert!(pass <= budget, "{at}");
                            let rest = (budget - pass) / (n as f64 * STEP_SECONDS_PER_NODE);
                            assert!(steps <= MAX_ASCENT, "{at}");
                            assert!(steps as f64 <= rest && (steps == MAX_ASCENT || rest < steps as f64 + 1.0), "{at}");
                        }
                    }
                }
            }
        }
        // the sizes the benchmarks rely on (two threads, 10 s): 2,000 points take the whole
        // ascent, 5,000 a shorter one, 10,000 quadrant lists
        assert_eq!(plan(2_000, 2, Some(10.0)), Some(MAX_ASCENT));
        assert_eq!(plan(5_000, 2, Some(10.0)), Some(89));
        assert_eq!(plan(10_000, 2, Some(10.0)), None);
        assert_eq!(plan(MAX_NODES, 1, None), Some(MAX_ASCENT));
        assert_eq!(plan(MAX_NODES + 1, 8, None), None);
    }

    /// The ascent's bound never exceeds the optimal tour (it is a Held–Karp lower bound), and
    /// the α-values behind the lists are what forcing each edge into the minimum spanning tree
    /// costs, checked against Kruskal with that edge forced on a complete graph.
    #[test]
    fn bound_is_below_the_optimum_and_alpha_matches_forced_trees() {
        for seed in 0..20u64 {
            let n = 9 + (seed % 4) as usize;
            let p = random_tour_problem(n, seed);
            let net = Net::new(&p);
            let nb = Neighbors::build(&net, n - 1);
            let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
            let opt = solve_exact(&p).unwrap().unwrap().cost;
            let mut g = sparse_graph(&net, &nb, &arc);
            let pi = ascent(&mut g, vec![0.0; n], 200, opt * 1.2, &arc);
            let tree = prim(&mut g, &pi, &arc);
            let bound = tree.cost - 2.0 * pi.iter().sum::<f64>();
            assert!(bound <= opt + 1e-6 * opt, "seed {seed}: bound {bound} above the optimum {opt}");
            assert!(bound >= 0.8 * opt, "seed {seed}: bound {bound} far below the optimum {opt}");

            let pc = |a: u32, b: u32| arc(a, b) + pi[a as usize] + pi[b as usize];
            let mst = forced_mst(n, &pc, None);
            let k = 4;
            let lists = lowest_alpha(&net, &nb, &tree, &pi, k, 2, &arc);
            for i in 0..n as u32 {
                let mut want: Vec<(Cost, Cost, u32)> = (0..n as u32)
                    .filter(|&j| j != i)
                    .map(|j| (forced_mst(n, &pc, Some((i, j))) - mst, arc(i, j), j))
                    .collect();
                want.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
                // the k-th and (k+1)-th α may tie within rounding: compare α-values, not ids
                let got: Vec<Cost> = {
                    let mut a: Vec<Cost> =
                        lists[i as usize].iter().map(|&j| forced_mst(n, &pc, Some((i, j))) - mst).collect();
                    a.sort_by(f64::total_cmp);
                    a
                };
                for (g, w) in got.iter().zip(&want) {
                    assert!((g - w.0).abs() <= 1e-6 * opt, "seed {seed} node {i}: α {got:?} want {want:?}");
                }
                assert_eq!(got.len(), k);
            }
        }
    }

    /// The complete-graph 1-tree is a 1-tree: it equals, for some special node v, a minimum
    /// spanning tree of the other nodes (Kruskal) plus v's two cheapest edges, less 2 Σ π, and
    /// stays below the optimal tour for any π, also when π comes from an ascent over lists too
    /// short to hold the minimum tree (three neighbours on clustered points).
    #[test]
    fn complete_one_tree_is_a_one_tree_and_below_the_optimum() {
        for seed in 0..12u64 {
            let n = 8 + (seed % 4) as usize;
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let pts: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    let c = if i % 2 == 0 { 0.0 } else { 500.0 };
                    [c + rng.gen_range(0.0..20.0), c + rng.gen_range(0.0..20.0), 0.0]
                })
                .collect();
            let p = crate::search::testing::points_problem(pts);
            let net = Net::new(&p);
            let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
            let opt = solve_exact(&p).unwrap().unwrap().cost;
            let random_pi: Vec<Cost> = (0..n).map(|_| rng.gen_range(-30.0..30.0)).collect();
            let nb = Neighbors::build(&net, 3);
            let mut g = sparse_graph(&net, &nb, &arc);
            let ascended = ascent(&mut g, vec![0.0; n], 100, opt * 1.1, &arc);
            for pi in [vec![0.0; n], random_pi, ascended] {
                let (got, _) = complete_one_tree(&pi, &arc);
                let pc = |a: u32, b: u32| arc(a, b) + pi[a as usize] + pi[b as usize];
                let sum2 = 2.0 * pi.iter().sum::<Cost>();
                let one_trees: Vec<Cost> = (0..n as u32)
                    .map(|v| {
                        let others: Vec<u32> = (0..n as u32).filter(|&u| u != v).collect();
                        let rest = forced_mst(n - 1, &|a, b| pc(others[a as usize], others[b as usize]), None);
                        let mut at_v: Vec<Cost> = others.iter().map(|&u| pc(v, u)).collect();
                        at_v.sort_by(f64::total_cmp);
                        rest + at_v[0] + at_v[1] - sum2
                    })
                    .collect();
                assert!(
                    one_trees.iter().any(|&t| (t - got).abs() <= 1e-9 * opt),
                    "seed {seed}: {got} is no 1-tree: {one_trees:?}"
                );
                assert!(got <= opt + 1e-9 * opt, "seed {seed}: bound {got} above the optimum {opt}");
            }
            let bound = held_karp_bound(&net, &nb, opt * 1.1).expect("a plain tour");
            assert!(bound <= opt + 1e-9 * opt, "seed {seed}: bound {bound} above the optimum {opt}");
            assert!(bound >= 0.9 * opt, "seed {seed}: bound {bound} far below the optimum {opt}");
        }
    }

    /// On uniform random points the bound after the ascent is within a few per cent of the
    /// optimum (Held–Karp's gap is about 0.7 % on large random instances; small ones have more).
    #[test]
    fn held_karp_bound_is_close_below_the_optimum() {
        let mut ratios = Vec::new();
        for seed in 0..10u64 {
            let n = 10 + (seed % 3) as usize;
            let p = random_tour_problem(n, seed);
            let net = Net::new(&p);
            let nb = Neighbors::build(&net, 8);
            let opt = solve_exact(&p).unwrap().unwrap().cost;
            let bound = held_karp_bound(&net, &nb, opt).expect("a plain tour");
            assert!(bound <= opt + 1e-9 * opt, "seed {seed}: bound {bound} above the optimum {opt}");
            ratios.push(bound / opt);
        }
        ratios.sort_by(f64::total_cmp);
        assert!(ratios[ratios.len() / 2] >= 0.97, "median bound/optimum {:?}", ratios);
    }

    #[test]
    fn the_pruned_planar_pass_gives_the_lists_of_the_full_one() {
        // clustered points, more than the arc table holds (so the arcs are planar distances),
        // under each rounding: the pass that prices pairs from the walk's copy of the points,
        // skips them by squared distance and starts from a bound must give the same lists as
        // pricing every pair through the net's arcs with no bound
        use crate::cost::Metric;
        for (seed, metric) in [(1, Metric::Euclidean), (2, Metric::EuclideanNint), (3, Metric::EuclideanCeil)] {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let mut pts = Vec::new();
            for _ in 0..24 {
                let (cx, cy) = (rng.gen_range(0.0..5_000.0), rng.gen_range(0.0..5_000.0));
                for _ in 0..50 {
                    pts.push([cx + rng.gen_range(-60.0..60.0), cy + rng.gen_range(-60.0..60.0), 0.0]);
                }
            }
            let n = pts.len();
            let mut b = Problem::builder(PointCost::new(pts, metric));
            for v in 0..n as u32 {
                b.task(vec![crate::model::Mode::point(crate::cost::StateId(v))]);
            }
            let p = b.build().expect("a point per task");
            let net = Net::new(&p);
            assert!(net.planar().is_some(), "{metric:?}: no planar arcs at {n} points");
            let nb = Neighbors::build(&net, 10);
            let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
            let mut g = sparse_graph(&net, &nb, &arc);
            let tour: Cost = (0..n as u32).map(|v| arc(v, (v + 1) % n as u32)).sum();
            let pi = ascent(&mut g, vec![0.0; n], 30, tour, &arc);
            let tree = prim(&mut g, &pi, &arc);
            let fast = lowest_alpha(&net, &nb, &tree, &pi, ALPHA_K, 2, &arc);
            let walk = TreeWalk::new(&tree, &pi, &arc);
            let full = split_rows(&walk, ALPHA_K, 1, &|_| Vec::new(), &PlacedArcs { walk: &walk, arc: &arc });
            assert_eq!(fast.len(), n);
            for v in 0..n {
                assert_eq!(fast[v], full[v], "{metric:?}: node {v}");
            }
        }
    }

    /// On clustered points the nearest lists fall apart into the clusters; the ascent's graph
    /// is joined by quadrant neighbours into one piece, holds every nearest-list edge, and the
    /// candidate lists built over it still hold the nearest neighbours. `Pieces` counts as a
    /// breadth-first search does, and the links added are one fewer than the pieces.
    #[test]
    fn the_ascent_graph_of_clusters_is_one_piece() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let mut pts = Vec::new();
        for _ in 0..30 {
            let (cx, cy) = (rng.gen_range(0.0..10_000.0), rng.gen_range(0.0..10_000.0));
            for _ in 0..20 {
                pts.push([cx + rng.gen_range(-10.0..10.0), cy + rng.gen_range(-10.0..10.0), 0.0]);
            }
        }
        let p = crate::search::testing::points_problem(pts);
        let net = Net::new(&p);
        let n = net.n;
        let nb = Neighbors::build(&net, 5);
        let arc = |a: u32, b: u32| net.arc(a, 0, b, 0);
        let nearest: Vec<(u32, u32)> =
            (0..n as u32).flat_map(|v| nb.out(v).iter().flat_map(move |&u| [(v, u), (u, v)])).collect();
        let bfs_pieces = |edges: &[(u32, u32)]| {
            let mut adj = vec![Vec::new(); n];
            for &(a, b) in edges {
                adj[a as usize].push(b);
            }
            let mut seen = vec![false; n];
            let mut count = 0;
            for s in 0..n {
                if seen[s] {
                    continue;
                }
                count += 1;
                seen[s] = true;
                let mut stack = vec![s as u32];
                while let Some(v) = stack.pop() {
                    for &u in &adj[v as usize] {
                        if !seen[u as usize] {
                            seen[u as usize] = true;
                            stack.push(u);
                        }
                    }
                }
            }
            count
        };
        let mut p = Pieces::new(n);
        let apart = n - nearest.iter().filter(|&&(a, b)| p.join(a, b)).count();
        assert_eq!(apart, bfs_pieces(&nearest));
        assert!(apart >= 20, "the nearest lists should fall apart into the clusters: {apart} pieces");
        let g = sparse_graph(&net, &nb, &arc);
        let joined: Vec<(u32, u32)> = (0..n as u32)
            .flat_map(|v| g.to[g.off[v as usize] as usize..g.off[v as usize + 1] as usize].iter().map(move |&u| (v, u)))
            .collect();
        assert_eq!(bfs_pieces(&joined), 1);
        let mut unique = nearest.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(joined.len(), unique.len() + 2 * (apart - 1));
        assert!(nearest.iter().all(|&(a, b)| g.has_edge(a, b)));
        let lists = candidates(&net, &nb, 50, 1e9, 2).expect("a symmetric tour");
        for v in 0..n as u32 {
            for &u in nb.out(v).iter().take(NEAREST_KEPT) {
                assert!(lists.out(v).contains(&u), "node {v} lost near neighbour {u}");
            }
        }
    }

    /// The lists keep the nearest neighbours beside the lowest-α ones, sorted by cost.
    #[test]
    fn lists_hold_the_nearest_and_are_sorted_by_cost() {
        let p = random_tour_problem(300, 7);
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 10);
        let lists = candidates(&net, &nb, 100, 1e9, 2).expect("a symmetric tour");
        for v in 0..300u32 {
            let l = lists.out(v);
            assert!(l.len() >= ALPHA_K && l.len() <= ALPHA_K + NEAREST_KEPT);
            for &u in nb.out(v).iter().take(NEAREST_KEPT) {
                assert!(l.contains(&u), "node {v} lost near neighbour {u}");
            }
            for w in l.windows(2) {
                assert!(net.arc(v, 0, w[0], 0) <= net.arc(v, 0, w[1], 0));
            }
            assert!(!l.contains(&v));
        }
    }
}
