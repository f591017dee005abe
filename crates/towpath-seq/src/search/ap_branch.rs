//! A truncated depth-first branch and bound on the assignment relaxation: the start for
//! asymmetric one-mode problems (ATSP, SOP).
//!
//! The cheapest assignment (each node one successor and one predecessor) is a set of cycles
//! whose cost bounds every route from below; on random asymmetric costs it is within a few
//! tenths of a percent of the optimum (on SOPLIB's sparse files 1,291 against a best known
//! 1,294). A node's cycles are broken by subtour elimination (Carpaneto & Toth 1980): for the
//! cycle with the fewest free arcs `a₁ … a_m`, child `k` forbids `a_k` and requires
//! `a₁ … a_{k-1}`, so the children split the routes between them. A child's assignment is its
//! parent's with one row reassigned along one shortest augmenting path (O(n²): the parent's
//! potentials stay feasible as costs only go up). Children are searched cheapest bound first,
//! depth first, and every node's assignment is patched into a route (Karp 1979), which is how
//! the search finds good routes long before it could prove one optimal (Zhang 1993's truncated
//! depth-first branch and bound for the ATSP). A route is made to keep precedence by a stable
//! topological order; the assignment bound stays valid for it because an arc into one's own
//! predecessor is priced as forbidden.
//!
//! The search stops at its deadline or node budget; the best route is the start the local
//! search descends from.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use super::construct::Seq;
use super::net::Net;
use super::patching::{cycles_of, patch, tour_of, Assignment};
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

/// The branch and bound goes on past its root only when the root's assignment is within this
/// fraction of the root's patched route. Measured (route, bound): SOPLIB's sparse files 3-10 %
/// (R.300.100.1 29 / 26, R.200.1000.1 1,479 / 1,392), all then proven optimal in under 0.4 s;
/// TSPLIB ATSP ft70, ftv55-ftv70 5-14 %, proven in under 0.7 s; on TSPLIB SOP's rbg323a and
/// rbg341a 29 % and 48 %, where a quarter of the limit brought nothing, and on SOPLIB's dense
/// files the bound is a few percent of the route.
pub(crate) const MAX_ROOT_GAP: f64 = 0.2;

/// Deepest node searched (each level forbids one more arc), which bounds the search's stack.
/// The subtree below is left unsearched (and the answer not proven).
const MAX_DEPTH: usize = 1_000;

/// What the branch and bound found (the cost, bound and node count are read by the tests).
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct Found {
    /// The cheapest route (keeping precedence) of every node's patched assignment.
    pub seq: Seq,
    pub cost: Cost,
    /// The root's assignment cost: a lower bound of every route.
    pub bound: Cost,
    /// Nodes searched.
    pub nodes: u64,
    /// Whether the route is proven optimal: the search ran to its end, and every node whose
    /// assignment was one cycle had that cycle keep precedence (so its route cost its bound).
    pub proven: bool,
}

/// Runs the branch and bound on the arc matrix `c` of `net` (see `patching::arc_matrix`) until
/// `deadline`, the `cancel` flag or `max_nodes` nodes (one node: the patched assignment only),
/// or after the root when its assignment is more than `max_root_gap` (a fraction) below its
/// patched route; `None` when no route was found. `report` is given the best route's cost at
/// most every [`REPORT_EVERY`] while the search runs.
pub(crate) fn search<C: CostModel>(
    net: &Net<C>,
    c: Vec<Cost>,
    deadline: Option<Instant>,
    cancel: Option<&AtomicBool>,
    max_nodes: u64,
    max_root_gap: f64,
    report: Option<&dyn Fn(Cost)>,
) -> Option<Found> {
    let n = net.n;
    let root = Assignment::solve(&c, n);
    let bound = root.cost(&c);
    let integral = c.iter().all(|&x| x == x.round());
    let mut s = Search {
        net,
        n,
        work: c.clone(),
        c,
        log: Vec::new(),
        fixed: vec![false; n],
        big: net.forbidden,
        integral,
        eps: 1e-9 * net.typical_arc.max(1e-300),
        best: None,
        nodes: 0,
        max_nodes,
        deadline,
        cancel,
        stopped: false,
        inexact: false,
        max_root_gap,
        report,
        reported: Instant::now(),
    };
    s.visit(&root, 0);
    let (cost, seq) = s.best?;
    Some(Found { seq, cost, bound, nodes: s.nodes, proven: !s.stopped && !s.inexact })
}

struct Search<'a, 'p, C> {
    net: &'a Net<'p, C>,
    n: usize,
    /// The arc costs as given (for pricing patched routes).
    c: Vec<Cost>,
    /// The arc costs with the current node's forbidden arcs and required arcs' rivals raised
    /// to `big`.
    work: Vec<Cost>,
    /// Undo log of `work`: (index, old cost).
    log: Vec<(usize, Cost)>,
    /// Rows whose arc the current node requires.
    fixed: Vec<bool>,
    big: Cost,
    integral: bool,
    eps: Cost,
    best: Option<(Cost, Seq)>,
    nodes: u64,
    max_nodes: u64,
    deadline: Option<Instant>,
    cancel: Option<&'a AtomicBool>,
    stopped: bool,
    /// Set when a node's assignment was one cycle that broke precedence: its subtree was not
    /// searched to the end.
    inexact: bool,
    max_root_gap: f64,
    report: Option<&'a dyn Fn(Cost)>,
    /// When `report` was last called (or the search began).
    reported: Instant,
}

/// How often the branch and bound reports its best route while it runs.
pub(crate) const REPORT_EVERY: std::time::Duration = std::time::Duration::from_millis(500);

impl<C: CostModel> Search<'_, '_, C> {
    /// Whether a node with bound `lb` cannot hold a route cheaper than the best.
    fn prunes(&self, lb: Cost) -> bool {
        if lb >= 0.5 * self.big {
            return true;
        }
        match &self.best {
            None => false,
            // With integral costs a route cheaper than the best costs at least one unit less.
            Some((ub, _)) if self.integral => lb > ub - 1.0 + 1e-6,
            Some((ub, _)) => lb >= ub - self.eps,
        }
    }

    fn visit(&mut self, ap: &Assignment, depth: usize) {
        self.nodes += 1;
        let now = Instant::now();
        if self.nodes > self.max_nodes
            || self.deadline.is_some_and(|d| now >= d)
            || self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
        {
            self.stopped = true;
            return;
        }
        if let (Some(report), Some((best, _))) = (self.report, &self.best) {
            if now.duration_since(self.reported) >= REPORT_EVERY {
                self.reported = now;
                report(*best);
            }
        }
        if depth > MAX_DEPTH {
            self.inexact = true;
            return;
        }
        let succ = ap.columns();
        let cycles = cycles_of(&succ);
        let route = self.price_patched(&succ);
        let lb = ap.cost(&self.work);
        if self.nodes == 1 && route.is_some_and(|r| lb < (1.0 - self.max_root_gap) * r) {
            // A weak bound: branching would not close the gap in any time that pays.
            self.stopped = true;
            return;
        }
        if cycles.len() <= 1 {
            // A tour: the best route of its subtree if it keeps precedence as it is.
            if route.is_none_or(|r| r > lb + self.eps) {
                self.inexact = true;
            }
            return;
        }
        // Branch on the cycle with the fewest free arcs.
        let Some(cycle) = cycles.iter().min_by_key(|cy| cy.iter().filter(|&&a| !self.fixed[a]).count()) else {
            return;
        };
        let free: Vec<usize> = cycle.iter().copied().filter(|&a| !self.fixed[a]).collect();
        // The children's bounds first (each one augmentation); their assignments are solved
        // again when visited, which keeps the memory at O(n) a level.
        let mut kids: Vec<(Cost, usize)> = Vec::with_capacity(free.len());
        for k in 0..free.len() {
            let mark = self.constrain(&free, &succ, k);
            let child = self.child(ap, &free, &succ, k);
            let lb = child.cost(&self.work);
            self.undo(mark, &free[..k]);
            if !self.prunes(lb) {
                kids.push((lb, k));
            }
        }
        kids.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (lb, k) in kids {
            if self.stopped {
                return;
            }
            if self.prunes(lb) {
                continue;
            }
            let mark = self.constrain(&free, &succ, k);
            let child = self.child(ap, &free, &succ, k);
            self.visit(&child, depth + 1);
            self.undo(mark, &free[..k]);
        }
    }

    /// Child `k`'s assignment, under its constraints (see [`Search::constrain`]).
    fn child(&self, ap: &Assignment, free: &[usize], succ: &[usize], k: usize) -> Assignment {
        let mut child = ap.clone();
        child.reassign(&self.work, self.n, free[k], succ[free[k]]);
        child
    }

    /// Child `k`'s constraints: the arcs of rows `free[..k]` required, that of `free[k]`
    /// forbidden. Returns the undo mark.
    fn constrain(&mut self, free: &[usize], succ: &[usize], k: usize) -> usize {
        let mark = self.log.len();
        let n = self.n;
        for &a in &free[..k] {
            self.fixed[a] = true;
            let b = succ[a];
            for j in (0..n).filter(|&j| j != b) {
                self.raise(a * n + j);
            }
            for i in (0..n).filter(|&i| i != a) {
                self.raise(i * n + b);
            }
        }
        self.raise(free[k] * n + succ[free[k]]);
        mark
    }

    fn raise(&mut self, at: usize) {
        let old = self.work[at];
        if old < self.big {
            self.log.push((at, old));
            self.work[at] = self.big;
        }
    }

    fn undo(&mut self, mark: usize, required: &[usize]) {
        while self.log.len() > mark {
            let Some((at, old)) = self.log.pop() else { break };
            self.work[at] = old;
        }
        for &a in required {
            self.fixed[a] = false;
        }
    }

    /// Patches the node's cycles into one, makes it keep precedence, and keeps it if it is the
    /// cheapest route so far. Returns the route's cost.
    fn price_patched(&mut self, succ: &[usize]) -> Option<Cost> {
        let mut joined = succ.to_vec();
        patch(&self.c, self.n, &mut joined);
        let (seq, mode) = tour_of(self.net, &joined)?;
        let tour = Tour::new(self.net, seq, mode);
        let cost = tour.cost;
        if cost < self.big && self.best.as_ref().is_none_or(|(ub, _)| cost < ub - self.eps) {
            self.best = Some((cost, (tour.seq, tour.mode)));
        }
        Some(cost)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{MatrixCost, StateId};
    use crate::exact::solve_exact;
    use crate::model::{End, Mode, Problem, TaskId};
    use crate::search::patching::arc_matrix;
    use crate::solution::check;

    /// A random asymmetric problem of `n` tasks with costs below `max_cost`; with `prec`, the
    /// first task pinned, a few precedence pairs along a hidden order and, on odd seeds, the
    /// last task pinned on an open route.
    pub(crate) fn problem(seed: u64, n: usize, max_cost: u32, prec: bool) -> Problem<MatrixCost> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let data: Vec<Cost> =
            (0..n * n).map(|i| if i % (n + 1) == 0 { 0.0 } else { f64::from(rng.gen_range(0..max_cost)) }).collect();
        let mut b = Problem::builder(MatrixCost::new(n, data).expect("square"));
        for t in 0..n as u32 {
            b.task(vec![Mode::new(StateId(t), StateId(t))]);
        }
        if prec {
            for _ in 0..n / 3 {
                let (x, y) = (rng.gen_range(1..n as u32 - 1), rng.gen_range(1..n as u32 - 1));
                if x < y {
                    b.precede(TaskId(x), TaskId(y));
                }
            }
            b.first(TaskId(0));
            if seed % 2 == 1 {
                b.last(TaskId(n as u32 - 1)).end(End::Free);
            }
        }
        b.build().expect("valid problem")
    }

    /// The branch and bound's route as the checker prices it.
    fn checked<C: CostModel>(p: &Problem<C>, net: &Net<C>, found: &Found) -> Cost {
        let tour = Tour::new(net, found.seq.0.clone(), found.seq.1.clone());
        let steps = super::super::steps_from_tour(net, &tour);
        check(p, &steps).expect("the route keeps precedence and pins")
    }

    #[test]
    fn proven_routes_are_the_exact_optimum() {
        let mut proven_with_prec = 0;
        for seed in 0..80u64 {
            let n = 5 + (seed % 8) as usize;
            let prec = seed % 4 != 0;
            let p = problem(seed, n, if seed % 3 == 0 { 10 } else { 100 }, prec);
            let net = Net::new(&p);
            let c = arc_matrix(&net, None).expect("an asymmetric one-mode problem");
            let found = search(&net, c, None, None, u64::MAX, 1.0, None).expect("a route");
            let cost = checked(&p, &net, &found);
            assert!((cost - found.cost).abs() < 1e-9, "seed {seed}: says {} but costs {cost}", found.cost);
            let exact = solve_exact(&p).expect("small").expect("feasible").cost;
            assert!(found.bound <= exact + 1e-9, "seed {seed}: bound {} above the optimum {exact}", found.bound);
            assert!(cost >= exact - 1e-9, "seed {seed}: {cost} below the optimum {exact}");
            if found.proven {
                assert!((cost - exact).abs() < 1e-9, "seed {seed}: proven {cost} but the optimum is {exact}");
                proven_with_prec += usize::from(prec);
            } else {
                // Without precedence every one-cycle assignment is a route: the search is complete.
                assert!(prec, "seed {seed}: an unconstrained search not run to its end");
            }
        }
        assert!(proven_with_prec >= 30, "only {proven_with_prec} of 60 problems with precedence proven");
    }

    #[test]
    fn a_truncated_search_still_gives_a_route_no_dearer_than_the_patched_start() {
        for seed in 0..6u64 {
            let p = problem(100 + seed, 120, 1000, true);
            let net = Net::new(&p);
            let c = arc_matrix(&net, None).expect("an asymmetric one-mode problem");
            let (seq, mode) = super::super::patching::assignment_patching(&net, None).expect("patched start");
            let patched = Tour::new(&net, seq, mode).cost;
            let found = search(&net, c, None, None, 50, 1.0, None).expect("a route");
            assert!(found.nodes <= 51);
            let cost = checked(&p, &net, &found);
            assert!(cost <= patched + 1e-9, "seed {seed}: {cost} above the patched start {patched}");
            assert!(found.bound <= cost + 1e-9);
        }
    }

    #[test]
    fn solve_reports_a_proven_route_as_exact() {
        use crate::search::{solve, SolveOptions};
        let mut proven = 0;
        for seed in 0..30u64 {
            let p = problem(200 + seed, 14, 1000, seed % 2 == 0);
            let opts = SolveOptions {
                time_limit: None,
                iterations: Some(300),
                threads: 1,
                exact_up_to: 0,
                seed,
                ..SolveOptions::default()
            };
            let r = solve(&p, &opts).expect("a route");
            let cost = check(&p, &r.solution.steps).expect("feasible");
            assert!((cost - r.solution.cost).abs() < 1e-9);
            // the reported bound is below the optimum (the assignment relaxation, or the
            // optimum itself when proven)
            let exact = solve_exact(&p).expect("small").expect("feasible").cost;
            let bound = r.lower_bound.expect("the assignment ran");
            assert!(bound <= exact + 1e-9, "seed {seed}: bound {bound} above the optimum {exact}");
            if r.exact {
                assert!((bound - exact).abs() < 1e-9);
                assert!((cost - exact).abs() < 1e-9, "seed {seed}: reported exact {cost}, optimum {exact}");
                assert_eq!(r.iterations, 0, "seed {seed}: searched after a proof");
                proven += 1;
            }
        }
        assert!(proven >= 10, "only {proven} of 30 proven");
    }
}
