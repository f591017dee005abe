//! The solvers' view of a problem: a cyclic sequence of *nodes* with position 0 fixed.
//!
//! Node `t < n_tasks` is task `t`. When the problem has a start state or an open end, an extra
//! *depot* node (id `n_tasks`) sits at position 0 and prices the way in and out; a closed tour
//! without a start state instead fixes an *anchor* task at position 0. Pinned first/last tasks
//! become precedence edges, so every move that keeps precedence keeps them too.

use crate::cost::{Cost, CostModel, PlanarEuclid, StateId};
use crate::model::{End, Problem, NO_GROUP};

/// The least price the search puts on a forbidden (non-finite) transition; see [`Net::forbidden`].
const MIN_FORBIDDEN: Cost = 1e12;

/// Marks "no reverse mode".
pub(crate) const NO_REV: u32 = u32::MAX;

pub(crate) struct Net<'p, C> {
    pub p: &'p Problem<C>,
    /// Tasks in the problem.
    pub n_tasks: usize,
    /// Nodes in the tour (tasks plus depot, if any).
    pub n: usize,
    /// Id of the depot node, or `u32::MAX` if there is none.
    pub depot: u32,
    /// The node fixed at position 0.
    pub anchor: u32,
    /// Where the way out of the last node goes, if it is priced.
    back: Option<StateId>,
    /// Reverse mode of each (task, mode), indexed by the global mode index.
    rev: Vec<u32>,
    mode_base: Vec<u32>,
    /// Entry and exit state and cost of each (task, mode), by global mode index.
    entry: Vec<StateId>,
    exit: Vec<StateId>,
    mcost: Vec<Cost>,
    /// Every mode begins and ends in the same state: reversing changes no mode.
    pub modes_self_reverse: bool,
    /// Every mode of every task has a reverse mode of equal cost, and the cost model is
    /// symmetric: reversing a stretch of the tour (with modes swapped) leaves its inside cost
    /// unchanged.
    pub reversal_symmetric: bool,
    /// Reversal-symmetric, modes self-reverse and the depot (if any) priced the same both ways:
    /// every arc costs the same in both directions.
    pub plain_symmetric: bool,
    /// Long reversals may go the short way round through position 0 (reversal-symmetric with a
    /// depot priced the same both ways, no precedence, no groups): who sits at position 0 may then change, and the tour is rotated
    /// back to the anchor before it is reported.
    pub wrap_ok: bool,
    /// Precedence including pins, in compressed form: its transitive reduction (see
    /// [`transitive_reduction`]), which keeps every order the given edges keep.
    succ_off: Vec<u32>,
    succ: Vec<u32>,
    pred_off: Vec<u32>,
    pred: Vec<u32>,
    /// The precedence edges as given (with pins), for what must know which pairs are tied
    /// directly: the same lists as `succ`/`pred` when the reduction was not computed.
    direct_succ_off: Vec<u32>,
    direct_succ: Vec<u32>,
    direct_pred_off: Vec<u32>,
    direct_pred: Vec<u32>,
    pub has_prec: bool,
    /// Rank of each node in a topological order of the precedence (with pins).
    pub topo_rank: Vec<u32>,
    /// Consecutive group per node (`NO_GROUP` if none; the depot has none).
    group: Vec<u32>,
    pub has_groups: bool,
    pub multi_mode: bool,
    /// The price of a forbidden transition in the search: at least 10¹², and a million times the
    /// largest sampled finite cost; far above any real route, finite so that sums and
    /// differences stay meaningful. The checker refuses routes that use one.
    pub forbidden: Cost,
    /// Mean of a sample of finite transition costs (at least 1).
    pub typical_arc: Cost,
    /// Every arc, priced as [`Net::arc`] does, by dense index (see [`Net::dense_index`]) when
    /// the table is small enough; empty otherwise.
    dense: Vec<Cost>,
    /// Width of `dense` (0 when there is no table).
    dense_w: usize,
    /// The table's index of every (node, mode) is the node's number (one mode per task, the
    /// depot last): an arc is looked up with no mode arithmetic.
    dense_by_node: bool,
    /// One mode per task, entering and leaving at the state with the task's own number, and no
    /// depot: an arc is the cost model's cost between the two node numbers.
    identity: bool,
    /// With `identity` and no table, the points when the costs are their (rounded) Euclidean
    /// distances in a plane: the hot path then computes an arc inline, with no call into the
    /// cost model.
    planar: Option<PlanarEuclid>,
    /// The node each node is tied to by a fixed edge that every good tour uses (see
    /// `two_way`), or `two_way::NONE`; empty when there are none.
    pub partner: Vec<u32>,
}

/// Largest number of (node, mode) pairs for which the arcs are tabulated (a table of at most
/// 2048² costs, 32 MiB). Cost models with positions are tabulated only up to `DENSE_POINTS`:
/// beyond that computing a distance is cheaper than a cache miss.
const DENSE_MAX: usize = 2048;
const DENSE_POINTS: usize = 1100;

impl<'p, C: CostModel> Net<'p, C> {
    pub fn new(p: &'p Problem<C>) -> Self {
        let n_tasks = p.num_tasks();
        let cyclic = p.is_cyclic();
        let (n, depot, anchor) = if cyclic {
            let anchor = p.first_task().map_or(0, |t| t.0);
            (n_tasks, u32::MAX, anchor)
        } else {
            (n_tasks + 1, n_tasks as u32, n_tasks as u32)
        };
        let back = match p.end() {
            End::Free => None,
            End::At(e) => Some(e),
            End::Closed => p.start(),
        };
        // Reverse modes.
        let mut mode_base = Vec::with_capacity(n_tasks + 1);
        let mut rev = Vec::new();
        let mut all_rev = true;
        let (mut entry, mut exit, mut mcost) = (Vec::new(), Vec::new(), Vec::new());
        let mut modes_self_reverse = true;
        for t in p.tasks() {
            mode_base.push(rev.len() as u32);
            let ms = p.modes(t);
            for m in ms {
                entry.push(m.entry);
                exit.push(m.exit);
                mcost.push(m.cost);
                modes_self_reverse &= m.entry == m.exit;
                let r = ms
                    .iter()
                    .position(|o| o.entry == m.exit && o.exit == m.entry && o.cost == m.cost)
                    .map_or(NO_REV, |k| k as u32);
                all_rev &= r != NO_REV;
                rev.push(r);
            }
        }
        mode_base.push(rev.len() as u32);
        let reversal_symmetric = all_rev && p.cost_model().is_symmetric();
        let depot_symmetric = cyclic || p.start() == back;
        let plain_symmetric = reversal_symmetric && modes_self_reverse && depot_symmetric;

        // Precedence with pins.
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for t in p.tasks() {
            for s in p.precedence().successors(t) {
                edges.push((t.0, s.0));
            }
        }
        if !cyclic {
            if let Some(f) = p.first_task() {
                edges.extend((0..n_tasks as u32).filter(|&x| x != f.0).map(|x| (f.0, x)));
            }
        }
        if let Some(l) = p.last_task() {
            edges.extend((0..n_tasks as u32).filter(|&x| x != l.0 && x != anchor).map(|x| (x, l.0)));
        }
        edges.sort_unstable();
        edges.dedup();
        let has_prec = !edges.is_empty();
        let (direct_succ_off, direct_succ) = csr(n, edges.iter().copied());
        let (direct_pred_off, direct_pred) = csr(n, edges.iter().map(|&(a, b)| (b, a)));
        let topo_rank = topological_rank(n, &direct_succ_off, &direct_succ, &direct_pred_off);
        let reduced = transitive_reduction(n, &direct_succ_off, &direct_succ, &topo_rank);
        let ((succ_off, succ), (pred_off, pred)) = match &reduced {
            Some(cover) => (csr(n, cover.iter().copied()), csr(n, cover.iter().map(|&(a, b)| (b, a)))),
            None => ((direct_succ_off.clone(), direct_succ.clone()), (direct_pred_off.clone(), direct_pred.clone())),
        };
        let mut group = vec![NO_GROUP; n];
        for t in p.tasks() {
            if let Some(g) = p.group_of(t) {
                group[t.index()] = g as u32;
            }
        }
        let mut net = Net {
            p,
            n_tasks,
            n,
            depot,
            anchor,
            back,
            rev,
            mode_base,
            entry,
            exit,
            mcost,
            modes_self_reverse,
            reversal_symmetric,
            plain_symmetric,
            wrap_ok: false,
            succ_off,
            succ,
            pred_off,
            pred,
            direct_succ_off,
            direct_succ,
            direct_pred_off,
            direct_pred,
            has_prec,
            topo_rank,
            group,
            has_groups: !p.groups().is_empty(),
            multi_mode: p.max_modes() > 1,
            forbidden: f64::INFINITY,
            typical_arc: 1.0,
            dense: Vec::new(),
            dense_w: 0,
            dense_by_node: false,
            identity: false,
            planar: None,
            partner: Vec::new(),
        };
        let (mean, max) = net.sample_arcs();
        net.typical_arc = mean;
        net.forbidden = (max * 1e6).max(MIN_FORBIDDEN);
        net.wrap_ok = net.reversal_symmetric && depot_symmetric && !net.has_prec && !net.has_groups;
        net.identity = depot == u32::MAX
            && (0..n_tasks).all(|t| {
                net.mode_base[t + 1] - net.mode_base[t] == 1
                    && net.entry[net.mode_base[t] as usize] == StateId(t as u32)
                    && net.exit[net.mode_base[t] as usize] == StateId(t as u32)
            });
        net.tabulate();
        if net.identity && net.dense_w == 0 {
            net.planar = p.cost_model().planar_euclid().filter(|pl| pl.xy.len() >= n_tasks);
        }
        net.reversible_under_precedence();
        net
    }

    /// Marks a one-mode instance with precedence as reversal-symmetric when its tabulated arcs
    /// are symmetric except between tasks tied directly by precedence (as in TSPLIB's prob.100,
    /// whose matrix is symmetric but for the -1 entries that encode the precedence): an arc
    /// against a precedence edge is never used by a feasible route, so reversing a stretch with
    /// no precedence inside leaves the stretch's cost unchanged. `plain_symmetric` stays false
    /// (arcs are priced in their direction).
    fn reversible_under_precedence(&mut self) {
        if self.reversal_symmetric || !self.has_prec || self.multi_mode || self.has_groups || self.dense_w == 0 {
            return;
        }
        let w = self.dense_w;
        let node = |i: usize| if i + 1 == w && self.depot != u32::MAX { self.depot } else { i as u32 };
        for i in 0..w {
            for j in i + 1..w {
                if self.dense[i * w + j] == self.dense[j * w + i] {
                    continue;
                }
                let (a, b) = (node(i), node(j));
                if !self.direct_successors(a).contains(&b) && !self.direct_successors(b).contains(&a) {
                    return;
                }
            }
        }
        self.reversal_symmetric = true;
    }

    /// Fills the dense arc table when it is small enough to pay off.
    fn tabulate(&mut self) {
        let total_modes = self.entry.len();
        let w = total_modes + usize::from(self.depot != u32::MAX);
        let has_positions = self.n_tasks > 0 && self.p.cost_model().position(StateId(0)).is_some();
        let limit = if has_positions { DENSE_POINTS } else { DENSE_MAX };
        if w > limit || w == 0 {
            return;
        }
        // (node, mode) of every dense index
        let mut of: Vec<(u32, u32)> = Vec::with_capacity(w);
        for v in 0..self.n_tasks as u32 {
            for m in 0..self.num_modes(v) {
                of.push((v, m));
            }
        }
        if self.depot != u32::MAX {
            of.push((self.depot, 0));
        }
        let mut dense = Vec::with_capacity(w * w);
        for &(a, ma) in &of {
            for &(b, mb) in &of {
                dense.push(self.priced(self.raw_arc(a, ma, b, mb)));
            }
        }
        self.dense = dense;
        self.dense_w = w;
        self.dense_by_node = of.iter().enumerate().all(|(k, &(v, m))| m == 0 && v as usize == k);
    }

    /// Index of `(v, m)` in the dense table: the global mode index, the depot last.
    #[inline]
    fn dense_index(&self, v: u32, m: u32) -> usize {
        if v == self.depot {
            self.dense_w - 1
        } else {
            (self.mode_base[v as usize] + m) as usize
        }
    }

    /// Number of modes of a node (the depot has one).
    #[inline]
    pub fn num_modes(&self, v: u32) -> u32 {
        if v == self.depot {
            1
        } else {
            self.mode_base[v as usize + 1] - self.mode_base[v as usize]
        }
    }

    /// The cheapest internal cost of node `v` over its modes.
    pub fn min_mode_cost(&self, v: u32) -> Cost {
        (0..self.num_modes(v)).map(|m| self.mode_cost(v, m)).fold(Cost::INFINITY, Cost::min)
    }

    /// Internal cost of a node in a mode.
    #[inline]
    pub fn mode_cost(&self, v: u32, m: u32) -> Cost {
        if v == self.depot {
            0.0
        } else {
            self.mcost[(self.mode_base[v as usize] + m) as usize].min(self.forbidden)
        }
    }

    /// Transition cost from node `a` in mode `ma` to node `b` in mode `mb`, with forbidden
    /// (non-finite) transitions priced at `self.forbidden` so that cost differences stay finite.
    #[inline]
    pub fn arc(&self, a: u32, ma: u32, b: u32, mb: u32) -> Cost {
        if self.dense_by_node {
            return self.dense[a as usize * self.dense_w + b as usize];
        }
        if self.dense_w != 0 {
            return self.dense[self.dense_index(a, ma) * self.dense_w + self.dense_index(b, mb)];
        }
        if let Some(pl) = &self.planar {
            // a distance: never negative, never NaN (the coordinates are finite)
            return pl.cost(a as usize, b as usize).min(self.forbidden);
        }
        self.arc_by_model(a, ma, b, mb)
    }

    /// The points of a plane whose rounded distances are the arcs (clamped to
    /// [`Net::forbidden`]), when there is no table and the costs are such distances.
    pub(crate) fn planar(&self) -> Option<&PlanarEuclid> {
        self.planar.as_ref()
    }

    /// [`Net::arc`] through the cost model (kept out of line so that the table and planar
    /// paths inline into the search's loops).
    #[inline(never)]
    fn arc_by_model(&self, a: u32, ma: u32, b: u32, mb: u32) -> Cost {
        if self.identity {
            return self.priced(self.p.transition(StateId(a), StateId(b)));
        }
        self.priced(self.raw_arc(a, ma, b, mb))
    }

    /// A raw transition cost clamped to ±the forbidden price (`min` maps +inf and NaN to it).
    #[inline]
    fn priced(&self, raw: Cost) -> Cost {
        raw.min(self.forbidden).max(-self.forbidden)
    }

    #[inline]
    fn raw_arc(&self, a: u32, ma: u32, b: u32, mb: u32) -> Cost {
        if a == self.depot {
            if b == self.depot {
                return match (self.p.start(), self.back) {
                    (Some(s), Some(e)) => self.p.transition(s, e),
                    _ => 0.0,
                };
            }
            match self.p.start() {
                Some(s) => self.p.transition(s, self.entry[(self.mode_base[b as usize] + mb) as usize]),
                None => 0.0,
            }
        } else if b == self.depot {
            match self.back {
                Some(e) => self.p.transition(self.exit[(self.mode_base[a as usize] + ma) as usize], e),
                None => 0.0,
            }
        } else {
            self.p.transition(
                self.exit[(self.mode_base[a as usize] + ma) as usize],
                self.entry[(self.mode_base[b as usize] + mb) as usize],
            )
        }
    }

    /// True when `a`–`b` is a fixed edge (see [`Net::partner`]).
    #[inline]
    pub fn fixed(&self, a: u32, b: u32) -> bool {
        self.partner.get(a as usize) == Some(&b)
    }

    /// The mean and the largest of a deterministic sample of finite transition costs (at
    /// least 1): the scale for "equal within rounding" and for the forbidden price.
    fn sample_arcs(&self) -> (Cost, Cost) {
        let n = self.n_tasks as u32;
        if n < 2 {
            return (1.0, 1.0);
        }
        let (mut sum, mut count, mut max) = (0.0, 0u32, 1.0f64);
        let step = (n / 64).max(1);
        for a in (0..n).step_by(step as usize) {
            for k in 1..=16u32.min(n - 1) {
                let b = (a + k * 7919) % n;
                if a != b {
                    let c = self.raw_arc(a, 0, b, 0);
                    if c.is_finite() {
                        sum += c.abs();
                        count += 1;
                        max = max.max(c.abs());
                    }
                }
            }
        }
        let mean = if count == 0 { 1.0 } else { (sum / count as f64).max(1.0) };
        (mean, max)
    }

    /// The reverse mode of `(v, m)`, or `NO_REV`.
    #[inline]
    pub fn rev_mode(&self, v: u32, m: u32) -> u32 {
        if v == self.depot {
            0
        } else {
            self.rev[(self.mode_base[v as usize] + m) as usize]
        }
    }

    /// The nodes that must come after `v` (not necessarily at once), by the transitive
    /// reduction of the precedence: enough to keep the whole precedence when a feasible tour
    /// is rearranged, as every pair tied only through others has those others between it.
    #[inline]
    pub fn successors(&self, v: u32) -> &[u32] {
        &self.succ[self.succ_off[v as usize] as usize..self.succ_off[v as usize + 1] as usize]
    }

    /// For each task, how many tasks must come at once before it in the transitive reduction
    /// (pins to the depot left out): the in-degrees from which a topological order starts.
    pub fn task_indegrees(&self) -> Vec<u32> {
        let n = self.n_tasks;
        let mut indegree = vec![0u32; n];
        for v in 0..n as u32 {
            for &s in self.successors(v) {
                if (s as usize) < n {
                    indegree[s as usize] += 1;
                }
            }
        }
        indegree
    }

    /// The nodes that must come before `v`, in the transitive reduction (see
    /// [`Net::successors`]).
    #[inline]
    pub fn predecessors(&self, v: u32) -> &[u32] {
        &self.pred[self.pred_off[v as usize] as usize..self.pred_off[v as usize + 1] as usize]
    }

    /// The successors of `v` by the precedence edges as given (with pins).
    pub fn direct_successors(&self, v: u32) -> &[u32] {
        &self.direct_succ[self.direct_succ_off[v as usize] as usize..self.direct_succ_off[v as usize + 1] as usize]
    }

    /// The predecessors of `v` by the precedence edges as given (with pins).
    pub fn direct_predecessors(&self, v: u32) -> &[u32] {
        &self.direct_pred[self.direct_pred_off[v as usize] as usize..self.direct_pred_off[v as usize + 1] as usize]
    }

    /// The consecutive group of a node.
    #[inline]
    pub fn group(&self, v: u32) -> u32 {
        self.group[v as usize]
    }

    /// True if the arc between `a` and `b` lies inside one consecutive group.
    #[inline]
    pub fn inside_group(&self, a: u32, b: u32) -> bool {
        let g = self.group[a as usize];
        g != NO_GROUP && g == self.group[b as usize]
    }

    /// Does a move keep every consecutive group contiguous? It removes `arcs` (given by their end
    /// nodes) and rearranges only positions `lo..=hi` of `seq`. It does if all removed arcs join
    /// different groups (whole blocks move), or all lie inside one group, or the rearranged
    /// positions all belong to one group.
    pub fn move_allowed(&self, seq: &[u32], arcs: &[(u32, u32)], lo: usize, hi: usize) -> bool {
        if !self.has_groups || self.cuts_allowed(arcs) {
            return true;
        }
        let g = self.group[seq[lo] as usize];
        g != NO_GROUP && seq[lo..=hi].iter().all(|&x| self.group[x as usize] == g)
    }

    fn cuts_allowed(&self, arcs: &[(u32, u32)]) -> bool {
        if !self.has_groups {
            return true;
        }
        let inside: Vec<bool> = arcs.iter().map(|&(a, b)| self.inside_group(a, b)).collect();
        if inside.iter().all(|&x| !x) {
            return true;
        }
        if inside.iter().all(|&x| x) {
            let g = self.group[arcs[0].0 as usize];
            return arcs.iter().all(|&(a, _)| self.group[a as usize] == g);
        }
        false
    }
}

/// Kahn's algorithm over the compressed adjacency; nodes on a cycle (impossible after model
/// validation) keep rank `u32::MAX`.
fn topological_rank(n: usize, succ_off: &[u32], succ: &[u32], pred_off: &[u32]) -> Vec<u32> {
    let mut indeg: Vec<u32> = (0..n).map(|v| pred_off[v + 1] - pred_off[v]).collect();
    let mut stack: Vec<u32> = (0..n as u32).filter(|&v| indeg[v as usize] == 0).collect();
    let mut rank = vec![u32::MAX; n];
    let mut r = 0;
    while let Some(v) = stack.pop() {
        rank[v as usize] = r;
        r += 1;
        for &s in &succ[succ_off[v as usize] as usize..succ_off[v as usize + 1] as usize] {
            indeg[s as usize] -= 1;
            if indeg[s as usize] == 0 {
                stack.push(s);
            }
        }
    }
    rank
}

/// Largest node count for which the precedence is reduced: the reduction keeps a reachability
/// bit set per node, n²/8 bytes (32 MiB at this size).
const REDUCE_UP_TO: usize = 16_384;

/// The transitive reduction of an acyclic precedence (every edge implied by a path of others
/// dropped), or `None` when there are no edges, the graph is too large (see [`REDUCE_UP_TO`])
/// or it has a cycle. On SOPLIB's R.300.1000.15 it keeps 766 of 7,228 edges (pins
/// included): the local search labels and checks a ninth as many.
///
/// Nodes are taken in reverse topological order; a node's successors in topological order,
/// each kept unless reachable from one kept before it, and its reachable set is theirs joined.
fn transitive_reduction(n: usize, succ_off: &[u32], succ: &[u32], rank: &[u32]) -> Option<Vec<(u32, u32)>> {
    if succ.is_empty() || n > REDUCE_UP_TO || rank.contains(&u32::MAX) {
        return None;
    }
    let words = n.div_ceil(64);
    let mut reach = vec![0u64; n * words];
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_unstable_by_key(|&v| std::cmp::Reverse(rank[v as usize]));
    let mut kept = Vec::new();
    let mut succs: Vec<u32> = Vec::new();
    let mut covered = vec![0u64; words];
    for &v in &order {
        succs.clear();
        succs.extend_from_slice(&succ[succ_off[v as usize] as usize..succ_off[v as usize + 1] as usize]);
        succs.sort_unstable_by_key(|&s| rank[s as usize]);
        covered.fill(0);
        for &s in &succs {
            let s = s as usize;
            if covered[s / 64] >> (s % 64) & 1 == 1 {
                continue;
            }
            kept.push((v, s as u32));
            covered[s / 64] |= 1 << (s % 64);
            for (c, r) in covered.iter_mut().zip(&reach[s * words..(s + 1) * words]) {
                *c |= r;
            }
        }
        reach[v as usize * words..(v as usize + 1) * words].copy_from_slice(&covered);
    }
    kept.sort_unstable();
    Some(kept)
}

fn csr(n: usize, edges: impl Iterator<Item = (u32, u32)> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut off = vec![0u32; n + 1];
    for (a, _) in edges.clone() {
        off[a as usize + 1] += 1;
    }
    for i in 0..n {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut out = vec![0u32; off[n] as usize];
    for (a, b) in edges {
        out[fill[a as usize] as usize] = b;
        fill[a as usize] += 1;
    }
    (off, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cost::{MatrixCost, Metric, PointCost, PointMetric};
    use crate::model::Mode;

    /// The reduction keeps exactly the reachability of the given edges, and no kept edge is
    /// implied by the others (brute-force closures of random acyclic graphs).
    #[test]
    fn transitive_reduction_keeps_reachability_and_drops_every_implied_edge() {
        use rand::{Rng, SeedableRng};
        let closure = |n: usize, edges: &[(u32, u32)]| {
            let mut r = vec![vec![false; n]; n];
            for &(a, b) in edges {
                r[a as usize][b as usize] = true;
            }
            for k in 0..n {
                for i in 0..n {
                    for j in 0..n {
                        if r[i][k] && r[k][j] {
                            r[i][j] = true;
                        }
                    }
                }
            }
            r
        };
        for seed in 0..40u64 {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            let n = 2 + (seed as usize % 30);
            let mut perm: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                perm.swap(i, rng.gen_range(0..=i));
            }
            let density = rng.gen_range(0.05..0.6);
            let mut edges = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if rng.gen_bool(density) {
                        edges.push((perm[i], perm[j]));
                    }
                }
            }
            edges.sort_unstable();
            let (so, sv) = csr(n, edges.iter().copied());
            let (po, _) = csr(n, edges.iter().map(|&(a, b)| (b, a)));
            let rank = topological_rank(n, &so, &sv, &po);
            let Some(kept) = transitive_reduction(n, &so, &sv, &rank) else {
                assert!(edges.is_empty(), "seed {seed}: no reduction of {} edges", edges.len());
                continue;
            };
            assert!(kept.iter().all(|e| edges.binary_search(e).is_ok()), "seed {seed}: an edge not given");
            assert_eq!(closure(n, &kept), closure(n, &edges), "seed {seed}: reachability changed");
            for (x, e) in kept.iter().enumerate() {
                let others: Vec<(u32, u32)> =
                    kept.iter().enumerate().filter(|&(y, _)| y != x).map(|(_, &f)| f).collect();
                assert!(!closure(n, &others)[e.0 as usize][e.1 as usize], "seed {seed}: {e:?} is implied");
            }
        }
    }

    /// The dense table gives every arc exactly as the cost model does, through modes, the depot
    /// and forbidden transitions.
    #[test]
    fn dense_table_matches_the_cost_model() {
        let s = 7usize;
        let mut m: Vec<Cost> = (0..s * s).map(|k| ((k * 37) % 23) as Cost + 0.5).collect();
        m[3 * s + 4] = Cost::INFINITY;
        let cost = MatrixCost::new(s, m).unwrap();
        let mut b = Problem::builder(cost);
        b.task(vec![Mode::new(StateId(1), StateId(2)), Mode::new(StateId(2), StateId(1))]);
        b.task(vec![Mode::point(StateId(3))]);
        b.task(vec![Mode::new(StateId(4), StateId(5)), Mode::new(StateId(5), StateId(4)), Mode::point(StateId(6))]);
        b.start(StateId(0)).end(End::At(StateId(6)));
        let p = b.build().unwrap();
        let net = Net::new(&p);
        assert_eq!(net.dense_w, 7, "six modes and the depot");
        assert!(!net.dense_by_node, "two tasks have several modes");
        let nodes: Vec<u32> = (0..net.n as u32).collect();
        for &a in &nodes {
            for ma in 0..net.num_modes(a) {
                for &b in &nodes {
                    for mb in 0..net.num_modes(b) {
                        let want = net.raw_arc(a, ma, b, mb).min(net.forbidden).max(-net.forbidden);
                        assert_eq!(net.arc(a, ma, b, mb), want, "arc {a}/{ma} -> {b}/{mb}");
                    }
                }
            }
        }
        assert_eq!(net.arc(1, 0, 2, 0), net.forbidden, "state 3 -> 4 is forbidden");
    }

    /// One mode per task: the table is indexed by node number (the depot last), and every
    /// arc is still the cost model's, for an open route with a depot and for a cycle.
    #[test]
    fn table_by_node_matches_the_cost_model() {
        let s = 6usize;
        let mut m: Vec<Cost> = (0..s * s).map(|k| ((k * 29) % 17) as Cost - 3.0).collect();
        m[2 * s + 5] = Cost::INFINITY;
        let cost = MatrixCost::new(s, m).unwrap();
        for open in [true, false] {
            let mut b = Problem::builder(&cost);
            for st in 1..s as u32 {
                b.task(vec![Mode::point(StateId(st))]);
            }
            if open {
                b.start(StateId(0)).end(End::Free);
            }
            let p = b.build().unwrap();
            let net = Net::new(&p);
            assert!(net.dense_by_node, "open {open}");
            assert_eq!(net.dense_w, if open { s } else { s - 1 });
            for a in 0..net.n as u32 {
                for b in 0..net.n as u32 {
                    let want = net.priced(net.raw_arc(a, 0, b, 0));
                    assert_eq!(net.arc(a, 0, b, 0), want, "open {open}: arc {a} -> {b}");
                }
            }
        }
    }

    /// A closed tour through the points, one task per point.
    fn points_tour(pts: Vec<[f64; 3]>, metric: Metric) -> Problem<PointCost> {
        let n = pts.len();
        let mut b = Problem::builder(PointCost::new(pts, metric));
        for k in 0..n as u32 {
            b.task(vec![Mode::point(StateId(k))]);
        }
        b.build().unwrap()
    }

    /// Too many points for the table: with plane points under a Euclidean metric every arc is
    /// computed inline, and equals the cost model's price bit for bit (halves included: the
    /// coordinates are on a grid of quarters, so many distances end in .5 exactly); other
    /// metrics and points off the plane go through the model.
    #[test]
    fn planar_arcs_equal_the_cost_model() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let n = DENSE_POINTS + 100;
        let flat: Vec<[f64; 3]> =
            (0..n).map(|_| [rng.gen_range(0..400) as f64 / 4.0, rng.gen_range(0..400) as f64 / 4.0, 0.0]).collect();
        for metric in [Metric::Euclidean, Metric::EuclideanNint, Metric::EuclideanCeil, Metric::ManhattanNint] {
            let p = points_tour(flat.clone(), metric);
            let net = Net::new(&p);
            assert_eq!(net.dense_w, 0, "{metric:?}: no table at {n} points");
            assert_eq!(net.planar.is_some(), metric != Metric::ManhattanNint, "{metric:?}");
            let mut halves = 0;
            for _ in 0..20_000 {
                let (a, b) = (rng.gen_range(0..n as u32), rng.gen_range(0..n as u32));
                let want = p.transition(StateId(a), StateId(b));
                assert_eq!(net.arc(a, 0, b, 0).to_bits(), want.to_bits(), "{metric:?}: arc {a} -> {b}");
                let d = Metric::Euclidean.cost(&flat, a as usize, b as usize);
                halves += usize::from(d.fract() == 0.5);
            }
            assert!(halves > 0, "some distances end in exactly one half");
        }
        let mut lifted = flat;
        lifted[7][2] = 1.0;
        let p = points_tour(lifted, Metric::EuclideanNint);
        let net = Net::new(&p);
        assert!(net.planar.is_none(), "a point off the plane");
        for a in 0..50 {
            assert_eq!(net.arc(a, 0, 7, 0), p.transition(StateId(a), StateId(7)));
        }
    }
}
