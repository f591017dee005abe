//! Two-way tasks solved as a symmetric tour over their **ends**. A task that can be done either
//! way (two modes, the second the first backwards at the same cost: a stroke, a course, a spray
//! pass) becomes two nodes, one per end, joined by a *fixed edge* that every route uses; a task
//! with one mode that starts and ends in the same state stays one node. The route's start and
//! end become nodes too, so the problem is a closed, plain symmetric tour of points: the form
//! on which towpath's strongest search runs (Lin–Kernighan chains of sequential 3-opt moves,
//! double-bridge kicks, quadrant or α candidates, tour merging). A fixed edge costs −M, M far
//! above any transition, so no improving move removes one; the kicks never cut one, every
//! candidate list holds the node's partner, and constructed starts keep partners together.
//! This is the fixed-edge transformation LKH uses for such problems (Helsgaun 2017, LKH-3's
//! `FIXED_EDGES`); a 3-opt move on the ends is a move of whole tasks in which the tasks it turns
//! round change mode, which the task-level search can only do with 2-opt chains.
//!
//! Applies to problems without precedence, groups or pinned tasks whose cost model is symmetric
//! and whose every task has one self-reversing mode (a point) or exactly two modes that are
//! each other's reverse (entry and exit swapped, equal cost), with at least one such pair.

use std::sync::Arc;
use std::time::Instant;

use crate::cost::{Cost, CostModel, PlanarEuclid, StateId};
use crate::model::{End, Mode, Problem, TaskId};
use crate::solution::{check, Solution, Step};

use super::net::Net;
use super::tour::Tour;
use super::{solve_inner, Progress, ProgressFn, SolveError, SolveOptions, SolveReport};

/// No node.
pub(crate) const NONE: u32 = u32::MAX;

/// How a task of the original problem maps to end nodes.
#[derive(Clone, Copy)]
enum Shape {
    /// One node (a point task).
    Point(u32),
    /// Two nodes: the end where mode 0 enters, the end where it leaves.
    Pair(u32, u32),
}

/// Whether [`solve`] applies to the problem (see the module documentation).
pub(crate) fn applies<C: CostModel>(p: &Problem<C>) -> bool {
    if !p.cost_model().is_symmetric()
        || p.precedence().num_edges() > 0
        || !p.groups().is_empty()
        || p.first_task().is_some()
        || p.last_task().is_some()
        || p.num_tasks() < 2
    {
        return false;
    }
    let mut pairs = 0usize;
    for t in p.tasks() {
        match p.modes(t) {
            [m] if m.entry == m.exit => {}
            [a, b] if a.entry != a.exit && b.entry == a.exit && b.exit == a.entry && a.cost == b.cost => pairs += 1,
            _ => return false,
        }
    }
    pairs > 0
}

/// The cost model of the end nodes: the original cost between the nodes' states, −M on a fixed
/// edge, 0 to and from the dummy node that cuts the tour open.
pub(crate) struct EndCost<'a, C> {
    inner: &'a C,
    /// The original state of each node; `None` for the dummy.
    state: Vec<Option<StateId>>,
    partner: Vec<u32>,
    /// The price −M of a fixed edge, as the positive M.
    m: Cost,
    /// Where the dummy sits for spatial candidate lists (the centroid of the other nodes).
    dummy_at: Option<[f64; 3]>,
    /// When the original costs are plane distances ([`CostModel::planar_euclid`]): each node's
    /// point, NaN for the dummy, so that pricing an arc reads no state and calls no model.
    planar: Option<PlanarEuclid>,
}

impl<'a, C: CostModel> EndCost<'a, C> {
    fn new(inner: &'a C, state: Vec<Option<StateId>>, partner: Vec<u32>, m: Cost, dummy_at: Option<[f64; 3]>) -> Self {
        let planar = inner.planar_euclid().and_then(|pl| {
            let xy = state
                .iter()
                .map(|s| match s {
                    Some(s) => pl.xy.get(s.index()).copied(),
                    None => Some([f64::NAN; 2]),
                })
                .collect::<Option<Vec<_>>>()?;
            Some(PlanarEuclid { xy, rounding: pl.rounding })
        });
        EndCost { inner, state, partner, m, dummy_at, planar }
    }
}

impl<C: CostModel> CostModel for EndCost<'_, C> {
    fn num_states(&self) -> usize {
        self.state.len()
    }

    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        if self.partner[from.index()] == to.0 {
            return -self.m;
        }
        if let Some(pl) = &self.planar {
            // NaN only to or from the dummy: the real points are finite
            let c = pl.cost(from.index(), to.index());
            return if c.is_nan() { 0.0 } else { c };
        }
        match (self.state[from.index()], self.state[to.index()]) {
            (Some(a), Some(b)) => self.inner.cost(a, b),
            _ => 0.0,
        }
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        match self.state[state.index()] {
            Some(s) => self.inner.position(s),
            None => self.dummy_at,
        }
    }

    fn cost_bound(&self) -> Option<Cost> {
        self.inner.cost_bound().map(|b| b.max(self.m))
    }
}

/// The transformed problem and how to read its routes back.
struct Ends<'a, C> {
    problem: Problem<EndCost<'a, C>>,
    shapes: Vec<Shape>,
    /// Task of each node (`NONE` for the start, end and dummy nodes).
    task_of: Vec<u32>,
    /// The node the route leaves from (start, else the dummy) and the node it ends at (the
    /// fixed partner of the head, or the end node), if any.
    head: u32,
    tail: u32,
    /// Original cost = transformed cost + `offset` on a route that keeps every fixed edge.
    offset: Cost,
}

impl<'a, C: CostModel> Ends<'a, C> {
    fn build(p: &'a Problem<C>) -> Option<Self> {
        let cm = p.cost_model();
        let mut state: Vec<Option<StateId>> = Vec::new();
        let mut partner: Vec<u32> = Vec::new();
        let mut task_of: Vec<u32> = Vec::new();
        let mut shapes = Vec::with_capacity(p.num_tasks());
        let mut offset = 0.0;
        let mut push = |s: Option<StateId>, t: u32, state: &mut Vec<Option<StateId>>| {
            state.push(s);
            partner.push(NONE);
            task_of.push(t);
            state.len() as u32 - 1
        };
        for t in p.tasks() {
            let ms = p.modes(t);
            offset += ms[0].cost;
            if ms.len() == 1 {
                shapes.push(Shape::Point(push(Some(ms[0].entry), t.0, &mut state)));
            } else {
                let a = push(Some(ms[0].entry), t.0, &mut state);
                let b = push(Some(ms[0].exit), t.0, &mut state);
                shapes.push(Shape::Pair(a, b));
            }
        }
        let start = p.start().map(|s| push(Some(s), NONE, &mut state));
        let (head, tail) = match (start, p.end()) {
            (Some(s), End::Free) => (s, push(None, NONE, &mut state)),
            (Some(s), End::At(e)) => (s, push(Some(e), NONE, &mut state)),
            (Some(s), End::Closed) => (s, NONE),
            (None, End::Free) => (push(None, NONE, &mut state), NONE),
            (None, End::At(e)) => {
                let d = push(None, NONE, &mut state);
                (d, push(Some(e), NONE, &mut state))
            }
            (None, End::Closed) => (NONE, NONE),
        };
        let mut fixed: Vec<(u32, u32)> =
            shapes.iter().filter_map(|s| if let Shape::Pair(a, b) = *s { Some((a, b)) } else { None }).collect();
        if head != NONE && tail != NONE {
            fixed.push((head, tail));
        }
        for &(a, b) in &fixed {
            partner[a as usize] = b;
            partner[b as usize] = a;
        }
        let m = 4.0 * transition_bound(cm, &state)? + 1.0;
        offset += m * fixed.len() as Cost;
        let dummy_at = centroid(cm, &state);
        let cost = EndCost::new(cm, state, partner, m, dummy_at);
        let nodes = cost.num_states() as u32;
        let mut b = Problem::builder(cost);
        for v in 0..nodes {
            b.task(vec![Mode::point(StateId(v))]);
        }
        let problem = b.build().ok()?;
        Some(Ends { problem, shapes, task_of, head, tail, offset })
    }

    fn partner(&self, v: u32) -> u32 {
        self.problem.cost_model().partner[v as usize]
    }

    /// The transformed route of an original one.
    fn to_ends(&self, steps: &[Step]) -> Vec<Step> {
        let mut seq = Vec::with_capacity(self.task_of.len());
        if self.head != NONE {
            seq.push(self.head);
        }
        for s in steps {
            match self.shapes[s.task.index()] {
                Shape::Point(v) => seq.push(v),
                Shape::Pair(a, b) if s.mode == 0 => seq.extend([a, b]),
                Shape::Pair(a, b) => seq.extend([b, a]),
            }
        }
        if self.tail != NONE {
            seq.push(self.tail);
        }
        seq.into_iter().map(|v| Step { task: TaskId(v), mode: 0 }).collect()
    }

    /// The original route of a transformed one, and whether it kept every fixed edge. A task
    /// whose ends came apart is done from the end met first (the route stays valid).
    fn route_of_ends(&self, steps: &[Step]) -> (Vec<Step>, bool) {
        let mut seq: Vec<u32> = steps.iter().map(|s| s.task.0).collect();
        let n = seq.len();
        let mut intact = true;
        if self.head != NONE {
            if let Some(h) = seq.iter().position(|&v| v == self.head) {
                seq.rotate_left(h);
            }
            // leave the head away from its tail
            if self.tail != NONE && n > 2 && seq[1] == self.tail {
                seq[1..].reverse();
            }
            if self.tail != NONE && seq[n - 1] != self.tail {
                intact = false;
            }
        } else if n > 1 && self.partner(seq[0]) == seq[n - 1] {
            // a closed tour that wraps inside a task
            seq.rotate_right(1);
        }
        let mut done = vec![false; self.shapes.len()];
        let mut out = Vec::with_capacity(self.shapes.len());
        let mut i = 0;
        while i < n {
            let v = seq[i];
            i += 1;
            let t = self.task_of[v as usize];
            if t == NONE || done[t as usize] {
                continue;
            }
            done[t as usize] = true;
            let mode = match self.shapes[t as usize] {
                Shape::Point(_) => 0,
                Shape::Pair(a, b) => {
                    let other = if v == a { b } else { a };
                    if seq.get(i) == Some(&other) {
                        i += 1;
                    } else {
                        intact = false;
                    }
                    u32::from(v != a)
                }
            };
            out.push(Step { task: TaskId(t), mode });
        }
        (out, intact)
    }
}

/// A bound on the magnitude of every transition between the nodes' states: the cost model's
/// own, else the largest of the costs between every node and a few others, doubled. `None` when
/// no finite cost is seen.
fn transition_bound<C: CostModel>(cm: &C, state: &[Option<StateId>]) -> Option<Cost> {
    if let Some(b) = cm.cost_bound() {
        return (b.is_finite()).then_some(b.max(1e-9));
    }
    let states: Vec<StateId> = state.iter().flatten().copied().collect();
    let n = states.len();
    let mut max: Cost = 0.0;
    for (i, &a) in states.iter().enumerate() {
        for k in 1..=16usize.min(n.saturating_sub(1)) {
            let c = cm.cost(a, states[(i + k * 7919) % n]);
            if c.is_finite() {
                max = max.max(c.abs());
            }
        }
    }
    (max > 0.0).then_some(2.0 * max)
}

/// The centroid of the nodes' positions, if every state has one.
fn centroid<C: CostModel>(cm: &C, state: &[Option<StateId>]) -> Option<[f64; 3]> {
    let mut sum = [0.0; 3];
    let mut count = 0.0;
    for s in state.iter().flatten() {
        let p = cm.position(*s)?;
        for k in 0..3 {
            sum[k] += p[k];
        }
        count += 1.0;
    }
    (count > 0.0).then(|| sum.map(|x| x / count))
}

/// A tour with every node's fixed partner (see [`Net::partner`]) right after it, where it was
/// not already beside it: the nodes keep their order otherwise. Constructed starts pass through
/// it, as they know nothing of fixed edges.
pub(crate) fn keep_partners<C: CostModel>(net: &Net<C>, tour: &Tour) -> Tour {
    let mut placed = vec![false; net.n];
    let mut seq = Vec::with_capacity(net.n);
    for (i, &v) in tour.seq.iter().enumerate() {
        if placed[v as usize] {
            continue;
        }
        let p = net.partner[v as usize];
        let prev = if i == 0 { tour.seq[net.n - 1] } else { tour.seq[i - 1] };
        seq.push(v);
        placed[v as usize] = true;
        // a partner just before position 0 stays there (the pair wraps round the tour's end)
        if p != NONE && !placed[p as usize] && !(i == 0 && prev == p) {
            seq.push(p);
            placed[p as usize] = true;
        }
    }
    Tour::new(net, seq, vec![0; net.n])
}

/// Solves a problem [`applies`] to through its ends; `None` when the transformed problem cannot
/// be built (its costs would exceed what towpath adds up), so the caller searches the tasks.
pub(crate) fn solve<C: CostModel>(
    problem: &Problem<C>,
    opts: &SolveOptions,
    t0: Instant,
    initial_cost: Option<Cost>,
) -> Option<Result<SolveReport, SolveError>> {
    let ends = Ends::build(problem)?;
    let mut topts = opts.clone();
    topts.time_limit = opts.time_limit.map(|tl| tl.saturating_sub(t0.elapsed()));
    topts.initial = opts.initial.as_ref().map(|s| ends.to_ends(s));
    let offset = ends.offset;
    topts.progress = opts.progress.clone().map(|cb| -> ProgressFn {
        Arc::new(move |p: &Progress| cb(&Progress { best_cost: p.best_cost + offset, ..p.clone() }))
    });
    let partner = ends.problem.cost_model().partner.clone();
    let report = match solve_inner(&ends.problem, &topts, partner) {
        Ok(r) => r,
        Err(e) => return Some(Err(e)),
    };
    let (steps, intact) = ends.route_of_ends(&report.solution.steps);
    let cost = match check(problem, &steps) {
        Ok(c) => c,
        Err(v) => return Some(Err(SolveError::NoFeasibleRoute(v))),
    };
    let mut solution = Solution { steps, cost };
    if let (Some(init), Some(ic)) = (&opts.initial, initial_cost) {
        if ic < solution.cost {
            solution = Solution { steps: init.clone(), cost: ic };
        }
    }
    Some(Ok(SolveReport {
        solution,
        initial_cost,
        first_local_optimum: report.first_local_optimum + offset,
        iterations: report.iterations,
        elapsed: t0.elapsed(),
        search_elapsed: report.search_elapsed,
        exact: report.exact && intact,
        lower_bound: report.lower_bound.map(|b| b + offset),
    }))
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{Metric, PointCost};
    use crate::exact::solve_exact;

    /// With plane points the end nodes' costs are computed from each node's own point; they
    /// equal, bit for bit, the costs read through the nodes' states (fixed edges at −M, the
    /// dummy at 0), for every start and end kind.
    #[test]
    fn planar_end_costs_equal_the_state_costs() {
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        for (start, end) in [(true, 0), (false, 0), (true, 2), (false, 2), (true, 1), (false, 1)] {
            let p = problem(&mut rng, 12, 3, start, end);
            let ends = Ends::build(&p).expect("two-way tasks");
            let cm = ends.problem.cost_model();
            assert!(cm.planar.is_some(), "plane points under a Euclidean metric");
            let n = cm.num_states() as u32;
            for a in 0..n {
                for b in 0..n {
                    let want = if cm.partner[a as usize] == b {
                        -cm.m
                    } else {
                        match (cm.state[a as usize], cm.state[b as usize]) {
                            (Some(x), Some(y)) => p.cost_model().cost(x, y),
                            _ => 0.0,
                        }
                    };
                    let got = cm.cost(StateId(a), StateId(b));
                    assert_eq!(got.to_bits(), want.to_bits(), "start {start} end {end}: {a} -> {b}");
                }
            }
        }
    }

    /// `strokes` two-way tasks and `points` point tasks at random in a 100 × 100 square, with
    /// the given start and end.
    fn problem(rng: &mut Pcg64Mcg, strokes: usize, points: usize, start: bool, end: u8) -> Problem<PointCost> {
        let mut pts: Vec<[f64; 3]> = Vec::new();
        let at = |rng: &mut Pcg64Mcg, pts: &mut Vec<[f64; 3]>| {
            pts.push([rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0), 0.0]);
            StateId(pts.len() as u32 - 1)
        };
        let mut tasks = Vec::new();
        for _ in 0..strokes {
            let (a, b) = (at(rng, &mut pts), at(rng, &mut pts));
            tasks.push(vec![Mode { entry: a, exit: b, cost: 3.0 }, Mode { entry: b, exit: a, cost: 3.0 }]);
        }
        for _ in 0..points {
            tasks.push(vec![Mode::point(at(rng, &mut pts))]);
        }
        let s = start.then(|| at(rng, &mut pts));
        let e = (end == 2).then(|| at(rng, &mut pts));
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in tasks {
            b.task(t);
        }
        if let Some(s) = s {
            b.start(s);
        }
        b.end(match (end, e) {
            (0, _) => End::Free,
            (2, Some(e)) => End::At(e),
            _ => End::Closed,
        });
        b.build().expect("a valid problem")
    }

    fn budget(seed: u64) -> SolveOptions {
        SolveOptions { time_limit: None, iterations: Some(300), seed, threads: 1, exact_up_to: 0, ..Default::default() }
    }

    #[test]
    fn applies_only_to_two_way_tasks_without_precedence() {
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        assert!(applies(&problem(&mut rng, 3, 2, true, 0)));
        // points only: already a plain tour
        assert!(!applies(&problem(&mut rng, 0, 5, true, 0)));
        // a one-way task
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let mut b = Problem::builder(PointCost::new(pts.clone(), Metric::Euclidean));
        b.task(vec![Mode::new(StateId(0), StateId(1))]);
        b.task(vec![Mode::new(StateId(1), StateId(2)), Mode::new(StateId(2), StateId(1))]);
        assert!(!applies(&b.build().unwrap()));
        // modes of different costs
        let mut b = Problem::builder(PointCost::new(pts.clone(), Metric::Euclidean));
        b.task(vec![Mode::point(StateId(0))]);
        b.task(vec![Mode { entry: StateId(1), exit: StateId(2), cost: 1.0 }, Mode::new(StateId(2), StateId(1))]);
        assert!(!applies(&b.build().unwrap()));
        // precedence
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        b.task(vec![Mode::point(StateId(0))]);
        b.task(vec![Mode::new(StateId(1), StateId(2)), Mode::new(StateId(2), StateId(1))]);
        b.precede(TaskId(0), TaskId(1));
        b.start(StateId(0));
        b.end(End::Free);
        assert!(!applies(&b.build().unwrap()));
    }

    #[test]
    fn routes_read_back_through_the_ends_are_the_same_routes() {
        let mut rng = Pcg64Mcg::seed_from_u64(2);
        for case in 0..30u64 {
            let p = problem(&mut rng, 5, 2, case % 2 == 0, (case % 3) as u8);
            let ends = Ends::build(&p).expect("buildable");
            let mut order: Vec<u32> = (0..7).collect();
            for i in (1..7).rev() {
                order.swap(i, rng.gen_range(0..=i));
            }
            let steps: Vec<Step> = order
                .iter()
                .map(|&t| Step { task: TaskId(t), mode: if t < 5 { rng.gen_range(0..2) } else { 0 } })
                .collect();
            let tsteps = ends.to_ends(&steps);
            let (back, intact) = ends.route_of_ends(&tsteps);
            assert!(intact);
            assert_eq!(back, steps);
            // the two problems' costs differ by the offset
            let c = check(&p, &steps).unwrap();
            let tc = check(&ends.problem, &tsteps).unwrap();
            assert!((tc + ends.offset - c).abs() < 1e-6 * c.abs().max(1.0), "{tc} + {} vs {c}", ends.offset);
            // any rotation or reversal of the closed tour reads back to the same cost
            let mut turned = tsteps.clone();
            turned.reverse();
            let len = turned.len();
            turned.rotate_left(case as usize % len);
            let (back, intact) = ends.route_of_ends(&turned);
            assert!(intact);
            assert!((check(&p, &back).unwrap() - c).abs() < 1e-6 * c.abs().max(1.0));
        }
    }

    #[test]
    fn a_tour_that_splits_a_task_still_reads_back_to_a_valid_route() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let p = problem(&mut rng, 4, 0, true, 0);
        let ends = Ends::build(&p).expect("buildable");
        // head 8 (start), then the ends of tasks 0..3 with task 1's ends apart, then the tail 9
        let seq = [8u32, 0, 1, 2, 4, 5, 3, 6, 7, 9];
        let tsteps: Vec<Step> = seq.iter().map(|&v| Step { task: TaskId(v), mode: 0 }).collect();
        let (back, intact) = ends.route_of_ends(&tsteps);
        assert!(!intact);
        assert_eq!(back.len(), 4);
        check(&p, &back).expect("a valid route");
    }

    #[test]
    fn the_search_on_the_ends_finds_the_exact_optimum_of_small_problems() {
        let mut rng = Pcg64Mcg::seed_from_u64(4);
        for case in 0..24u64 {
            let strokes = 3 + (case % 4) as usize;
            let p = problem(&mut rng, strokes, (case % 3) as usize, case % 2 == 0, (case / 2 % 3) as u8);
            assert!(applies(&p));
            let best = solve_exact(&p).unwrap().unwrap().cost;
            let r = crate::solve(&p, &budget(case)).unwrap();
            let c = check(&p, &r.solution.steps).unwrap();
            assert_eq!(c, r.solution.cost);
            assert!(c <= best + 1e-9 * best.max(1.0), "case {case}: {c} vs optimum {best}");
            // the same through the task-level search is never better
            let direct = crate::solve(&p, &SolveOptions { two_way_ends: false, ..budget(case) }).unwrap();
            assert!(direct.solution.cost >= best - 1e-9 * best.max(1.0));
        }
    }

    /// The Held–Karp bound through the ends (the fixed edges at −M, the offset added back) is
    /// a bound on the original routes: never above the exact optimum, and close below it.
    #[test]
    fn the_held_karp_bound_through_the_ends_is_below_the_optimum() {
        let mut rng = Pcg64Mcg::seed_from_u64(6);
        let mut ratios = Vec::new();
        for case in 0..24u64 {
            let strokes = 3 + (case % 4) as usize;
            let p = problem(&mut rng, strokes, (case % 3) as usize, case % 2 == 0, (case / 2 % 3) as u8);
            let best = solve_exact(&p).unwrap().unwrap().cost;
            let r = crate::solve(&p, &SolveOptions { held_karp_bound: true, ..budget(case) }).unwrap();
            let bound = r.lower_bound.expect("a bound through the ends");
            assert!(bound <= best + 1e-9 * best.max(1.0), "case {case}: bound {bound} above the optimum {best}");
            ratios.push(bound / best);
            // not asked for, not given
            assert_eq!(crate::solve(&p, &budget(case)).unwrap().lower_bound, None);
        }
        ratios.sort_by(f64::total_cmp);
        assert!(ratios[ratios.len() / 2] >= 0.9, "median bound/optimum {ratios:?}");
    }

    #[test]
    fn larger_problems_keep_every_fixed_edge_and_beat_the_task_level_search() {
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let (mut ends_total, mut direct_total) = (0.0, 0.0);
        for case in 0..6u64 {
            let p = problem(&mut rng, 150, 20, case % 2 == 0, (case % 3) as u8);
            let ends = Ends::build(&p).expect("buildable");
            let opts = SolveOptions { iterations: Some(3000), ..budget(case) };
            let partner = ends.problem.cost_model().partner.clone();
            let r = solve_inner(&ends.problem, &opts, partner).unwrap();
            let (steps, intact) = ends.route_of_ends(&r.solution.steps);
            assert!(intact, "case {case}: a fixed edge was cut");
            let c = check(&p, &steps).unwrap();
            assert!((r.solution.cost + ends.offset - c).abs() < 1e-6 * c);
            ends_total += c;
            direct_total += crate::solve(&p, &SolveOptions { two_way_ends: false, ..opts }).unwrap().solution.cost;
        }
        assert!(ends_total < direct_total, "{ends_total} vs {direct_total}");
    }
}
