//! The off-part motion solver of seed 000 §3.2 (Doherty, Wehbe, Plain, Harik & Halbritter
//! 2022): seed selection with nearest neighbour, then a depth-first and a breadth-first local
//! search, run on each precedence set in turn.
//!
//! **Precedence sets** (§3.1): the part is split into ordered, disjoint sets of courses that may
//! be laid in any order within a set. They are given by the caller ([`DohertyParams::sets`],
//! e.g. plies joined while they do not intersect, as the paper does); without them they are
//! derived from the problem's precedence DAG by layers: a task's set is the length of the
//! longest chain of predecessors before it (with no precedence at all, one set holds every
//! task). Every precedence rule then goes from an earlier set to a later one.
//!
//! For each set, in order (§3.2):
//!
//! 1. **Seed pool**: every course's start position, and its end position when it can be laid
//!    in reverse — in towpath's terms, every (task, mode) as the first step. The paper adds "the
//!    single vertex which has the maximum total distance between itself and all vertices"; with
//!    every start and end already in the pool that vertex is among them.
//! 2. Each seed grows a **nearest-neighbour** path (each step the unvisited task and mode with
//!    the cheapest move, the mode's own cost included); the seed of the cheapest path is kept.
//! 3. **Depth-first phase**: paths are rebuilt from the seed with growing depth `d`. At depth
//!    `d` each step looks ahead: every unvisited (task, mode) `v` is scored by the move to it
//!    plus a nearest-neighbour chain of `d − 1` further steps from it, and the step goes to the
//!    best-scored `v` (depth 1 is plain nearest neighbour). This is our reading of "paths of
//!    length *depth* of successive nearest vertices"; the figure that details it is not in the
//!    text. Each iteration increases the depth; an iteration that does not lower the best cost
//!    increases the counter `a` (never reset, as the paper says). The phase stops when `a = N`,
//!    the depth reaches the maximum depth, or the iterations reach their maximum.
//! 4. **Breadth-first phase**: one pass at the depth of the last improvement that builds `k`
//!    paths, the `j`-th one going first from the seed to its `j`-th nearest task and then
//!    following the depth rule. The best path of both phases is the set's path.
//!
//! As in the paper, the move between the end of one set's path and the next set's seed is not
//! part of the search (it "will be considered negligible"): each set is solved on its own. The
//! reported cost is the problem's full route cost, which does count those moves, the start and
//! the end. An initial route, if given, is returned when it is cheaper (requirement 4,
//! F(p) ≤ F(o)). The algorithm is deterministic.
//!
//! The paper makes the maximum depth "a function of the course count and ply count" of the set
//! and `k` "a function of the precedence set's ply count and the layup strategy" without giving
//! the functions; ours are [`DohertyParams::max_depth`] and [`DohertyParams::breadth`].

use towpath_seq::{Clock, CostModel, Problem, SolveOptions, SolveReport, StateId, Step, TaskId};

use crate::common::finish;
use crate::BaselineError;

/// Most moves one nearest-neighbour pass over the precedence sets may weigh (Σ tasks × modes of
/// each set): the first pass is made in full whatever the time limit.
pub const DOHERTY_MAX_PASS: u64 = 1_000_000_000;

/// One precedence set: tasks that may be done in any order among themselves, and how many plies
/// they came from (used by the depth and breadth rules).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PrecedenceSet {
    /// The set's tasks.
    pub tasks: Vec<TaskId>,
    /// Plies joined into the set (at least 1).
    pub plies: usize,
}

/// Parameters of the seed-000 solver.
#[derive(Clone, Debug, PartialEq)]
pub struct DohertyParams {
    /// The precedence sets, in laying order; `None` derives them from the precedence DAG.
    pub sets: Option<Vec<PrecedenceSet>>,
    /// `N`: depth-first iterations without improvement before the phase stops (default 3).
    pub no_improvement: usize,
    /// Maximum depth-first iterations per set (default 25), the operator's runtime cap.
    pub max_iterations: usize,
    /// Maximum depth: `min(courses, depth_base + depth_per_ply · plies)` (defaults 2 and 2).
    pub depth_base: usize,
    /// See [`DohertyParams::depth_base`].
    pub depth_per_ply: usize,
    /// Breadth `k`: `min(courses, breadth_per_ply · plies · (2 if bidirectional else 1))`
    /// (default 2).
    pub breadth_per_ply: usize,
}

impl Default for DohertyParams {
    fn default() -> Self {
        DohertyParams {
            sets: None,
            no_improvement: 3,
            max_iterations: 25,
            depth_base: 2,
            depth_per_ply: 2,
            breadth_per_ply: 2,
        }
    }
}

impl DohertyParams {
    /// The maximum depth for a set of `courses` tasks from `plies` plies.
    pub fn max_depth(&self, courses: usize, plies: usize) -> usize {
        (self.depth_base + self.depth_per_ply * plies.max(1)).min(courses).max(1)
    }

    /// The breadth `k` for a set of `courses` tasks from `plies` plies; bidirectional when some
    /// task of the set has more than one mode.
    pub fn breadth(&self, courses: usize, plies: usize, bidirectional: bool) -> usize {
        let f = if bidirectional { 2 } else { 1 };
        (self.breadth_per_ply * plies.max(1) * f).min(courses)
    }
}

/// Derives precedence sets by layers of the precedence DAG (see the module docs).
pub fn sets_from_precedence<C: CostModel>(p: &Problem<C>) -> Vec<PrecedenceSet> {
    let n = p.num_tasks();
    let mut layer = vec![0usize; n];
    for &t in p.precedence().topological() {
        for &q in p.precedence().predecessors(t) {
            layer[t.index()] = layer[t.index()].max(layer[q.index()] + 1);
        }
    }
    let layers = layer.iter().copied().max().map_or(0, |m| m + 1);
    let mut sets: Vec<PrecedenceSet> = (0..layers).map(|_| PrecedenceSet { tasks: Vec::new(), plies: 1 }).collect();
    for t in p.tasks() {
        sets[layer[t.index()]].tasks.push(t);
    }
    sets
}

/// Checks that sets partition the tasks and agree with the precedence and pins.
fn validate_sets<C: CostModel>(p: &Problem<C>, sets: &[PrecedenceSet]) -> Result<(), BaselineError> {
    let n = p.num_tasks();
    let mut set_of = vec![usize::MAX; n];
    for (k, s) in sets.iter().enumerate() {
        for t in &s.tasks {
            let Some(slot) = set_of.get_mut(t.index()) else {
                return Err(BaselineError::BadSets(format!("set {k} names task {}, which does not exist", t.0)));
            };
            if *slot != usize::MAX {
                return Err(BaselineError::BadSets(format!("task {} is in sets {} and {k}", t.0, *slot)));
            }
            *slot = k;
        }
    }
    if let Some(t) = set_of.iter().position(|&s| s == usize::MAX) {
        return Err(BaselineError::BadSets(format!("task {t} is in no set")));
    }
    for t in p.tasks() {
        for &after in p.precedence().successors(t) {
            if set_of[t.index()] >= set_of[after.index()] {
                return Err(BaselineError::BadSets(format!(
                    "task {} must precede task {} but is in set {}, not an earlier one than {}",
                    t.0,
                    after.0,
                    set_of[t.index()],
                    set_of[after.index()]
                )));
            }
        }
    }
    let nonempty: Vec<usize> = (0..sets.len()).filter(|&k| !sets[k].tasks.is_empty()).collect();
    if let Some(f) = p.first_task() {
        if nonempty.first() != Some(&set_of[f.index()]) {
            return Err(BaselineError::BadSets(format!("task {} is pinned first but is not in the first set", f.0)));
        }
    }
    if let Some(l) = p.last_task() {
        if nonempty.last() != Some(&set_of[l.index()]) {
            return Err(BaselineError::BadSets(format!("task {} is pinned last but is not in the last set", l.0)));
        }
    }
    Ok(())
}

/// A task of a set (its index in the set) and a mode.
type Slot = (usize, usize);

/// The search over one precedence set.
struct SetSearch<'a, C> {
    p: &'a Problem<C>,
    tasks: &'a [TaskId],
    /// Tasks that may not be chosen by the search (the pinned last task, appended afterwards).
    barred: Option<TaskId>,
    /// Once it expires, paths are finished by nearest neighbour (no lookahead).
    clock: &'a Clock,
}

impl<C: CostModel> SetSearch<'_, C> {
    /// Cost of doing `(t, m)` after leaving the tool in `from` (the mode's own cost included).
    #[inline]
    fn step(&self, from: Option<StateId>, t: TaskId, m: usize) -> f64 {
        let md = self.p.modes(t)[m];
        let c = md.cost + from.map_or(0.0, |s| self.p.transition(s, md.entry));
        if c.is_nan() {
            f64::INFINITY
        } else {
            c
        }
    }

    /// The cheapest unvisited (task slot, mode) from `from`; ties to the lowest slot and mode.
    fn nearest(&self, from: Option<StateId>, visited: &[bool]) -> Option<(usize, usize, f64)> {
        let mut best: Option<(usize, usize, f64)> = None;
        for (i, &t) in self.tasks.iter().enumerate() {
            if visited[i] {
                continue;
            }
            for m in 0..self.p.modes(t).len() {
                let c = self.step(from, t, m);
                if best.is_none_or(|b| c < b.2) {
                    best = Some((i, m, c));
                }
            }
        }
        best
    }

    /// Cost of a nearest-neighbour chain of `len` steps from `from` (visited restored after).
    fn chain(&self, from: StateId, len: usize, visited: &mut [bool], scratch: &mut Vec<usize>) -> f64 {
        let mut cost = 0.0;
        let mut cur = from;
        scratch.clear();
        for _ in 0..len {
            let Some((i, m, c)) = self.nearest(Some(cur), visited) else { break };
            visited[i] = true;
            scratch.push(i);
            cost += c;
            cur = self.p.modes(self.tasks[i])[m].exit;
        }
        for &i in scratch.iter() {
            visited[i] = false;
        }
        cost
    }

    /// A path from the seed `(slot, mode)` built by the depth-`depth` lookahead rule; `first`, if
    /// given, forces the step after the seed. Returns (slot, mode) pairs and the path cost.
    fn path(&self, seed: (usize, usize), depth: usize, first: Option<(usize, usize)>) -> (Vec<(usize, usize)>, f64) {
        let n = self.tasks.len();
        let mut visited = vec![false; n];
        if let Some(b) = self.barred {
            if let Some(i) = self.tasks.iter().position(|&t| t == b) {
                visited[i] = true;
            }
        }
        let todo = visited.iter().filter(|&&v| !v).count();
        let mut out = Vec::with_capacity(n);
        let mut scratch = Vec::new();
        visited[seed.0] = true;
        out.push(seed);
        let mut cost = self.step(None, self.tasks[seed.0], seed.1);
        let mut cur = self.p.modes(self.tasks[seed.0])[seed.1].exit;
        if let Some((i, m)) = first.filter(|&(i, _)| !visited[i]) {
            visited[i] = true;
            out.push((i, m));
            cost += self.step(Some(cur), self.tasks[i], m);
            cur = self.p.modes(self.tasks[i])[m].exit;
        }
        while out.len() < todo {
            let mut best: Option<(f64, f64, usize, usize)> = None;
            if depth <= 1 || self.clock.expired() {
                if let Some((i, m, c)) = self.nearest(Some(cur), &visited) {
                    best = Some((c, c, i, m));
                }
            } else {
                for i in 0..n {
                    if visited[i] {
                        continue;
                    }
                    let t = self.tasks[i];
                    for m in 0..self.p.modes(t).len() {
                        let c = self.step(Some(cur), t, m);
                        visited[i] = true;
                        let score = c + self.chain(self.p.modes(t)[m].exit, depth - 1, &mut visited, &mut scratch);
                        visited[i] = false;
                        let better = match best {
                            None => true,
                            Some((bs, bc, _, _)) => score < bs || (score == bs && c < bc),
                        };
                        if better {
                            best = Some((score, c, i, m));
                        }
                    }
                }
            }
            let Some((_, c, i, m)) = best else { break };
            visited[i] = true;
            out.push((i, m));
            cost += c;
            cur = self.p.modes(self.tasks[i])[m].exit;
        }
        (out, cost)
    }

    /// The set's tasks ordered by the cheapest move from the exit of `seed` (each with its
    /// cheapest mode), excluding the seed and the barred task.
    fn nearest_from(&self, seed: (usize, usize)) -> Vec<(usize, usize)> {
        let from = self.p.modes(self.tasks[seed.0])[seed.1].exit;
        let mut v: Vec<(f64, usize, usize)> = Vec::new();
        for (i, &t) in self.tasks.iter().enumerate() {
            if i == seed.0 || Some(t) == self.barred {
                continue;
            }
            let (m, c) = (0..self.p.modes(t).len())
                .map(|m| (m, self.step(Some(from), t, m)))
                .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            v.push((c, i, m));
        }
        v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        v.into_iter().map(|(_, i, m)| (i, m)).collect()
    }
}

/// What the search did on one set (for tests and reports).
#[derive(Clone, Debug, PartialEq)]
pub struct SetTrace {
    /// Cost of the chosen seed's nearest-neighbour path.
    pub seed_cost: f64,
    /// Depth of the last improvement in the depth-first phase.
    pub final_depth: usize,
    /// Depth-first iterations run.
    pub iterations: usize,
    /// Cost after the depth-first phase.
    pub depth_first_cost: f64,
    /// Cost after the breadth-first phase (the set's path cost, moves inside the set only).
    pub cost: f64,
}

/// Runs the seed-000 solver and returns the route with a trace per set.
pub fn solve_doherty_traced<C: CostModel>(
    p: &Problem<C>,
    params: &DohertyParams,
    opts: &SolveOptions,
) -> Result<(SolveReport, Vec<SetTrace>), BaselineError> {
    let clock = Clock::for_options(opts);
    if !p.groups().is_empty() {
        return Err(BaselineError::Unsupported {
            solver: crate::SolverName::Doherty,
            reason: "consecutive groups are not part of the seed-000 model".into(),
        });
    }
    let sets = match &params.sets {
        Some(s) => s.clone(),
        None => sets_from_precedence(p),
    };
    validate_sets(p, &sets)?;
    // The first nearest-neighbour path of every set is made whatever the time limit: refuse
    // sets too large for it (each step weighs every mode of the set).
    let pass: u64 = sets
        .iter()
        .map(|set| set.tasks.len() as u64 * set.tasks.iter().map(|&t| p.modes(t).len() as u64).sum::<u64>())
        .sum();
    if pass > DOHERTY_MAX_PASS {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Doherty,
            what: format!(
                "one nearest-neighbour pass over the precedence sets weighs {pass} moves, the seed pool at most \
                 {DOHERTY_MAX_PASS}"
            ),
        });
    }
    let mut steps: Vec<Step> = Vec::with_capacity(p.num_tasks());
    let mut traces = Vec::new();
    let mut iterations = 0u64;
    let mut first_total = 0.0;
    let last_nonempty = sets.iter().rposition(|s| !s.tasks.is_empty());
    for (k, set) in sets.iter().enumerate() {
        if set.tasks.is_empty() {
            continue;
        }
        let barred = p.last_task().filter(|_| Some(k) == last_nonempty && set.tasks.len() > 1);
        let search = SetSearch { p, tasks: &set.tasks, barred, clock: &clock };
        let bidirectional = set.tasks.iter().any(|&t| p.modes(t).len() > 1);
        let courses = set.tasks.len() - usize::from(barred.is_some());
        // 1–2: seed pool, nearest neighbour from each seed, the cheapest path's seed kept.
        let pinned_first = p.first_task().filter(|f| set.tasks.contains(f));
        let mut pool: Vec<(usize, usize)> = Vec::new();
        for (i, &t) in set.tasks.iter().enumerate() {
            if Some(t) == barred || pinned_first.is_some_and(|f| f != t) {
                continue;
            }
            for m in 0..p.modes(t).len() {
                pool.push((i, m));
            }
        }
        let mut best: Option<(Slot, Vec<Slot>, f64)> = None;
        for &seed in &pool {
            let (path, cost) = search.path(seed, 1, None);
            if best.as_ref().is_none_or(|b| cost < b.2) {
                best = Some((seed, path, cost));
            }
            if clock.expired() {
                break;
            }
        }
        let Some((seed, mut best_path, mut best_cost)) = best else { continue };
        let seed_cost = best_cost;
        first_total += seed_cost;
        // 3: depth-first phase.
        let max_depth = params.max_depth(courses, set.plies);
        let (mut depth, mut a, mut iters, mut final_depth) = (1usize, 0usize, 0usize, 1usize);
        while iters < params.max_iterations && depth < max_depth && a < params.no_improvement && !clock.expired() {
            depth += 1;
            iters += 1;
            let (path, cost) = search.path(seed, depth, None);
            if cost < best_cost {
                best_cost = cost;
                best_path = path;
                final_depth = depth;
            } else {
                a += 1;
            }
        }
        iterations += iters as u64;
        let depth_first_cost = best_cost;
        // 4: breadth-first phase at the depth of the last improvement.
        let k_paths = params.breadth(courses, set.plies, bidirectional);
        for &first in search.nearest_from(seed).iter().take(k_paths) {
            if clock.expired() {
                break;
            }
            let (path, cost) = search.path(seed, final_depth, Some(first));
            if cost < best_cost {
                best_cost = cost;
                best_path = path;
            }
        }
        steps.extend(best_path.iter().map(|&(i, m)| Step { task: set.tasks[i], mode: m as u32 }));
        if let Some(l) = barred {
            let from = steps.last().map(|s| p.modes(s.task)[s.mode as usize].exit);
            let m = (0..p.modes(l).len()).map(|m| (m, search.step(from, l, m))).fold((0, f64::INFINITY), |a, b| {
                if b.1 < a.1 {
                    b
                } else {
                    a
                }
            });
            steps.push(Step { task: l, mode: m.0 as u32 });
        }
        traces.push(SetTrace { seed_cost, final_depth, iterations: iters, depth_first_cost, cost: best_cost });
    }
    let report = finish(p, steps, opts, &clock, first_total, iterations)?;
    Ok((report, traces))
}

/// Runs the seed-000 solver.
pub fn solve_doherty<C: CostModel>(
    p: &Problem<C>,
    params: &DohertyParams,
    opts: &SolveOptions,
) -> Result<SolveReport, BaselineError> {
    solve_doherty_traced(p, params, opts).map(|(r, _)| r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_seq::{End, MatrixCost};

    /// Points on a line at 2, 1, 0, 10, 11: nearest neighbour from task 0 (at 2) goes
    /// 2→1→0→10→11 (cost 1 + 1 + 10 + 1 = 13); from task 2 (at 0) it finds the optimum
    /// 0→1→2→10→11 (cost 11).
    fn line() -> Problem<MatrixCost> {
        let x: [f64; 5] = [2.0, 1.0, 0.0, 10.0, 11.0];
        let m = MatrixCost::from_fn(5, |i, j| (x[i] - x[j]).abs());
        let mut b = Problem::builder(m);
        b.point_tasks(5);
        b.end(End::Free);
        b.build().unwrap()
    }

    #[test]
    fn seed_pool_finds_the_best_start() {
        let p = line();
        let (r, trace) = solve_doherty_traced(&p, &DohertyParams::default(), &SolveOptions::default()).unwrap();
        assert_eq!(r.solution.cost, 11.0);
        assert_eq!(trace.len(), 1);
        assert_eq!(trace[0].seed_cost, 11.0);
    }

    /// On random point sets the depth-first phase sometimes improves on the best seed's
    /// nearest-neighbour path, and the phases never make it worse.
    #[test]
    fn depth_and_breadth_phases_improve_on_nearest_neighbour() {
        use rand::{Rng, SeedableRng};
        let mut improved = 0;
        for seed in 0..60u64 {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            let n = 12;
            let pts: Vec<(f64, f64)> = (0..n).map(|_| (rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0))).collect();
            let m =
                MatrixCost::from_fn(n, |i, j| ((pts[i].0 - pts[j].0).powi(2) + (pts[i].1 - pts[j].1).powi(2)).sqrt());
            let mut b = Problem::builder(m);
            b.point_tasks(n);
            b.end(End::Free);
            let p = b.build().unwrap();
            let (r, t) = solve_doherty_traced(&p, &DohertyParams::default(), &SolveOptions::default()).unwrap();
            assert!(t[0].depth_first_cost <= t[0].seed_cost && t[0].cost <= t[0].depth_first_cost);
            assert!((r.solution.cost - t[0].cost).abs() < 1e-9);
            if t[0].cost < t[0].seed_cost - 1e-9 {
                improved += 1;
            }
        }
        assert!(improved >= 4, "the local search improved only {improved} of 60 instances");
    }

    #[test]
    fn sets_are_layers_and_are_validated() {
        let m = MatrixCost::from_fn(4, |i, j| (i as f64 - j as f64).abs());
        let mut b = Problem::builder(m);
        b.point_tasks(4);
        b.precede(TaskId(0), TaskId(2)).precede(TaskId(2), TaskId(3)).precede(TaskId(1), TaskId(3));
        b.end(End::Free);
        let p = b.build().unwrap();
        let sets = sets_from_precedence(&p);
        let got: Vec<Vec<u32>> = sets.iter().map(|s| s.tasks.iter().map(|t| t.0).collect()).collect();
        assert_eq!(got, vec![vec![0, 1], vec![2], vec![3]]);
        let bad = vec![
            PrecedenceSet { tasks: vec![TaskId(0), TaskId(2)], plies: 1 },
            PrecedenceSet { tasks: vec![TaskId(1), TaskId(3)], plies: 1 },
        ];
        let params = DohertyParams { sets: Some(bad), ..DohertyParams::default() };
        assert!(matches!(solve_doherty(&p, &params, &SolveOptions::default()), Err(BaselineError::BadSets(_))));
        let missing = vec![PrecedenceSet { tasks: vec![TaskId(0)], plies: 1 }];
        let params = DohertyParams { sets: Some(missing), ..DohertyParams::default() };
        assert!(matches!(solve_doherty(&p, &params, &SolveOptions::default()), Err(BaselineError::BadSets(_))));
    }
}
