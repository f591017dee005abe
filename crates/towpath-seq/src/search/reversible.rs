//! A fast search for small open routes over **reversible segments**: every task is one piece
//! of work that may be done either way (two modes, the second the first run backwards at the
//! same cost), transitions are symmetric, there is no precedence, and the route starts at an
//! optional home state and ends wherever its last task leaves the tool. Spray passes, plotter
//! strokes and raster lines are such problems; with a few hundred tasks the general solver's
//! machinery (candidate nets, epochs, threads) costs more than the search itself.
//!
//! The route is an array of tasks with a direction bit each, between a fixed home sentinel
//! (its arcs cost the transit from home, or nothing) and a fixed tail sentinel (every arc to it
//! costs nothing, as the route ends anywhere). Every arc between a task's exit and the next
//! task's entry is a free arc; the task's own segment is never cut. Transit costs come from a
//! dense matrix over the task ends and the two sentinels, built once.
//!
//! Moves (Johnson & McGeoch 1997, with each segment's direction carried along):
//! - **2-opt**: a stretch of tasks is reversed, every task in it then runs the other way (the
//!   costs inside are unchanged as transitions are symmetric); the new arc joins an end to one
//!   of its nearest ends;
//! - **flip**: one task runs the other way in place;
//! - **Or-opt**: a stretch of one to three tasks moves next to one of its ends' nearest ends,
//!   forwards or backwards;
//! - **runs**: a *run* is a stretch between two long arcs (longer than [`LONG_ARC`] times the
//!   mean nearest-end distance: one patch's raster, one cluster of strokes). At a long arc the
//!   run on either side moves as a whole by Or-opt, and the two runs meeting there are
//!   rearranged: each kept, reversed, *turned over* (every task the other way, the order kept:
//!   a raster entered from its other side, which changes only the run's outer arcs on a
//!   zigzag but no 2-opt or flip can reach) or reversed and turned over, in either order.
//!
//! Dirty ends sit in a queue (don't-look bits). The perturbation is a segment swap (two
//! adjacent stretches exchange places, each turned round or not, a double bridge): half the
//! kicks take two random stretches of up to [`KICK_SEGMENT`] tasks, half cut at three of the
//! route's dearest arcs. Each kick is followed by the local search from the changed arcs and
//! undone when the route got dearer (Martin, Otto & Felten 1991; Lourenço, Martin & Stützle
//! 2003). Deterministic under a work budget; single-threaded. Up to [`FULL_LISTS_UP_TO`] tasks
//! every end's neighbour list holds every other end (the gain criterion ends each scan early).
//! Up to [`BOUND_UP_TO`] tasks the search stops as soon as its route costs no more than a
//! minimum spanning tree over the tasks (a lower bound; often met by a single patch's raster).
//! Up to [`PROOF_UP_TO`] tasks a branch and bound over such trees ([`super::tree_proof`]) is
//! tried before the local search: on a few patches' rasters it usually finds the optimum and
//! proves it in about one tree per task.

use std::collections::VecDeque;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::clock::Clock;
use crate::cost::{Cost, CostModel};
use crate::model::{End, Problem, TaskId};
use crate::solution::{check, Solution, Step};

use super::tree_proof::Trees;
use super::{solve, SolveError, SolveOptions, SolveReport};

/// Largest problem [`solve_reversible`] takes (a dense matrix over twice as many ends); larger
/// ones go to [`solve`].
pub const MAX_REVERSIBLE_TASKS: usize = 1500;

/// Nearest ends each end keeps.
const NEIGHBOURS: usize = 10;
/// Up to this many tasks every end keeps all other ends, sorted (the gain criterion then stops
/// each scan early, and moves between far clusters of tasks are seen too).
const FULL_LISTS_UP_TO: usize = 200;
/// Longest stretch an Or-opt move moves.
const OR_SEGMENT: usize = 3;
/// Up to this many tasks the search prices the spanning-tree lower bound ([`Dense::trees`])
/// and stops as soon as a route meets it (proven optimal).
const BOUND_UP_TO: usize = 200;
/// Largest plan the tree branch and bound ([`super::tree_proof`]) tries to solve exactly.
const PROOF_UP_TO: usize = 40;
/// It gives up when its first route is more than this fraction above its first tree.
const PROOF_GAP: f64 = 0.02;
/// Trees it may price, per task.
const PROOF_NODES_PER_TASK: usize = 2;
/// An arc longer than this many times the mean distance from an end to its nearest other end
/// ends a run of tasks (Or-opt moves whole runs).
const LONG_ARC: f64 = 2.5;
/// Longest stretch a kick moves.
const KICK_SEGMENT: usize = 30;
/// Kicks between looks at the clock.
const CLOCK_EVERY: u64 = 32;

/// Solves an open route over reversible segments (see the module docs) with the fast dense
/// search; a problem that is not of that kind (more than two modes, a mode that is not the
/// other run backwards, asymmetric costs, precedence, groups, a fixed first or last task, a
/// closed or fixed end, or more than [`MAX_REVERSIBLE_TASKS`] tasks) is passed to [`solve`].
///
/// Honours the time limit, the work budget (`iterations` kicks), `stall_epochs` (stop after
/// that many twentieths of the budget in a row without an improvement, but never before as
/// many kicks again as it took to find the best route), the seed, the cancel flag and the
/// initial route (the answer is never worse). Up to 200 tasks it stops as soon as the route
/// meets a lower bound (the minimum spanning tree over the tasks, each pair joined by their
/// nearest ends), and reports it `exact` (proven optimal); up to 40 tasks a branch and bound
/// over such trees first tries to find and prove the optimum within about two trees per task.
/// Runs on one thread whatever `threads` says.
pub fn solve_reversible<C: CostModel>(problem: &Problem<C>, opts: &SolveOptions) -> Result<SolveReport, SolveError> {
    if opts.threads > super::MAX_THREADS {
        return Err(SolveError::TooManyThreads { threads: opts.threads });
    }
    let clock = Clock::for_options(opts);
    let t0 = clock.started();
    let Some(mut search) = applies(problem).then(|| Dense::new(problem)).flatten() else {
        return solve(problem, opts);
    };
    let initial_cost = match &opts.initial {
        Some(steps) => Some(check(problem, steps).map_err(SolveError::BadInitial)?),
        None => None,
    };
    let eps = 1e-9 * search.typical.max(Cost::MIN_POSITIVE);
    let tol = 1e-9 * search.typical.max(Cost::MIN_POSITIVE) * search.n as f64;
    // A route that meets the bound needs no descent (a raster's nearest-neighbour route often
    // does). A small plan is then given to the tree branch and bound, which settles most plans of
    // a few patches' rasters in about one tree per task, for less than the descent and the kicks
    // would take; it gives up at once when its first route is far from its first tree.
    let mut route = search.nearest_neighbour();
    let mut settled = false;
    let bound = search.trees().map(|trees| {
        let b = trees.bound();
        if search.n <= PROOF_UP_TO && route.cost > b + tol {
            let proof = trees.prove(route.cost, tol, PROOF_GAP, PROOF_NODES_PER_TASK * search.n);
            if let Some((seq, dir)) = proof.better {
                let better = search.route(seq, dir);
                if better.cost < route.cost {
                    route = better;
                }
            }
            settled = proof.proven;
        }
        b
    });
    let proven = |c: Cost| bound.is_some_and(|b| c <= b + tol);
    if !settled && !proven(route.cost) {
        search.descend(&mut route, eps);
        if let Some(steps) = &opts.initial {
            let mut from = search.route_from_steps(steps);
            search.descend(&mut from, eps);
            if from.cost < route.cost - eps {
                route = from;
            }
        }
    }
    let first_local_optimum = route.cost;
    let budget = opts.iterations;
    let stall = match (budget, opts.stall_epochs) {
        (Some(b), Some(k)) => Some((b / 20).max(1) * k as u64),
        _ => None,
    };
    let mut rng = Pcg64Mcg::seed_from_u64(opts.seed);
    let mut kicks = 0u64;
    let mut since = 0u64;
    let mut trial = route.clone();
    // The kick that found the best route so far: the stall rule waits at least as long again.
    let mut found_at = 0u64;
    let search_start = std::time::Instant::now();
    while search.n >= 4
        && !settled
        && !proven(route.cost)
        && budget.is_none_or(|b| kicks < b)
        && stall.is_none_or(|s| since < s.max(found_at))
    {
        if kicks % CLOCK_EVERY == 0 && (clock.expired() || (budget.is_none() && clock.deadline().is_none())) {
            break;
        }
        kicks += 1;
        since += 1;
        trial.copy_from(&route);
        search.kick(&mut trial, &mut rng);
        search.drain(&mut trial, eps);
        if trial.cost <= route.cost + eps {
            if trial.cost < route.cost - eps {
                since = 0;
                found_at = kicks;
            }
            std::mem::swap(&mut route, &mut trial);
        }
    }
    let steps: Vec<Step> =
        route.seq.iter().map(|&t| Step { task: TaskId(t), mode: u32::from(route.dir[t as usize]) }).collect();
    let cost = check(problem, &steps).map_err(SolveError::NoFeasibleRoute)?;
    let exact = settled || proven(route.cost);
    // The bound prices transitions like the route; the checked cost adds the passes' own.
    let lower_bound = if exact { Some(cost) } else { bound.map(|b| b + (cost - route.cost)) };
    let mut solution = Solution { steps, cost };
    if let (Some(init), Some(ic)) = (&opts.initial, initial_cost) {
        if ic < solution.cost {
            solution = Solution { steps: init.clone(), cost: ic };
        }
    }
    let lower_bound = lower_bound.map(|b| b.min(solution.cost));
    Ok(SolveReport {
        solution,
        initial_cost,
        first_local_optimum,
        iterations: kicks,
        elapsed: t0.elapsed(),
        search_elapsed: search_start.elapsed(),
        exact,
        lower_bound,
    })
}

/// True when the problem is an open route over reversible segments the dense search takes.
fn applies<C: CostModel>(problem: &Problem<C>) -> bool {
    let n = problem.num_tasks();
    if n == 0 || n > MAX_REVERSIBLE_TASKS || !problem.cost_model().is_symmetric() {
        return false;
    }
    if problem.end() != End::Free
        || problem.precedence().num_edges() > 0
        || !problem.groups().is_empty()
        || problem.first_task().is_some()
        || problem.last_task().is_some()
    {
        return false;
    }
    problem.tasks().all(|t| match problem.modes(t) {
        [a, b] => a.entry == b.exit && a.exit == b.entry && a.cost == b.cost && a.cost.is_finite(),
        _ => false,
    })
}

/// An integer key in the order of [`f64::total_cmp`].
fn order_key(c: Cost) -> u64 {
    let b = c.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// Length of each end's neighbour list.
fn list_len(n: usize) -> usize {
    if n <= FULL_LISTS_UP_TO {
        2 * n - 2
    } else {
        NEIGHBOURS.min(2 * n - 2)
    }
}

/// A move of the runs on either side of a long arc (see [`Dense::best_run_pair`]): run A is
/// positions `sa ..= gap`, run B `gap + 1 ..= tb` (1-based; either may be empty); each is done
/// one of four ways (0 as is, 1 reversed, 2 turned over, 3 reversed and turned over).
#[derive(Clone, Copy, Debug)]
struct RunPair {
    delta: Cost,
    sa: usize,
    gap: usize,
    tb: usize,
    way_a: u8,
    way_b: u8,
    b_first: bool,
}

/// A route: tasks by position (0-based), each task's direction (true: run backwards, mode 1),
/// each task's position, and the transit cost.
#[derive(Clone, Debug)]
struct Route {
    seq: Vec<u32>,
    dir: Vec<bool>,
    pos: Vec<u32>,
    cost: Cost,
}

impl Route {
    fn copy_from(&mut self, other: &Route) {
        self.seq.copy_from_slice(&other.seq);
        self.dir.copy_from_slice(&other.dir);
        self.pos.copy_from_slice(&other.pos);
        self.cost = other.cost;
    }
}

/// The dense instance and the local search's scratch.
struct Dense {
    n: usize,
    /// Side of the matrix: the 2n task ends (end 2t is where mode 0 of task t enters, 2t+1
    /// where it leaves), then home, then tail.
    m: usize,
    d: Vec<Cost>,
    nb: Vec<u32>,
    /// The route starts at a home state (else the home sentinel's arcs cost nothing).
    has_home: bool,
    typical: Cost,
    /// Arcs dearer than this end a run (see [`LONG_ARC`]).
    long: Cost,
    queue: VecDeque<u32>,
    queued: Vec<bool>,
    /// Scratch: the route's arcs (cost, gap) for the kicks' cut points.
    gaps: Vec<(Cost, u32)>,
}

impl Dense {
    /// The dense instance, or `None` when a transit cost is not finite (a forbidden move: the
    /// general solver handles those).
    fn new<C: CostModel>(problem: &Problem<C>) -> Option<Dense> {
        let n = problem.num_tasks();
        let m = 2 * n + 2;
        let state: Vec<_> = problem
            .tasks()
            .flat_map(|t| {
                let md = problem.modes(t)[0];
                [md.entry, md.exit]
            })
            .collect();
        let cm = problem.cost_model();
        let mut d = vec![0.0; m * m];
        for u in 0..2 * n {
            for v in u + 1..2 * n {
                let c = cm.cost(state[u], state[v]);
                if !c.is_finite() {
                    return None;
                }
                d[u * m + v] = c;
                d[v * m + u] = c;
            }
        }
        let home = 2 * n;
        if let Some(h) = problem.start() {
            for v in 0..2 * n {
                let c = cm.cost(h, state[v]);
                if !c.is_finite() {
                    return None;
                }
                d[home * m + v] = c;
                d[v * m + home] = c;
            }
        }
        // Mean distance from an end to its nearest other end (not its own task's other end).
        let mut sum = 0.0;
        let mut count = 0usize;
        for u in 0..2 * n {
            let near = (0..2 * n).filter(|&v| v != u && v != (u ^ 1)).map(|v| d[u * m + v]).reduce(Cost::min);
            if let Some(c) = near {
                sum += c;
                count += 1;
            }
        }
        let typical = if count > 0 { sum / count as f64 } else { 1.0 };
        Some(Dense {
            n,
            m,
            d,
            nb: Vec::new(),
            has_home: problem.start().is_some(),
            typical,
            long: LONG_ARC * typical,
            queue: VecDeque::new(),
            queued: vec![false; 2 * n + 2],
            gaps: Vec::new(),
        })
    }

    /// Each end's nearest ends (not its own task's other end), nearest first; built when the
    /// local search first needs them (a route proven optimal before that never does).
    fn build_lists(&mut self) {
        let n = self.n;
        let k = list_len(n);
        let mut nb = vec![0u32; 2 * n * k];
        let (d, m) = (&self.d, self.m);
        let mut cand: Vec<(Cost, u32)> = Vec::with_capacity(2 * n);
        let mut keys: Vec<u128> = Vec::with_capacity(2 * n);
        for u in 0..2 * n {
            if k == 2 * n - 2 {
                // Every other end, by cost then number (the order a stable sort by cost gives),
                // sorted as integers: several times faster than comparing floats on small plans.
                keys.clear();
                keys.extend(
                    (0..2 * n)
                        .filter(|&v| v != u && v != (u ^ 1))
                        .map(|v| (u128::from(order_key(d[u * m + v])) << 32) | v as u128),
                );
                keys.sort_unstable();
                for (i, &key) in keys.iter().enumerate() {
                    nb[u * k + i] = key as u32;
                }
                continue;
            }
            cand.clear();
            cand.extend((0..2 * n).filter(|&v| v != u && v != (u ^ 1)).map(|v| (d[u * m + v], v as u32)));
            if k > 0 && cand.len() > k {
                cand.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
            }
            cand.truncate(k);
            cand.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (i, &(_, v)) in cand.iter().enumerate() {
                nb[u * k + i] = v;
            }
        }
        self.nb = nb;
    }

    #[inline]
    fn arc(&self, u: u32, v: u32) -> Cost {
        self.d[u as usize * self.m + v as usize]
    }

    fn home(&self) -> u32 {
        2 * self.n as u32
    }

    fn tail(&self) -> u32 {
        2 * self.n as u32 + 1
    }

    fn neighbours(&self, u: u32) -> &[u32] {
        let k = list_len(self.n);
        &self.nb[u as usize * k..(u as usize + 1) * k]
    }

    /// The end where the task at 1-based position `i` is entered (`n + 1`: the tail).
    #[inline]
    fn en(&self, r: &Route, i: usize) -> u32 {
        if i > self.n {
            return self.tail();
        }
        let t = r.seq[i - 1];
        2 * t + u32::from(r.dir[t as usize])
    }

    /// The end where the task at 1-based position `i` is left (0: home).
    #[inline]
    fn ex(&self, r: &Route, i: usize) -> u32 {
        if i == 0 {
            return self.home();
        }
        let t = r.seq[i - 1];
        2 * t + 1 - u32::from(r.dir[t as usize])
    }

    /// 1-based position of end `u`'s task, and whether `u` is its entry there.
    #[inline]
    fn place(&self, r: &Route, u: u32) -> (usize, bool) {
        let t = (u / 2) as usize;
        (r.pos[t] as usize + 1, (u & 1) == u32::from(r.dir[t]))
    }

    fn cost_of(&self, r: &Route) -> Cost {
        (0..=self.n).map(|i| self.arc(self.ex(r, i), self.en(r, i + 1))).sum()
    }

    /// The spanning trees over the tasks ([`Trees`]), up to [`BOUND_UP_TO`] tasks: a route is a
    /// path through home (if any) and every task, so a spanning tree over them, and none is
    /// cheaper than the minimum spanning tree whose edge between two tasks costs the cheapest
    /// arc between their ends ([`Trees::bound`]). A single patch's raster, whose turns join each
    /// pass to its nearest neighbour's near end, meets it: the search can stop there. (Held–Karp
    /// penalties on the tree's degrees, tried on the four-patch cylinder section of the spray
    /// benchmark, raised its bound only from 0.20 % to 0.17 % under the optimum in 40 steps;
    /// the branch and bound of [`Trees::prove`] settles it.)
    fn trees(&self) -> Option<Trees<'_>> {
        (self.n <= BOUND_UP_TO).then(|| Trees::new(&self.d, self.m, self.n, self.has_home))
    }

    fn nearest_neighbour(&self) -> Route {
        let n = self.n;
        let mut used = vec![false; n];
        let mut seq = Vec::with_capacity(n);
        let mut dir = vec![false; n];
        let mut cur = self.home();
        for _ in 0..n {
            let mut best = (Cost::INFINITY, u32::MAX);
            for v in 0..2 * n as u32 {
                if !used[(v / 2) as usize] {
                    let c = self.arc(cur, v);
                    if c < best.0 || best.1 == u32::MAX {
                        best = (c, v);
                    }
                }
            }
            let v = best.1;
            let t = v / 2;
            used[t as usize] = true;
            dir[t as usize] = v & 1 == 1;
            seq.push(t);
            cur = v ^ 1;
        }
        self.route(seq, dir)
    }

    fn route_from_steps(&self, steps: &[Step]) -> Route {
        let mut dir = vec![false; self.n];
        let seq = steps
            .iter()
            .map(|s| {
                dir[s.task.index()] = s.mode == 1;
                s.task.0
            })
            .collect();
        self.route(seq, dir)
    }

    fn route(&self, seq: Vec<u32>, dir: Vec<bool>) -> Route {
        let mut pos = vec![0u32; self.n];
        for (i, &t) in seq.iter().enumerate() {
            pos[t as usize] = i as u32;
        }
        let mut r = Route { seq, dir, pos, cost: 0.0 };
        r.cost = self.cost_of(&r);
        r
    }

    fn push(&mut self, u: u32) {
        if (u as usize) < 2 * self.n && !self.queued[u as usize] {
            self.queued[u as usize] = true;
            self.queue.push_back(u);
        }
    }

    /// Local search until no move from a queued end improves (every end queued first).
    fn descend(&mut self, r: &mut Route, eps: Cost) {
        for u in 0..2 * self.n as u32 {
            self.push(u);
        }
        self.drain(r, eps);
    }

    fn drain(&mut self, r: &mut Route, eps: Cost) {
        if self.nb.is_empty() {
            self.build_lists();
        }
        while let Some(u) = self.queue.pop_front() {
            self.queued[u as usize] = false;
            while self.improve(r, u, eps) {}
        }
    }

    /// Tries the moves around end `u`; applies the first that gains and queues its ends.
    fn improve(&mut self, r: &mut Route, u: u32, eps: Cost) -> bool {
        let (i, entry) = self.place(r, u);
        // Flip the task in place.
        {
            let (a, b) = (self.ex(r, i - 1), self.en(r, i + 1));
            let (e, x) = (self.en(r, i), self.ex(r, i));
            let delta = self.arc(a, x) + self.arc(e, b) - self.arc(a, e) - self.arc(x, b);
            if delta < -eps {
                self.two_opt(r, i - 1, i, delta);
                return true;
            }
        }
        // 2-opt: the new arc joins u to a near end of the same kind (both exits or both entries).
        let g1 = if entry { self.arc(self.ex(r, i - 1), u) } else { self.arc(u, self.en(r, i + 1)) };
        let extra = if entry { self.tail() } else { self.home() };
        for k in 0..=self.neighbours(u).len() {
            let c = if k == 0 { extra } else { self.neighbours(u)[k - 1] };
            let duc = self.arc(u, c);
            if duc >= g1 - eps && k > 0 {
                break;
            }
            let (j, c_entry) = if c == self.home() {
                (0, false)
            } else if c == self.tail() {
                (self.n + 1, true)
            } else {
                self.place(r, c)
            };
            if c_entry != entry || j == i {
                continue;
            }
            let (lo, hi) = if entry { (i.min(j) - 1, i.max(j) - 1) } else { (i.min(j), i.max(j)) };
            if lo >= hi {
                continue;
            }
            let delta = self.two_opt_delta(r, lo, hi);
            if delta < -eps {
                self.two_opt(r, lo, hi, delta);
                return true;
            }
        }
        // Or-opt: a stretch of one to three tasks beginning or ending with u's task moves next to
        // a near end of either of its ends.
        for len in 1..=OR_SEGMENT.min(self.n - 1) {
            let starts = [Some(i), if len > 1 && i >= len { Some(i + 1 - len) } else { None }];
            for s in starts.into_iter().flatten() {
                let t = s + len - 1;
                if t > self.n {
                    continue;
                }
                if let Some((delta, q0, rev)) = self.best_or(r, s, t, eps) {
                    self.or_move(r, s, t, q0, rev, delta);
                    return true;
                }
            }
        }
        // Or-opt of a run: when u's free arc is long, the tasks from u to the next long arc
        // (a patch's raster, a cluster of strokes) move as one.
        if let Some((s, t)) = self.run_at(r, i, entry) {
            if t + 1 - s > OR_SEGMENT && t + 1 - s < self.n {
                if let Some((delta, q0, rev)) = self.best_or(r, s, t, eps) {
                    self.or_move(r, s, t, q0, rev, delta);
                    return true;
                }
            }
        }
        // The runs on either side of u's long arc: each kept, reversed, turned over (every task
        // the other way, the order kept: a raster entered from its other side) or both, and the
        // two in either order.
        let gap = if entry { i - 1 } else { i };
        if self.arc(self.ex(r, gap), self.en(r, gap + 1)) > self.long {
            if let Some(mv) = self.best_run_pair(r, gap, eps) {
                self.apply_run_pair(r, mv);
                return true;
            }
        }
        false
    }

    /// The run that starts (u an entry) or ends (u an exit) at position `i` when u's free arc
    /// is long: up to the next long arc the other way.
    fn run_at(&self, r: &Route, i: usize, entry: bool) -> Option<(usize, usize)> {
        let long = self.long;
        if entry {
            if self.arc(self.ex(r, i - 1), self.en(r, i)) <= long {
                return None;
            }
            Some((i, self.run_last(r, i)))
        } else {
            if i >= self.n || self.arc(self.ex(r, i), self.en(r, i + 1)) <= long {
                return None;
            }
            Some((self.run_first(r, i), i))
        }
    }

    /// The first position of the run that position `i` (1-based) is in.
    fn run_first(&self, r: &Route, i: usize) -> usize {
        let mut s = i;
        while s > 1 && self.arc(self.ex(r, s - 1), self.en(r, s)) <= self.long {
            s -= 1;
        }
        s
    }

    /// The last position of the run that position `i` (1-based) is in.
    fn run_last(&self, r: &Route, i: usize) -> usize {
        let mut t = i;
        while t < self.n && self.arc(self.ex(r, t), self.en(r, t + 1)) <= self.long {
            t += 1;
        }
        t
    }

    /// The cost of the inner links of positions `s ..= t` (1-based) turned over, minus their
    /// cost now.
    fn turn_over_inner(&self, r: &Route, s: usize, t: usize) -> Cost {
        (s..t).map(|i| self.arc(self.en(r, i), self.ex(r, i + 1)) - self.arc(self.ex(r, i), self.en(r, i + 1))).sum()
    }

    /// The best rearrangement of the two runs meeting at long arc `gap` (one run when the gap
    /// is at home or the tail): each run in one of four ways (see [`RunPair`]), the pair in either
    /// order.
    fn best_run_pair(&self, r: &Route, gap: usize, eps: Cost) -> Option<RunPair> {
        // Run A ends at `gap` (empty at home), run B starts after it (empty at the tail).
        let sa = if gap >= 1 { self.run_first(r, gap) } else { gap + 1 };
        let tb = if gap < self.n { self.run_last(r, gap + 1) } else { gap };
        let (p, f) = (self.ex(r, sa - 1), self.en(r, tb + 1));
        let now = self.arc(p, self.en(r, sa))
            + self.arc(self.ex(r, tb), f)
            + if gap >= 1 && gap < self.n { self.arc(self.ex(r, gap), self.en(r, gap + 1)) } else { 0.0 };
        // (in, out, inner change) of a run [s..t] each way; an empty run passes through.
        let ways = |s: usize, t: usize| -> [(u32, u32, Cost); 4] {
            let d = self.turn_over_inner(r, s, t);
            [
                (self.en(r, s), self.ex(r, t), 0.0),
                (self.ex(r, t), self.en(r, s), 0.0),
                (self.ex(r, s), self.en(r, t), d),
                (self.en(r, t), self.ex(r, s), d),
            ]
        };
        let wa = (gap >= 1).then(|| ways(sa, gap));
        let wb = (gap < self.n).then(|| ways(gap + 1, tb));
        let mut best: Option<RunPair> = None;
        let mut consider = |delta: Cost, mv: RunPair| {
            if delta < -eps && best.is_none_or(|b| delta < b.delta) {
                best = Some(RunPair { delta, ..mv });
            }
        };
        let base = RunPair { delta: 0.0, sa, gap, tb, way_a: 0, way_b: 0, b_first: false };
        match (wa, wb) {
            (Some(wa), Some(wb)) => {
                for (ia, a) in wa.iter().enumerate() {
                    for (ib, b) in wb.iter().enumerate() {
                        let ab = self.arc(p, a.0) + self.arc(a.1, b.0) + self.arc(b.1, f) + a.2 + b.2;
                        let ba = self.arc(p, b.0) + self.arc(b.1, a.0) + self.arc(a.1, f) + a.2 + b.2;
                        let (wa8, wb8) = (ia as u8, ib as u8);
                        consider(ab - now, RunPair { way_a: wa8, way_b: wb8, b_first: false, ..base });
                        consider(ba - now, RunPair { way_a: wa8, way_b: wb8, b_first: true, ..base });
                    }
                }
            }
            (Some(w), None) | (None, Some(w)) => {
                for (iw, x) in w.iter().enumerate().skip(1) {
                    let c = self.arc(p, x.0) + self.arc(x.1, f) + x.2;
                    consider(c - now, RunPair { way_a: iw as u8, way_b: iw as u8, ..base });
                }
            }
            (None, None) => {}
        }
        best
    }

    /// Applies a [`RunPair`] move.
    fn apply_run_pair(&mut self, r: &mut Route, mv: RunPair) {
        let RunPair { delta, sa, gap, tb, way_a, way_b, b_first } = mv;
        let outer = [self.ex(r, sa - 1), self.en(r, tb + 1)];
        // 0-based: A = seq[sa-1..gap], B = seq[gap..tb].
        let (lo, mid, hi) = (sa - 1, gap, tb);
        let mut moved: Vec<(u32, bool)> = Vec::with_capacity(hi - lo);
        let (first, second) =
            if b_first { ((mid, hi, way_b), (lo, mid, way_a)) } else { ((lo, mid, way_a), (mid, hi, way_b)) };
        for (from, to, way) in [first, second] {
            let flipped = way == 1 || way == 2;
            let start = moved.len();
            moved.extend(r.seq[from..to].iter().map(|&t| (t, r.dir[t as usize] ^ flipped)));
            if way == 1 || way == 3 {
                moved[start..].reverse();
            }
        }
        for (k, &(t, d)) in moved.iter().enumerate() {
            r.seq[lo + k] = t;
            r.dir[t as usize] = d;
            r.pos[t as usize] = (lo + k) as u32;
        }
        r.cost += delta;
        for e in outer {
            self.push(e);
        }
        // Both ends of the tasks at the runs' ends (inner links of a run turned over changed
        // too, but stay the run's own).
        let junction = lo + (first.1 - first.0);
        for p in [lo, junction.saturating_sub(1).max(lo), junction.min(hi - 1), hi - 1] {
            let t = r.seq[p];
            self.push(2 * t);
            self.push(2 * t + 1);
        }
    }

    fn two_opt_delta(&self, r: &Route, lo: usize, hi: usize) -> Cost {
        let (a, b) = (self.ex(r, lo), self.en(r, lo + 1));
        let (c, d) = (self.ex(r, hi), self.en(r, hi + 1));
        self.arc(a, c) + self.arc(b, d) - self.arc(a, b) - self.arc(c, d)
    }

    /// Reverses 1-based positions `lo + 1 ..= hi` (each task there turns round).
    fn two_opt(&mut self, r: &mut Route, lo: usize, hi: usize, delta: Cost) {
        let ends = [self.ex(r, lo), self.en(r, lo + 1), self.ex(r, hi), self.en(r, hi + 1)];
        r.seq[lo..hi].reverse();
        for p in lo..hi {
            let t = r.seq[p] as usize;
            r.pos[t] = p as u32;
            r.dir[t] = !r.dir[t];
        }
        r.cost += delta;
        for e in ends {
            self.push(e);
        }
    }

    /// The best place for stretch `s ..= t` among the near ends of its two ends: (delta, the
    /// position it goes after, reversed).
    fn best_or(&self, r: &Route, s: usize, t: usize, eps: Cost) -> Option<(Cost, usize, bool)> {
        let (p, f) = (self.ex(r, s - 1), self.en(r, t + 1));
        let (e, x) = (self.en(r, s), self.ex(r, t));
        let removed = self.arc(p, e) + self.arc(x, f) - self.arc(p, f);
        let mut best: Option<(Cost, usize, bool)> = None;
        for (end, is_entry) in [(e, true), (x, false)] {
            for &c in self.neighbours(end) {
                if self.arc(end, c) >= removed - eps {
                    break;
                }
                let (q, c_entry) = self.place(r, c);
                // The gap (q0, q0 + 1) the stretch goes into, `end` next to `c`.
                let q0 = if c_entry { q - 1 } else { q };
                if q0 + 1 >= s && q0 <= t {
                    continue;
                }
                let (a, b) = (self.ex(r, q0), self.en(r, q0 + 1));
                // `end` next to c: an exit c is followed by the stretch's new entry.
                let rev = is_entry == c_entry;
                let added = if rev { self.arc(a, x) + self.arc(e, b) } else { self.arc(a, e) + self.arc(x, b) };
                let delta = added - self.arc(a, b) - removed;
                if delta < -eps && best.is_none_or(|bb| delta < bb.0) {
                    best = Some((delta, q0, rev));
                }
            }
        }
        best
    }

    /// Moves stretch `s ..= t` (1-based) into the gap after position `q0`, reversed or not.
    fn or_move(&mut self, r: &mut Route, s: usize, t: usize, q0: usize, rev: bool, delta: Cost) {
        let len = t + 1 - s;
        let ends = [self.ex(r, s - 1), self.en(r, t + 1), self.ex(r, q0), self.en(r, q0 + 1)];
        // 0-based slices: the stretch is seq[s-1..t].
        let (lo, hi, new_start) = if q0 < s {
            r.seq[q0..t].rotate_right(len);
            (q0, t, q0)
        } else {
            r.seq[s - 1..q0].rotate_left(len);
            (s - 1, q0, q0 - len)
        };
        if rev {
            r.seq[new_start..new_start + len].reverse();
            for p in new_start..new_start + len {
                let tk = r.seq[p] as usize;
                r.dir[tk] = !r.dir[tk];
            }
        }
        for p in lo..hi {
            r.pos[r.seq[p] as usize] = p as u32;
        }
        r.cost += delta;
        for e in ends {
            self.push(e);
        }
        for p in new_start..new_start + len {
            let tk = r.seq[p];
            self.push(2 * tk);
            self.push(2 * tk + 1);
        }
    }

    /// A segment swap: two adjacent stretches at a random position exchange places, each
    /// turned round or not at random; the ends of the changed arcs are queued.
    fn kick(&mut self, r: &mut Route, rng: &mut Pcg64Mcg) {
        let n = self.n;
        let (a, b, c) = if rng.gen::<bool>() {
            let most = KICK_SEGMENT.min(n / 2).max(1);
            let l1 = 1 + rng.gen_range(0..most);
            let l2 = 1 + rng.gen_range(0..most);
            if l1 + l2 > n {
                return;
            }
            let a = rng.gen_range(0..n - l1 - l2 + 1);
            (a, a + l1, a + l1 + l2)
        } else {
            // Cut at three of the route's dearest arcs (the route's end counts as one): whole
            // runs of tasks between long transits trade places.
            let k = (n / 8).max(4).min(n);
            let mut gaps = std::mem::take(&mut self.gaps);
            gaps.clear();
            gaps.extend((0..n).map(|g| (self.arc(self.ex(r, g), self.en(r, g + 1)), g as u32)));
            if gaps.len() > k {
                gaps.select_nth_unstable_by(k - 1, |x, y| y.0.total_cmp(&x.0));
                gaps.truncate(k);
            }
            gaps.push((0.0, n as u32));
            let m = gaps.len();
            let mut cuts = [0usize; 3];
            let i0 = rng.gen_range(0..m);
            let i1 = (i0 + 1 + rng.gen_range(0..m - 1)) % m;
            let mut i2 = rng.gen_range(0..m - 2);
            for lo in [i0.min(i1), i0.max(i1)] {
                if i2 >= lo {
                    i2 += 1;
                }
            }
            for (c, i) in cuts.iter_mut().zip([i0, i1, i2]) {
                *c = gaps[i].1 as usize;
            }
            self.gaps = gaps;
            cuts.sort_unstable();
            (cuts[0], cuts[1], cuts[2])
        };
        let turn: u8 = rng.gen_range(0..4);
        let delta = self.swap_delta(r, a, b, c, turn);
        self.swap(r, a, b, c, turn, delta);
    }

    /// The cost change of [`Dense::swap`].
    fn swap_delta(&self, r: &Route, a: usize, b: usize, c: usize, turn: u8) -> Cost {
        let (p, f) = (self.ex(r, a), self.en(r, c + 1));
        let (a_in, a_out) = (self.en(r, a + 1), self.ex(r, b));
        let (b_in, b_out) = (self.en(r, b + 1), self.ex(r, c));
        let (bi, bo) = if turn & 1 == 1 { (b_out, b_in) } else { (b_in, b_out) };
        let (ai, ao) = if turn & 2 == 2 { (a_out, a_in) } else { (a_in, a_out) };
        self.arc(p, bi) + self.arc(bo, ai) + self.arc(ao, f)
            - self.arc(p, a_in)
            - self.arc(a_out, b_in)
            - self.arc(b_out, f)
    }

    /// Segment swap: the stretches `seq[a..b]` and `seq[b..c]` (0-based) trade places, the one
    /// now first turned round when bit 0 of `turn` is set, the other when bit 1 is; the ends of
    /// the changed arcs are queued.
    fn swap(&mut self, r: &mut Route, a: usize, b: usize, c: usize, turn: u8, delta: Cost) {
        for i in [a, b, c] {
            let e = self.ex(r, i);
            let f = self.en(r, i + 1);
            self.push(e);
            self.push(f);
        }
        let l2 = c - b;
        r.seq[a..c].rotate_left(b - a);
        for (k, (lo, hi)) in [(a, a + l2), (a + l2, c)].into_iter().enumerate() {
            if turn >> k & 1 == 1 {
                r.seq[lo..hi].reverse();
                for p in lo..hi {
                    let t = r.seq[p] as usize;
                    r.dir[t] = !r.dir[t];
                }
            }
        }
        for p in a..c {
            r.pos[r.seq[p] as usize] = p as u32;
        }
        for i in [a, a + l2, c] {
            let e = self.ex(r, i);
            let f = self.en(r, i + 1);
            self.push(e);
            self.push(f);
        }
        r.cost += delta;
    }
}

#[cfg(test)]
mod tests {
    use rand::Rng;
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{Metric, PointCost, StateId};
    use crate::exact::solve_exact;
    use crate::model::Mode;

    /// `n` random segments in a square, each a task with two directions; `home` optional.
    fn segments(seed: u64, n: usize, home: bool) -> Problem<PointCost> {
        let mut rng = Pcg64Mcg::new(seed as u128 + 7);
        let mut pts = Vec::new();
        for _ in 0..n {
            let p = [rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0), 0.0];
            let q = [p[0] + rng.gen_range(-20.0..20.0), p[1] + rng.gen_range(-20.0..20.0), 0.0];
            pts.push(p);
            pts.push(q);
        }
        if home {
            pts.push([50.0, -10.0, 0.0]);
        }
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in 0..n as u32 {
            let (s, e) = (StateId(2 * t), StateId(2 * t + 1));
            b.task(vec![Mode { entry: s, exit: e, cost: 3.0 }, Mode { entry: e, exit: s, cost: 3.0 }]);
        }
        if home {
            b.start(StateId(2 * n as u32));
        }
        b.end(End::Free);
        b.build().expect("valid problem")
    }

    fn opts(kicks: u64) -> SolveOptions {
        SolveOptions { time_limit: None, iterations: Some(kicks), threads: 1, ..SolveOptions::default() }
    }

    #[test]
    fn matches_the_exact_optimum_on_small_problems() {
        for seed in 0..40 {
            for home in [false, true] {
                let p = segments(seed, 8, home);
                let exact = solve_exact(&p).expect("exact runs").expect("an optimum");
                let exact_cost = check(&p, &exact.steps).expect("feasible");
                let r = solve_reversible(&p, &opts(400)).expect("solves");
                let cost = check(&p, &r.solution.steps).expect("feasible");
                assert!((cost - r.solution.cost).abs() < 1e-9);
                assert!(cost <= exact_cost + 1e-6, "seed {seed} home {home}: {cost} vs optimum {exact_cost}");
            }
        }
    }

    #[test]
    fn every_move_keeps_the_running_cost_true() {
        // Descend and kick many times, recomputing the cost from scratch each time.
        let p = segments(3, 60, true);
        let mut dense = Dense::new(&p).expect("finite costs");
        let mut r = dense.nearest_neighbour();
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        for _ in 0..200 {
            dense.kick(&mut r, &mut rng);
            dense.drain(&mut r, 1e-9);
            assert!((r.cost - dense.cost_of(&r)).abs() < 1e-6, "{} vs {}", r.cost, dense.cost_of(&r));
            for (i, &t) in r.seq.iter().enumerate() {
                assert_eq!(r.pos[t as usize] as usize, i);
            }
        }
    }

    /// Two rasters of `k` parallel passes each (spacing 10, length 100), far apart.
    fn two_rasters(k: usize) -> Problem<PointCost> {
        let mut pts = Vec::new();
        for (x0, y0) in [(0.0, 0.0), (0.0, 500.0)] {
            for i in 0..k {
                let y = y0 + 10.0 * i as f64;
                pts.push([x0, y, 0.0]);
                pts.push([x0 + 100.0, y, 0.0]);
            }
        }
        pts.push([-50.0, -50.0, 0.0]);
        let n = 2 * k;
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in 0..n as u32 {
            let (s, e) = (StateId(2 * t), StateId(2 * t + 1));
            b.task(vec![Mode { entry: s, exit: e, cost: 100.0 }, Mode { entry: e, exit: s, cost: 100.0 }]);
        }
        b.start(StateId(2 * n as u32));
        b.end(End::Free);
        b.build().expect("valid problem")
    }

    #[test]
    fn a_raster_entered_from_the_wrong_side_is_turned_over() {
        // The first raster is done as a zigzag entered at its far corner: turning it over (every
        // pass the other way, same order) saves the diagonal from home; no 2-opt or flip of a
        // single pass gains.
        let k = 5;
        let p = two_rasters(k);
        let mut dense = Dense::new(&p).expect("finite costs");
        let zigzag = |first: usize, start_reversed: bool| -> Vec<Step> {
            (0..k)
                .map(|i| Step { task: TaskId((first + i) as u32), mode: u32::from((i % 2 == 1) != start_reversed) })
                .collect()
        };
        let mut steps = zigzag(0, true);
        steps.extend(zigzag(k, false));
        let mut r = dense.route_from_steps(&steps);
        let before = r.cost;
        dense.descend(&mut r, 1e-9);
        assert!((r.cost - dense.cost_of(&r)).abs() < 1e-9);
        // Home (-50, -50) to the near corner (0, 0): 70.7 instead of the far one (100, 0).
        let optimum = solve_exact(&p).expect("runs").expect("optimum");
        let opt = check(&p, &optimum.steps).expect("feasible") - 2.0 * k as f64 * 100.0;
        assert!(r.cost < before - 50.0, "{before} -> {}", r.cost);
        assert!(r.cost <= opt + 1e-6, "{} vs optimum {opt}", r.cost);
    }

    #[test]
    fn the_tree_bound_is_below_every_optimum_and_proves_rasters_optimal() {
        for seed in 0..40 {
            for home in [false, true] {
                let p = segments(seed, 8, home);
                let exact = solve_exact(&p).expect("exact runs").expect("an optimum");
                // the transit part of the optimum (every task costs 3)
                let opt = check(&p, &exact.steps).expect("feasible") - 8.0 * 3.0;
                let bound = Dense::new(&p).expect("finite costs").trees().expect("small").bound();
                assert!(bound <= opt + 1e-9, "seed {seed} home {home}: bound {bound} above the optimum {opt}");
                let r = solve_reversible(&p, &opts(400)).expect("solves");
                if r.exact {
                    assert!((r.solution.cost - 24.0 - opt).abs() < 1e-6, "seed {seed}: proven but not optimal");
                }
                // the report's bound counts the tasks' own cost too
                let reported = r.lower_bound.expect("a bound up to 200 tasks");
                assert!(
                    reported <= opt + 24.0 + 1e-9,
                    "seed {seed}: reported bound {reported}, optimum {}",
                    opt + 24.0
                );
                assert!(reported >= bound + 24.0 - 1e-9 || r.exact);
            }
        }
        // Two rasters far apart: the zigzag through both is a spanning tree of nearest ends.
        for k in [3, 4, 6] {
            let p = two_rasters(k);
            let r = solve_reversible(&p, &opts(5000)).expect("solves");
            let optimum = solve_exact(&p).ok().flatten();
            assert!(r.exact, "k {k}: not proven");
            assert!(r.iterations < 5000, "k {k}: the bound did not stop the search");
            if let Some(o) = optimum {
                let opt = check(&p, &o.steps).expect("feasible");
                assert!((r.solution.cost - opt).abs() < 1e-6, "k {k}: {} vs {opt}", r.solution.cost);
            }
        }
    }

    #[test]
    fn patches_whose_zigzags_leave_by_the_far_end_are_solved_by_the_tree_branch_and_bound() {
        // Four patches of 6, 6, 4 and 4 slightly tilted passes, in a row; in the first patch
        // passes 3 and 4 are closer at their top ends, where no zigzag from the left can join
        // them: the spanning tree is below every route, and only the branch and bound proves the
        // route optimal.
        let mut pts = Vec::new();
        let mut x0 = 0.0;
        for (patch, passes) in [6, 6, 4, 4].into_iter().enumerate() {
            for i in 0..passes {
                let x = x0 + 60.0 * i as f64;
                let top = if patch == 0 && i == 4 { x - 10.0 } else { x + 2.0 };
                pts.push([x, 0.0, 0.0]);
                pts.push([top, 700.0, 0.0]);
            }
            x0 += 60.0 * passes as f64 + 40.0;
        }
        pts.push([-100.0, -50.0, 0.0]);
        let n = 20;
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in 0..n as u32 {
            let (s, e) = (StateId(2 * t), StateId(2 * t + 1));
            b.task(vec![Mode { entry: s, exit: e, cost: 700.0 }, Mode { entry: e, exit: s, cost: 700.0 }]);
        }
        b.start(StateId(2 * n as u32));
        b.end(End::Free);
        let p = b.build().expect("valid problem");
        let r = solve_reversible(&p, &opts(5000)).expect("solves");
        assert!(r.exact, "not proven");
        assert_eq!(r.iterations, 0, "proven before any kick");
        let transit = r.solution.cost - 700.0 * n as f64;
        let bound = Dense::new(&p).expect("finite costs").trees().expect("small").bound();
        assert!(bound < transit - 1.0, "the tree bound alone ({bound}) already proves {transit}");
        let general = solve(&p, &opts(20_000)).expect("solves");
        assert!(r.solution.cost <= general.solution.cost + 1e-6, "{} vs {}", r.solution.cost, general.solution.cost);
    }

    #[test]
    fn deterministic_and_no_worse_than_the_general_solver_by_much() {
        let p = segments(5, 120, true);
        let a = solve_reversible(&p, &opts(3000)).expect("solves");
        let b = solve_reversible(&p, &opts(3000)).expect("solves");
        assert_eq!(a.solution.steps, b.solution.steps);
        let general = solve(&p, &opts(3000)).expect("solves");
        assert!(
            a.solution.cost <= general.solution.cost * 1.02,
            "{} vs general {}",
            a.solution.cost,
            general.solution.cost
        );
    }

    #[test]
    fn never_worse_than_the_initial_route_and_other_problems_pass_through() {
        let p = segments(11, 30, false);
        let first = solve_reversible(&p, &opts(0)).expect("solves");
        let again = solve_reversible(&p, &SolveOptions { initial: Some(first.solution.steps.clone()), ..opts(200) })
            .expect("solves");
        assert!(again.solution.cost <= first.solution.cost + 1e-9);
        // A closed tour is not an open route: the general solver answers.
        let mut b = Problem::builder(PointCost::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            Metric::Euclidean,
        ));
        b.point_tasks(3);
        b.end(End::Closed);
        let closed = b.build().expect("valid");
        let r = solve_reversible(&closed, &opts(10)).expect("solves");
        assert_eq!(r.solution.steps.len(), 3);
    }
}
