//! The airtime solver of seed 003 (Castelino, D'Souza & Wright 2003): the generalized TSP with
//! precedence is turned into an asymmetric TSP of size 2n by the Dimitrijevic–Saric
//! transformation (§5.1, their ref. [26]), that TSP (an SOP when there is precedence) is
//! solved, and the solution is mapped back (§5.2).
//!
//! In towpath's model a GTSP **cluster** (a toolpath cell) is a task and its **nodes** (the
//! candidate entry points, each fixing the exit point, Fig. 4) are the task's modes. For every
//! cluster with nodes `v_0 … v_{k−1}` (§5.1):
//!
//! - each node `v_i` gets a copy `v_i'`, joined by the arc `v_i → v_i'` of cost `M`, a number
//!   larger than the cost of any route ("M > Σ c_ij"); this doubles the size to 2n;
//! - the originals are joined in a zero-cost cycle `v_0 → v_1 → … → v_{k−1} → v_0`, the copies
//!   in one of opposite orientation `v_{i}' → v_{i−1}'`;
//! - arcs that enter the cluster stay as they were; arcs that leave it from node `v_i` now
//!   leave from its copy `v_i'`, with the same cost; every other arc is removed. A removed arc
//!   (and a forbidden transition of the problem) costs `2M` rather than infinity, as it would in
//!   a TSPLIB matrix: no tour that uses one can beat a tour that does not, and the search can
//!   still add and subtract costs.
//!
//! A tour that enters a cluster at `v_i` runs round the originals to `v_{i−1}`, crosses to
//! `v_{i−1}'` at cost `M`, runs back round the copies to `v_i'` and leaves from there: it pays
//! `M` once per cluster and leaves from the copy of the node it entered at, which is exactly
//! the GTSP's "entering at X fixes the exit" (we add the entered mode's own cost to that `M`
//! arc, the only arc that identifies it). A tour of the transformed problem thus costs
//! `m·M + ` the GTSP route's cost, where `m` is the number of clusters.
//!
//! **Precedence** (§5.1): "if cell B must be done before cell A, then the cost of going from any
//! node in A to a node in B is set to −1", the SOP convention for "B precedes A". towpath reads
//! such −1 marks as precedence rules, so here every node (original and copy) of B is made to
//! precede every node of A directly. Consecutive groups and pinned tasks are carried over the
//! same way.
//!
//! **Solving** (§5.2): the paper used Ascheuer's SOP heuristic with precedence and Helsgaun's
//! LKH without; here towpath's own SOP/TSP search (`towpath_seq::solve`) solves the transformed
//! problem with the caller's options (time limit, seed, threads).
//!
//! **Mapping back**: a cluster's entry node is the first of its original nodes entered from
//! outside the cluster; clusters are ordered by the position of their entry node and done in
//! the entry node's mode. Any feasible tour of the transformed problem maps to a feasible GTSP
//! route (precedence between clusters holds node by node); a tour that pays `M` once per
//! cluster maps to a route of cost `tour cost − m·M`.

use towpath_seq::{Clock, CostModel, End, Mode, Problem, SolveOptions, SolveReport, StateId, Step, TaskId};

use crate::common::{finish, initial_cost};
use crate::BaselineError;

/// Largest transformed problem (2 × total modes) the solver builds.
pub const CASTELINO_MAX_NODES: usize = 200_000;

/// Most node-level precedence pairs the transformed problem may hold (a rule between two
/// clusters holds between each of their 2·k nodes: 4·k·k' pairs).
pub const CASTELINO_MAX_PRECEDENCE_PAIRS: u64 = 1 << 24;

/// Most tasks whose precedence rules are reduced (a reachability table of n² bits).
const REDUCE_MAX_TASKS: usize = 46_000;

/// Parameters of the transformation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CastelinoParams {
    /// The big arc cost `M`; `None` computes one larger than any route's cost.
    pub big_m: Option<f64>,
}

/// The transformed ATSP of a problem: `2n` node states (originals `0..n`, copies `n..2n`, `n`
/// the total number of modes) plus a start and an end depot for routes that are not cycles (the
/// start depot stands for the problem's start state, or for "anywhere"; the end depot for its
/// end state, its start again, or "anywhere").
pub struct Transformed<'p, C> {
    p: &'p Problem<C>,
    /// Node → (task, mode).
    node: Vec<(TaskId, u32)>,
    /// First node of each task (nodes of a task are consecutive).
    base: Vec<u32>,
    big_m: f64,
    /// Number of original nodes.
    n: usize,
}

impl<C: CostModel> Transformed<'_, C> {
    /// Number of original nodes `n` (the transformed problem has `2n` node tasks).
    pub fn num_nodes(&self) -> usize {
        self.n
    }

    /// The value of `M`.
    pub fn big_m(&self) -> f64 {
        self.big_m
    }

    fn start_state(&self) -> u32 {
        2 * self.n as u32
    }

    fn end_state(&self) -> u32 {
        2 * self.n as u32 + 1
    }

    /// The original node of (task, mode).
    pub fn original(&self, t: TaskId, m: u32) -> u32 {
        self.base[t.index()] + m
    }

    /// The copy of node `v`.
    pub fn copy(&self, v: u32) -> u32 {
        v + self.n as u32
    }

    /// Cluster size and position of original node `v` in it.
    fn place(&self, v: u32) -> (u32, u32, u32) {
        let (t, m) = self.node[v as usize];
        let k = self.p.modes(t).len() as u32;
        (self.base[t.index()], m, k)
    }

    /// The nodes of a task entered in mode `m`, in the order a tour visits them: originals from
    /// `m` round the cycle, then copies back round to `m'`.
    pub fn block(&self, t: TaskId, m: u32) -> Vec<u32> {
        let k = self.p.modes(t).len() as u32;
        let b = self.base[t.index()];
        let mut out: Vec<u32> = (0..k).map(|i| b + (m + i) % k).collect();
        out.extend((0..k).map(|i| self.copy(b + (m + k - 1 - i) % k)));
        out
    }
}

impl<C: CostModel> Transformed<'_, C> {
    /// The cost of a removed arc: `2M`, so a tour that uses one costs more than any tour that
    /// does not (every tour pays `M` at least once per cluster, and `M` exceeds any route's
    /// cost). Kept finite, as in a TSPLIB matrix, so the search can compute with it.
    pub fn removed_arc(&self) -> f64 {
        2.0 * self.big_m
    }

    /// The arc cost of the construction, infinite for a removed arc.
    fn arc(&self, a: u32, b: u32) -> f64 {
        if a == b {
            return 0.0;
        }
        let n = self.n as u32;
        let p = self.p;
        let entry_of = |v: u32| {
            let (t, m) = self.node[v as usize];
            p.modes(t)[m as usize].entry
        };
        let exit_of = |v: u32| {
            let (t, m) = self.node[v as usize];
            p.modes(t)[m as usize].exit
        };
        if a == self.start_state() {
            // into any original node: from the start state, or free where the route may begin
            // anywhere
            return match (b < n, p.start()) {
                (true, Some(s)) => p.transition(s, entry_of(b)),
                (true, None) => 0.0,
                _ => f64::INFINITY,
            };
        }
        if a == self.end_state() || b == self.start_state() {
            return f64::INFINITY;
        }
        if a < n {
            // original node: the cycle successor (0) or its own copy (M + the mode's cost of the
            // node the cluster was entered at, the cycle successor)
            let (base, pos, k) = self.place(a);
            let next = base + (pos + 1) % k;
            if b == a + n {
                let (t, m) = self.node[next as usize];
                return self.big_m + p.modes(t)[m as usize].cost;
            }
            if b == next {
                return 0.0;
            }
            return f64::INFINITY;
        }
        // copy of node v
        let v = a - n;
        let (base, pos, k) = self.place(v);
        if b == self.end_state() {
            let back = match p.end() {
                End::At(e) => Some(e),
                End::Closed => p.start(),
                End::Free => None,
            };
            // free where the route may end anywhere
            return back.map_or(0.0, |e| p.transition(exit_of(v), e));
        }
        if b >= n {
            let w = b - n;
            return if w == base + (pos + k - 1) % k { 0.0 } else { f64::INFINITY };
        }
        // leaving the cluster towards an original node of another cluster
        if self.node[b as usize].0 == self.node[v as usize].0 {
            return f64::INFINITY;
        }
        p.transition(exit_of(v), entry_of(b))
    }
}

impl<C: CostModel> CostModel for Transformed<'_, C> {
    fn num_states(&self) -> usize {
        2 * self.n + 2
    }

    fn cost(&self, from: StateId, to: StateId) -> f64 {
        let c = self.arc(from.0, to.0);
        if c.is_finite() {
            c
        } else {
            self.removed_arc()
        }
    }
}

/// Builds the transformation of `p` (without its precedence; see [`transformed_problem`]).
pub fn transform<'p, C: CostModel>(
    p: &'p Problem<C>,
    params: &CastelinoParams,
) -> Result<Transformed<'p, C>, BaselineError> {
    let mut node = Vec::new();
    let mut base = Vec::with_capacity(p.num_tasks());
    for t in p.tasks() {
        base.push(node.len() as u32);
        for m in 0..p.modes(t).len() as u32 {
            node.push((t, m));
        }
    }
    let n = node.len();
    if 2 * n > CASTELINO_MAX_NODES {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Castelino,
            what: format!("{} nodes after the transformation (at most {CASTELINO_MAX_NODES})", 2 * n),
        });
    }
    let big_m = match params.big_m {
        Some(m) if m.is_finite() && m > 0.0 => m,
        Some(m) => return Err(BaselineError::BadParams(format!("M must be a positive number, not {m}"))),
        None => default_big_m(p),
    };
    Ok(Transformed { p, node, base, big_m, n })
}

/// `1 + (m + 2) · (largest finite transition + largest mode cost)`: more than any route costs.
fn default_big_m<C: CostModel>(p: &Problem<C>) -> f64 {
    let mut states: Vec<StateId> = Vec::new();
    let mut max_mode: f64 = 0.0;
    for t in p.tasks() {
        for md in p.modes(t) {
            states.push(md.entry);
            states.push(md.exit);
            if md.cost.is_finite() {
                max_mode = max_mode.max(md.cost.abs());
            }
        }
    }
    states.extend(p.start());
    if let End::At(e) = p.end() {
        states.push(e);
    }
    states.sort_unstable();
    states.dedup();
    let mut max_arc: f64 = 0.0;
    // Sample rows on very large instances: M only has to be large; take a generous margin.
    let stride = (states.len() / 2000).max(1);
    for &a in states.iter().step_by(stride) {
        for &b in &states {
            let c = p.transition(a, b);
            if c.is_finite() {
                max_arc = max_arc.max(c.abs());
            }
        }
    }
    let margin = if stride > 1 { 4.0 } else { 1.0 };
    1.0 + margin * (p.num_tasks() as f64 + 2.0) * (max_arc + max_mode)
}

/// The transformed problem: `2n` point tasks over the [`Transformed`] cost model with the
/// route ends, precedence (node by node), groups and pins of `p`. For a closed tour without a
/// start state that has precedence, `pin_first` gives the (task, mode) the tour is rotated to
/// begin with.
pub fn transformed_problem<'t, 'p, C: CostModel>(
    t: &'t Transformed<'p, C>,
    pin_first: Option<(TaskId, u32)>,
) -> Result<Problem<&'t Transformed<'p, C>>, BaselineError> {
    let p = t.p;
    let n = t.n as u32;
    let reduced = reduced_precedence(p)?;
    // Count the node-level precedence pairs before making any.
    let nodes = |task: TaskId| 2 * p.modes(task).len() as u64;
    let all = 2 * t.n as u64;
    let mut pairs: u64 = reduced.iter().map(|&(a, c)| nodes(a) * nodes(c)).sum();
    if let Some(f) = p.first_task() {
        pairs += nodes(f) * (all - nodes(f)) + nodes(f);
    }
    if let Some(l) = p.last_task() {
        pairs += nodes(l) * (all - nodes(l));
    }
    if pairs > CASTELINO_MAX_PRECEDENCE_PAIRS {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Castelino,
            what: format!(
                "{pairs} node-level precedence pairs after the transformation (at most \
                 {CASTELINO_MAX_PRECEDENCE_PAIRS}): the precedence rules and pinned clusters join clusters with \
                 many nodes"
            ),
        });
    }
    let mut b = Problem::builder(t);
    for v in 0..2 * n {
        b.task(vec![Mode::point(StateId(v))]);
    }
    let nodes_of = |task: TaskId| -> Vec<TaskId> {
        let k = p.modes(task).len() as u32;
        let base = t.base[task.index()];
        (0..k).flat_map(|i| [TaskId(base + i), TaskId(base + i + n)]).collect()
    };
    // Precedence by transitive reduction at task level: fewer node pairs, same order.
    for (a, c) in reduced {
        b.precede_groups(&nodes_of(a), &nodes_of(c));
    }
    for g in p.groups() {
        b.consecutive(g.iter().flat_map(|&task| nodes_of(task)).collect());
    }
    if let Some(f) = p.first_task() {
        let fnodes = nodes_of(f);
        let others: Vec<TaskId> = p.tasks().filter(|&x| x != f).flat_map(nodes_of).collect();
        let head: Vec<TaskId> = match pin_first {
            Some((pt, pm)) if pt == f => {
                let e = TaskId(t.original(f, pm));
                fnodes.iter().copied().filter(|&x| x != e).collect()
            }
            _ => fnodes.clone(),
        };
        b.precede_groups(&head, &others);
        if let Some((pt, pm)) = pin_first.filter(|&(pt, _)| pt == f) {
            let e = TaskId(t.original(pt, pm));
            b.first(e);
            // the rest of the pinned cluster follows its entry node
            let rest: Vec<TaskId> = fnodes.iter().copied().filter(|&x| x != e).collect();
            b.precede_groups(&[e], &rest);
        }
    }
    if let Some(l) = p.last_task() {
        let lnodes = nodes_of(l);
        let others: Vec<TaskId> = p.tasks().filter(|&x| x != l).flat_map(nodes_of).collect();
        b.precede_groups(&others, &lnodes);
    }
    // An open route becomes a path from a start depot to an end depot, so every cluster is
    // entered by an arc into one of its originals and left by an arc out of one of its copies,
    // as in a tour (a free path end would let a cluster skip its M arc). A cycle stays a cycle.
    if !p.is_cyclic() {
        b.start(StateId(t.start_state()));
        b.end(End::At(StateId(t.end_state())));
    }
    b.build().map_err(|e| BaselineError::Unsupported {
        solver: crate::SolverName::Castelino,
        reason: format!("the transformed problem is not valid: {e}"),
    })
}

/// Task-level precedence pairs with transitively implied ones dropped.
fn reduced_precedence<C: CostModel>(p: &Problem<C>) -> Result<Vec<(TaskId, TaskId)>, BaselineError> {
    let n = p.num_tasks();
    let prec = p.precedence();
    if prec.num_edges() == 0 {
        return Ok(Vec::new());
    }
    if n > REDUCE_MAX_TASKS {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Castelino,
            what: format!("{n} clusters with precedence rules (the transformation reduces the rules of at most {REDUCE_MAX_TASKS})"),
        });
    }
    let words = n.div_ceil(64);
    // reach[t]: tasks reachable from t by a path of one or more edges
    let mut reach = vec![0u64; n * words];
    for &t in prec.topological().iter().rev() {
        for &s in prec.successors(t) {
            let (ti, si) = (t.index() * words, s.index() * words);
            reach[ti + s.index() / 64] |= 1 << (s.index() % 64);
            for w in 0..words {
                let v = reach[si + w];
                reach[ti + w] |= v;
            }
        }
    }
    let mut out = Vec::new();
    for t in p.tasks() {
        for &s in prec.successors(t) {
            let implied = prec
                .successors(t)
                .iter()
                .any(|&c| c != s && reach[c.index() * words + s.index() / 64] & (1 << (s.index() % 64)) != 0);
            if !implied {
                out.push((t, s));
            }
        }
    }
    Ok(out)
}

/// Maps a route of the transformed problem back to a route of the GTSP (see the module docs).
pub fn map_back<C: CostModel>(t: &Transformed<'_, C>, steps: &[Step]) -> Vec<Step> {
    let n = t.n as u32;
    let seq: Vec<u32> = steps.iter().map(|s| s.task.0).collect();
    let len = seq.len();
    let cluster = |v: u32| t.node[(if v >= n { v - n } else { v }) as usize].0;
    let mut entry: Vec<Option<(usize, u32)>> = vec![None; t.p.num_tasks()];
    for (i, &v) in seq.iter().enumerate() {
        if v >= n {
            continue;
        }
        let c = cluster(v);
        let prev = if i > 0 {
            Some(seq[i - 1])
        } else if t.p.is_cyclic() && len > 1 {
            Some(seq[len - 1])
        } else {
            None
        };
        let from_outside = prev.is_none_or(|q| cluster(q) != c);
        if from_outside && entry[c.index()].is_none() {
            entry[c.index()] = Some((i, t.node[v as usize].1));
        }
    }
    // A cluster never entered from outside (the whole sequence inside it): its first original.
    for (i, &v) in seq.iter().enumerate() {
        if v < n {
            let c = cluster(v);
            if entry[c.index()].is_none() {
                entry[c.index()] = Some((i, t.node[v as usize].1));
            }
        }
    }
    let mut order: Vec<(usize, TaskId, u32)> =
        entry.iter().enumerate().filter_map(|(c, e)| e.map(|(i, m)| (i, TaskId(c as u32), m))).collect();
    order.sort_unstable();
    order.into_iter().map(|(_, task, mode)| Step { task, mode }).collect()
}

/// The route of the transformed problem that does `steps` of the GTSP.
pub fn lift<C: CostModel>(t: &Transformed<'_, C>, steps: &[Step]) -> Vec<Step> {
    steps.iter().flat_map(|s| t.block(s.task, s.mode)).map(|v| Step { task: TaskId(v), mode: 0 }).collect()
}

/// Runs the seed-003 solver: transform, solve with towpath's search, map back.
pub fn solve_castelino<C: CostModel>(
    p: &Problem<C>,
    params: &CastelinoParams,
    opts: &SolveOptions,
) -> Result<SolveReport, BaselineError> {
    let clock = Clock::for_options(opts);
    initial_cost(p, opts)?;
    let t = transform(p, params)?;
    // A closed tour without a start state needs an anchor when there is precedence: rotate it to
    // begin at the pinned first task, entered at each of its nodes in turn.
    let pins: Vec<Option<(TaskId, u32)>> = match p.first_task() {
        Some(f) if p.is_cyclic() => (0..p.modes(f).len() as u32).map(|m| Some((f, m))).collect(),
        _ => vec![None],
    };
    let mut best: Option<(Vec<Step>, f64)> = None;
    let mut iterations = 0;
    let mut first = f64::INFINITY;
    let parts = pins.len() as u32;
    for (k, pin) in pins.into_iter().enumerate() {
        let tp = transformed_problem(&t, pin)?;
        let mut inner = opts.clone();
        // What is left of the time limit, shared by the pins still to solve.
        inner.time_limit = clock.remaining().map(|d| d / (parts - k as u32));
        inner.initial = opts
            .initial
            .as_ref()
            .filter(|init| pin.is_none_or(|(f, m)| init.first().is_some_and(|s| s.task == f && s.mode == m)))
            .map(|init| lift(&t, init));
        let r = towpath_seq::solve(&tp, &inner)?;
        iterations += r.iterations;
        let steps = map_back(&t, &r.solution.steps);
        let cost = towpath_seq::check(p, &steps).unwrap_or(f64::INFINITY);
        first = first.min(r.first_local_optimum - t.big_m * p.num_tasks() as f64);
        if best.as_ref().is_none_or(|b| cost < b.1) {
            best = Some((steps, cost));
        }
    }
    let steps = best.map(|b| b.0).unwrap_or_default();
    finish(p, steps, opts, &clock, first, iterations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_seq::MatrixCost;

    /// Three clusters of 1, 2 and 3 nodes on a line.
    fn small() -> Problem<MatrixCost> {
        let x: [f64; 7] = [0.0, 5.0, 6.0, 10.0, 11.0, 12.0, 3.0];
        let m = MatrixCost::from_fn(7, |i, j| (x[i] - x[j]).abs());
        let mut b = Problem::builder(m);
        b.task(vec![Mode::point(StateId(0))]);
        b.task(vec![Mode::point(StateId(1)), Mode::point(StateId(2))]);
        b.task(vec![
            Mode::point(StateId(3)),
            Mode::point(StateId(4)),
            Mode { entry: StateId(5), exit: StateId(6), cost: 2.0 },
        ]);
        b.start(StateId(0));
        b.build().unwrap()
    }

    #[test]
    fn lifted_routes_cost_m_per_cluster_plus_the_route() {
        let p = small();
        let t = transform(&p, &CastelinoParams::default()).unwrap();
        let tp = transformed_problem(&t, None).unwrap();
        for m1 in 0..2 {
            for m2 in 0..3 {
                for order in [[0u32, 1, 2], [0, 2, 1], [2, 1, 0]] {
                    let modes = [0, m1, m2];
                    let steps: Vec<Step> =
                        order.iter().map(|&k| Step { task: TaskId(k), mode: modes[k as usize] }).collect();
                    let c = towpath_seq::check(&p, &steps).unwrap();
                    let lifted = lift(&t, &steps);
                    let tc = towpath_seq::check(&tp, &lifted).unwrap();
                    assert!((tc - (c + 3.0 * t.big_m())).abs() < 1e-6, "{tc} vs {c} + 3M");
                    assert_eq!(map_back(&t, &lifted), steps);
                }
            }
        }
    }

    /// The transformation is exact: on tiny random GTSPs with precedence and every kind of route
    /// end, the optimum of the transformed problem (by the exact DP) is `m·M` plus the GTSP's
    /// optimum, and maps back to an optimal GTSP route.
    #[test]
    fn transformed_optimum_is_the_gtsp_optimum() {
        use rand::{Rng, SeedableRng};
        for seed in 0..40u64 {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            let clusters = rng.gen_range(2..=4usize);
            let mut pts = Vec::new();
            let mut tasks = Vec::new();
            let mut total = 0;
            for _ in 0..clusters {
                let k = rng.gen_range(1..=3usize).min(7 - total - (clusters - tasks.len() - 1));
                total += k;
                let mut ms = Vec::new();
                for _ in 0..k {
                    let a = pts.len() as u32;
                    pts.push((rng.gen_range(0.0..50.0f64).round(), rng.gen_range(0.0..50.0f64).round()));
                    pts.push((rng.gen_range(0.0..50.0f64).round(), rng.gen_range(0.0..50.0f64).round()));
                    ms.push(Mode { entry: StateId(a), exit: StateId(a + 1), cost: rng.gen_range(0.0..3.0f64).round() });
                }
                tasks.push(ms);
            }
            let s = pts.len() as u32;
            pts.push((25.0, 25.0));
            let ns = pts.len();
            let m = MatrixCost::from_fn(ns, |i, j| (pts[i].0 - pts[j].0).abs() + (pts[i].1 - pts[j].1).abs());
            let mut b = Problem::builder(m);
            for ms in tasks {
                b.task(ms);
            }
            let kind = rng.gen_range(0..4);
            match kind {
                0 => {
                    b.first(TaskId(0));
                }
                1 => {
                    b.start(StateId(s));
                }
                2 => {
                    b.end(End::Free);
                }
                _ => {
                    b.start(StateId(s)).end(End::Free);
                }
            }
            if rng.gen_bool(0.6) {
                let a = rng.gen_range(1..clusters as u32);
                let c = rng.gen_range(1..clusters as u32);
                if a != c {
                    b.precede(TaskId(a.min(c)), TaskId(a.max(c)));
                }
            }
            let p = b.build().unwrap();
            let exact = towpath_seq::solve_exact(&p).unwrap().unwrap();
            let t = transform(&p, &CastelinoParams::default()).unwrap();
            let pins: Vec<Option<(TaskId, u32)>> = if p.is_cyclic() && p.first_task().is_some() {
                (0..p.modes(TaskId(0)).len() as u32).map(|m| Some((TaskId(0), m))).collect()
            } else {
                vec![None]
            };
            let mut best = f64::INFINITY;
            for pin in pins {
                let tp = transformed_problem(&t, pin).unwrap();
                let te = towpath_seq::solve_exact(&tp).unwrap().unwrap();
                let back = map_back(&t, &te.steps);
                let c = towpath_seq::check(&p, &back).unwrap();
                assert!(
                    (te.cost - clusters as f64 * t.big_m() - c).abs() < 1e-6,
                    "seed {seed}: tour {} vs route {c}",
                    te.cost
                );
                best = best.min(c);
            }
            assert!((best - exact.cost).abs() < 1e-9, "seed {seed} kind {kind}: {best} vs optimum {}", exact.cost);
        }
    }

    /// Any feasible route of the transformed problem (here: random orders that keep its
    /// precedence, however many times they pay M) maps back to a feasible GTSP route.
    #[test]
    fn any_feasible_transformed_route_maps_back_to_a_feasible_route() {
        use rand::{Rng, SeedableRng};
        for seed in 0..30u64 {
            let p = crate::random_gtsp(30, seed, seed % 2 == 0).unwrap();
            let t = transform(&p, &CastelinoParams::default()).unwrap();
            let pin = if p.is_cyclic() && p.first_task().is_some() { Some((TaskId(0), 0)) } else { None };
            let tp = transformed_problem(&t, pin).unwrap();
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            for _ in 0..20 {
                let mut b = crate::order::OrderBuilder::new(&tp);
                let mut steps = Vec::new();
                while steps.len() < tp.num_tasks() {
                    let allowed: Vec<u32> = (0..tp.num_tasks() as u32).filter(|&v| b.allowed(v)).collect();
                    let v = allowed[rng.gen_range(0..allowed.len())];
                    b.take(v);
                    steps.push(Step { task: TaskId(v), mode: 0 });
                }
                towpath_seq::check(&tp, &steps).unwrap();
                let back = map_back(&t, &steps);
                towpath_seq::check(&p, &back).unwrap();
            }
        }
    }

    #[test]
    fn removed_arcs_are_forbidden() {
        let p = small();
        let t = transform(&p, &CastelinoParams::default()).unwrap();
        let n = t.num_nodes() as u32; // 6
                                      // original of cluster 1 to an original of cluster 2: replaced by the copy's arc
        let removed = t.removed_arc();
        assert!(removed >= 2.0 * t.big_m());
        assert_eq!(t.cost(StateId(1), StateId(3)), removed);
        assert_eq!(t.cost(StateId(1 + n), StateId(3)), 5.0);
        // cycle orientation: originals forward, copies backward
        assert_eq!(t.cost(StateId(3), StateId(4)), 0.0);
        assert_eq!(t.cost(StateId(4), StateId(3)), removed);
        assert_eq!(t.cost(StateId(4 + n), StateId(3 + n)), 0.0);
        assert_eq!(t.cost(StateId(3 + n), StateId(4 + n)), removed);
        // the M arc carries the cost of the node entered (the cycle successor): 4 → 4' closes the
        // cycle entered at node 5, whose mode costs 2
        assert_eq!(t.cost(StateId(4), StateId(4 + n)), t.big_m() + 2.0);
    }

    #[test]
    fn precedence_is_reduced_transitively() {
        let m = MatrixCost::from_fn(4, |i, j| (i as f64 - j as f64).abs());
        let mut b = Problem::builder(m);
        b.point_tasks(4);
        b.precede(TaskId(0), TaskId(1)).precede(TaskId(1), TaskId(2)).precede(TaskId(0), TaskId(2));
        b.precede(TaskId(0), TaskId(3));
        b.end(End::Free);
        let p = b.build().unwrap();
        let mut r = reduced_precedence(&p).unwrap();
        r.sort();
        assert_eq!(r, vec![(TaskId(0), TaskId(1)), (TaskId(0), TaskId(3)), (TaskId(1), TaskId(2))]);
    }
}
