//! towpath's own solver: construction, local search with modes and precedence, and iterated
//! local search on several threads within a time or work budget.

mod alpha;
mod ap_branch;
mod construct;
mod ils;
mod local;
mod merge;
mod modes;
mod neighbors;
mod net;
mod patching;
mod pieces;
mod population;
mod reversible;
mod sop3;
mod tour;
mod tree_proof;
mod two_way;

/// Test problems shared by the search modules' tests.
#[cfg(test)]
pub(crate) mod testing {
    use rand::Rng;
    use rand_pcg::Pcg64Mcg;

    use crate::cost::{Metric, PointCost, StateId};
    use crate::model::{Mode, Problem};

    /// A closed tour through `n` random points of a `side` × `side` square (Euclidean, one
    /// mode per task), the points drawn from `rng`.
    pub(crate) fn random_tour_problem(rng: &mut Pcg64Mcg, n: usize, side: f64) -> Problem<PointCost> {
        points_problem((0..n).map(|_| [rng.gen_range(0.0..side), rng.gen_range(0.0..side), 0.0]).collect())
    }

    /// A closed Euclidean tour through the points.
    pub(crate) fn points_problem(pts: Vec<[f64; 3]>) -> Problem<PointCost> {
        let n = pts.len();
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for k in 0..n as u32 {
            b.task(vec![Mode::point(StateId(k))]);
        }
        b.build().expect("a point per task is a valid problem")
    }
}

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::clock::Clock;
use crate::cost::{Cost, CostModel};
use crate::exact::solve_exact;
use crate::model::{Problem, TaskId};
use crate::solution::{check, Solution, Step, Violation};

use ils::{Budget, Ils};
use neighbors::Neighbors;
use net::Net;
use tour::Tour;

pub use reversible::{solve_reversible, MAX_REVERSIBLE_TASKS};

/// Progress of a running solve, passed to [`SolveOptions::progress`].
#[derive(Clone, Debug)]
pub struct Progress {
    /// Time since the solve started.
    pub elapsed: Duration,
    /// Best route cost so far.
    pub best_cost: Cost,
    /// Improvement kicks done so far.
    pub iterations: u64,
    /// Fraction of the budget used, in 0..=1.
    pub fraction: f64,
}

/// A progress callback.
pub type ProgressFn = Arc<dyn Fn(&Progress) + Send + Sync>;

/// How long to search and how.
#[derive(Clone)]
pub struct SolveOptions {
    /// Stop after this much wall time (default 10 s). `None` with `iterations` set runs the full
    /// work budget whatever it takes.
    pub time_limit: Option<Duration>,
    /// Work budget: the number of improvement kicks (summed over threads). With a work budget
    /// and no time limit the result depends only on the input, the seed and the thread count.
    pub iterations: Option<u64>,
    /// Seed for the random choices.
    pub seed: u64,
    /// Worker threads (default: the machine's available parallelism).
    pub threads: usize,
    /// A feasible route to start from; the answer is never worse than it.
    pub initial: Option<Vec<Step>>,
    /// Called after each epoch of the search.
    pub progress: Option<ProgressFn>,
    /// Set to true to stop the search early; the best route so far is returned.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Problems with at most this many tasks are solved exactly by dynamic programming instead
    /// (default 10), when their modes keep the programme small: 2ⁿ·n²·m² (times m on a closed
    /// route) at most 3.2·10⁷ for n tasks of at most m modes.
    pub exact_up_to: usize,
    /// Stop when this many epochs in a row (a twentieth of the work budget each) have not
    /// improved the best route: the budget becomes an upper bound for small or easy problems.
    /// Deterministic like the budget. Default `None`: run the whole budget.
    pub stall_epochs: Option<u32>,
    /// On asymmetric one-mode problems (ATSP, SOP) of up to 600 tasks, search a branch and
    /// bound on the assignment relaxation first: its best route is a start, and when it runs to
    /// its end the route is returned as proven optimal (default true; false leaves only the
    /// heuristic search, e.g. to test it).
    pub assignment_branching: bool,
    /// Solve problems of two-way tasks (each done either way: two modes, each the other
    /// reversed) without precedence as a symmetric tour over the tasks' ends, with a fixed edge
    /// per task (default true; false searches the tasks and their modes directly).
    pub two_way_ends: bool,
    /// After the search, compute a Held–Karp lower bound (a 1-tree bound after a subgradient
    /// ascent; Held and Karp 1970) on symmetric one-mode tours and on two-way tasks through
    /// their ends, up to 50,000 nodes, and report it in [`SolveReport::lower_bound`]. It costs
    /// O(n²) arc evaluations on top of the time limit (about 1 s at 5,000 nodes, 13 s at
    /// 20,000); default false.
    pub held_karp_bound: bool,
    /// On plain symmetric tours, how many first-level 3-opt moves a Lin–Kernighan chain tries
    /// in turn (backtracking, as LKH does) before it gives up, 1 to 4. `None` (default): by the
    /// budget's kicks per node, 3 from [`BREADTH3_KICKS_PER_NODE`], 2 from
    /// [`BREADTH_KICKS_PER_NODE`] (at 10 s on 2 threads: up to 1,000 and 5,000 nodes), else 1:
    /// each further try costs about as much as the first, which pays only where the search has
    /// kicks to spare.
    pub lk_breadth: Option<usize>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            time_limit: Some(Duration::from_secs(10)),
            iterations: None,
            seed: 1,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            initial: None,
            progress: None,
            cancel: None,
            exact_up_to: 10,
            stall_epochs: None,
            assignment_branching: true,
            two_way_ends: true,
            held_karp_bound: false,
            lk_breadth: None,
        }
    }
}

impl std::fmt::Debug for SolveOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolveOptions")
            .field("time_limit", &self.time_limit)
            .field("iterations", &self.iterations)
            .field("seed", &self.seed)
            .field("threads", &self.threads)
            .field("initial", &self.initial.as_ref().map(|s| s.len()))
            .field("exact_up_to", &self.exact_up_to)
            .field("stall_epochs", &self.stall_epochs)
            .field("assignment_branching", &self.assignment_branching)
            .field("two_way_ends", &self.two_way_ends)
            .field("held_karp_bound", &self.held_karp_bound)
            .field("lk_breadth", &self.lk_breadth)
            .finish()
    }
}

/// What a solve returns.
#[derive(Clone, Debug)]
pub struct SolveReport {
    /// The best route found, with its checked cost.
    pub solution: Solution,
    /// Cost of the initial route, if one was given.
    pub initial_cost: Option<Cost>,
    /// Cost after construction and the first local search.
    pub first_local_optimum: Cost,
    /// Improvement kicks done.
    pub iterations: u64,
    /// Wall time.
    pub elapsed: Duration,
    /// Wall time of the kick phase alone (the iterated local search, after the candidate lists,
    /// the starts and the first descent): `iterations` over it is the kick rate.
    pub search_elapsed: Duration,
    /// True when the answer is proven optimal: the exact solver was used, the branch and bound
    /// on the assignment relaxation ran to its end (asymmetric one-mode problems), or (in
    /// [`solve_reversible`]) the route met a lower bound.
    pub exact: bool,
    /// A lower bound on the cost of every route, when the solver has one: the optimum itself
    /// when `exact`; else the assignment relaxation's value (asymmetric one-mode problems of up
    /// to 600 tasks, when its branch and bound ran) or the spanning-tree bound of
    /// [`solve_reversible`] (up to 200 tasks), or the Held–Karp bound when
    /// [`SolveOptions::held_karp_bound`] asked for it (the largest of those that apply).
    /// `None` otherwise.
    pub lower_bound: Option<Cost>,
}

impl SolveReport {
    /// The report of a route proven optimal before any search (no kicks).
    fn proven(solution: Solution, initial_cost: Option<Cost>, t0: Instant) -> Self {
        let cost = solution.cost;
        SolveReport {
            solution,
            initial_cost,
            first_local_optimum: cost,
            iterations: 0,
            elapsed: t0.elapsed(),
            search_elapsed: Duration::ZERO,
            exact: true,
            lower_bound: Some(cost),
        }
    }
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The initial route given is not feasible.
    #[error("the initial route is not feasible: {0}")]
    BadInitial(Violation),
    /// No feasible route was found (every route uses a forbidden transition).
    #[error("no feasible route found: {0}")]
    NoFeasibleRoute(Violation),
    /// More worker threads were asked for than the solver runs.
    #[error("{threads} threads asked for; the solver runs at most {MAX_THREADS}")]
    TooManyThreads {
        /// The number asked for.
        threads: usize,
    },
}

/// The most worker threads [`solve`] runs (each keeps its own copy of the tour).
pub const MAX_THREADS: usize = 1024;

/// Solves a problem with towpath's best solver: exactly when it is small, else nearest-neighbour
/// starts, candidate lists, a first descent and the iterated local search in epochs (shared
/// between threads at each epoch's end), then a last full descent. Problems of two-way tasks
/// without precedence are searched as a tour over the tasks' ends (see
/// [`SolveOptions::two_way_ends`]).
pub fn solve<C: CostModel>(problem: &Problem<C>, opts: &SolveOptions) -> Result<SolveReport, SolveError> {
    let (clock, initial_cost) = match begin(problem, opts)? {
        Begun::Proven(report) => return Ok(report),
        Begun::Search(clock, initial_cost) => (clock, initial_cost),
    };
    if opts.two_way_ends && two_way::applies(problem) {
        if let Some(report) = two_way::solve(problem, opts, clock.started(), initial_cost) {
            return report;
        }
    }
    search(problem, opts, clock, initial_cost, None)
}

/// [`solve`] on a problem whose fixed edges (see `two_way`) are given: `partner[v]` is the node
/// tied to node `v`, or `two_way::NONE`. (Not `solve` itself: the ends of the ends' problem
/// would be a type without end.)
pub(crate) fn solve_inner<C: CostModel>(
    problem: &Problem<C>,
    opts: &SolveOptions,
    partner: Vec<u32>,
) -> Result<SolveReport, SolveError> {
    match begin(problem, opts)? {
        Begun::Proven(report) => Ok(report),
        Begun::Search(clock, initial_cost) => search(problem, opts, clock, initial_cost, Some(partner)),
    }
}

/// How a solve begins.
enum Begun {
    /// Solved exactly by the dynamic programme.
    Proven(SolveReport),
    /// To search: the clock and the initial route's cost, if one was given.
    Search(Clock, Option<Cost>),
}

/// What every solve does first: checks the thread count and the initial route, starts the
/// clock, and solves small problems exactly.
fn begin<C: CostModel>(problem: &Problem<C>, opts: &SolveOptions) -> Result<Begun, SolveError> {
    if opts.threads > MAX_THREADS {
        return Err(SolveError::TooManyThreads { threads: opts.threads });
    }
    let clock = Clock::for_options(opts);
    let initial_cost = match &opts.initial {
        Some(steps) => Some(check(problem, steps).map_err(SolveError::BadInitial)?),
        None => None,
    };
    if let Some(solution) = small_exact(problem, opts)? {
        return Ok(Begun::Proven(SolveReport::proven(solution, initial_cost, clock.started())));
    }
    Ok(Begun::Search(clock, initial_cost))
}

/// The heuristic search of [`solve`].
fn search<C: CostModel>(
    problem: &Problem<C>,
    opts: &SolveOptions,
    clock: Clock,
    initial_cost: Option<Cost>,
    partner: Option<Vec<u32>>,
) -> Result<SolveReport, SolveError> {
    let t0 = clock.started();
    let mut net = Net::new(problem);
    if let Some(partner) = partner {
        net.partner = partner;
    }
    let net = net;
    let threads = opts.threads.max(1);
    let work = (problem.num_tasks() as f64).powi(2) * problem.max_modes() as f64;
    let assigned = assignment_start(&net, opts, &clock);
    let lower_bound = assigned.as_ref().and_then(|a| a.bound);
    if let Some(Assigned { tour, proven: true, .. }) = &assigned {
        // Proven optimal by the branch and bound on the assignment.
        let steps = steps_from_tour(&net, tour);
        let cost = check(problem, &steps).map_err(SolveError::NoFeasibleRoute)?;
        return Ok(SolveReport::proven(Solution { steps, cost }, initial_cost, t0));
    }
    // Large plain tours build their lists first and start from a nearest-neighbour tour
    // through them (through the nearest lists when the α pass needs a tour's cost).
    let early = lists_before_starts(&net).then(|| lists_and_start(&net, opts, threads));
    let (early_lists, early_start) = early.unzip();
    let mut starts = if let Some(start) = early_start {
        let mut starts: Vec<Tour> = assigned.map(|a| a.tour).into_iter().collect();
        starts.push(start);
        starts
    } else if !net.partner.is_empty() && opts.initial.is_some() {
        // Constructed tours through the ends of two-way tasks are poor starts beside a given
        // one (a route of whole tasks): on 20,000 random strokes the first descent from a
        // space-filling curve took 4.5 s, from the given start 2.2 s.
        Vec::new()
    } else {
        construct_starts(&net, problem, opts, work, clock.deadline(), assigned.map(|a| a.tour))
    };
    if !net.partner.is_empty() {
        for t in &mut starts {
            *t = two_way::keep_partners(&net, t);
        }
    }
    let eps = 1e-9 * net.typical_arc;
    let nb = match early_lists {
        Some(nb) => nb,
        None => candidate_lists(&net, &starts, opts, threads),
    };
    let ils = Ils::new(&net, &nb, eps).with_breadth(lk_breadth(&net, opts, threads));
    // Descend from the best few constructed starts and from the initial route; keep the best
    // local optimum.
    starts.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    starts.truncate(if pool_is_short(opts, work) { 1 } else { 3 });
    if let Some(steps) = &opts.initial {
        starts.push(tour_from_steps(&net, steps));
    }
    let mut best: Option<Tour> = None;
    for mut t in starts {
        ils.descend(&mut t, clock.deadline());
        if best.as_ref().is_none_or(|b| t.cost < b.cost) {
            best = Some(t);
        }
    }
    let mut best = best.expect("at least one start");
    let first_local_optimum = best.cost;
    let search_start = Instant::now();
    let iterations = search_epochs(&net, &ils, &mut best, opts, &clock, threads, eps);
    let search_elapsed = search_start.elapsed();
    if !clock.cancelled() {
        ils.descend(&mut best, clock.deadline());
    }
    optimize_final(&net, &mut best, eps);
    let steps = steps_from_tour(&net, &best);
    let cost = check(problem, &steps).map_err(SolveError::NoFeasibleRoute)?;
    let mut solution = Solution { steps, cost };
    if let (Some(init), Some(ic)) = (&opts.initial, initial_cost) {
        if ic < solution.cost {
            solution = Solution { steps: init.clone(), cost: ic };
        }
    }
    let held_karp = opts.held_karp_bound.then(|| alpha::held_karp_bound(&net, &nb, best.cost)).flatten();
    let lower_bound = match (lower_bound, held_karp) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    let lower_bound = lower_bound.map(|b| b.min(solution.cost));
    Ok(SolveReport {
        solution,
        initial_cost,
        first_local_optimum,
        iterations,
        elapsed: t0.elapsed(),
        search_elapsed,
        exact: false,
        lower_bound,
    })
}

/// Largest estimated work, 2ⁿ·n²·m² transitions (times m for a closed route, one programme
/// per mode of its anchor), of a problem [`solve`] hands to the exact dynamic programme: ten
/// tasks of sixteen modes each (2.6·10⁷, about a tenth of a second), such as a machining tool's
/// cells with their entry points, are solved exactly at once instead of searched for the
/// whole time limit.
const EXACT_WORK: f64 = 3.2e7;

/// The exact answer of a problem small enough for the dynamic programme (at most
/// `opts.exact_up_to` tasks and [`EXACT_WORK`]), or `None` to search heuristically.
fn small_exact<C: CostModel>(problem: &Problem<C>, opts: &SolveOptions) -> Result<Option<Solution>, SolveError> {
    let (n, m) = (problem.num_tasks(), problem.max_modes().max(1) as f64);
    if n > opts.exact_up_to.min(crate::MAX_EXACT_TASKS) {
        return Ok(None);
    }
    let anchors = if problem.is_cyclic() { m } else { 1.0 };
    if 2f64.powi(n as i32) * (n * n) as f64 * m * m * anchors > EXACT_WORK {
        return Ok(None);
    }
    match solve_exact(problem) {
        Ok(Some(sol)) => {
            let cost = check(problem, &sol.steps).map_err(SolveError::NoFeasibleRoute)?;
            Ok(Some(Solution { steps: sol.steps, cost }))
        }
        _ => Ok(None),
    }
}

/// On asymmetric one-mode problems (ATSP, SOP), the best route of a truncated branch and bound
/// on the assignment relaxation (see `ap_branch`), when the assignment's O(n³) fits in a
/// twentieth of the time limit; the search gets at most `AP_BRANCH_SHARE` of the limit and
/// `AP_BRANCH_MAX` (`AP_BRANCH_NODES_PER_NODE` nodes per node without a limit). Returns the
/// route and whether the search proved it optimal.
fn assignment_start<C: CostModel>(net: &Net<C>, opts: &SolveOptions, clock: &Clock) -> Option<Assigned> {
    let deadline = clock.deadline();
    let affordable = opts.time_limit.is_none_or(|tl| (net.n as f64).powi(3) * 1e-9 <= tl.as_secs_f64() / 20.0);
    if !affordable {
        return None;
    }
    let c = patching::arc_matrix(net, deadline)?;
    let share = opts.time_limit.map(|tl| Instant::now() + tl.mul_f64(AP_BRANCH_SHARE).min(AP_BRANCH_MAX));
    let bb_deadline = match (share, deadline) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    let max_nodes = match (opts.assignment_branching, opts.time_limit) {
        (false, _) => 1,
        (true, Some(_)) => u64::MAX,
        (true, None) => AP_BRANCH_NODES_PER_NODE * net.n as u64,
    };
    // A front end hears from the search while it runs (it may take seconds).
    let t0 = clock.started();
    let report = opts.progress.as_ref().map(|cb| {
        move |best: Cost| {
            let fraction = budget_used(opts, t0, 0).unwrap_or(0.0);
            cb(&Progress { elapsed: t0.elapsed(), best_cost: best, iterations: 0, fraction });
        }
    });
    let found = ap_branch::search(
        net,
        c,
        bb_deadline,
        clock.cancel_flag().map(|c| c.as_ref()),
        max_nodes,
        ap_branch::MAX_ROOT_GAP,
        report.as_ref().map(|r| r as &dyn Fn(Cost)),
    )?;
    // The assignment prices arcs only; every route also pays each task's one mode.
    let modes: Cost = (0..net.n_tasks as u32).map(|t| net.mode_cost(t, 0)).sum();
    let bound = (found.bound < 0.5 * net.forbidden).then_some(found.bound + modes);
    Some(Assigned {
        tour: Tour::new(net, found.seq.0, found.seq.1),
        proven: found.proven && opts.assignment_branching,
        bound,
    })
}

/// What [`assignment_start`] found.
struct Assigned {
    /// The branch and bound's best route.
    tour: Tour,
    /// Whether the search proved it optimal.
    proven: bool,
    /// The root assignment's value plus the tasks' mode costs: a lower bound on every route
    /// (`None` when the assignment needed a forbidden arc).
    bound: Option<Cost>,
}

/// Construction: nearest neighbour from a seed pool sized to the budget (`work` arc
/// evaluations per start), or a space-filling curve for very large instances, beside the
/// `assigned` start (see [`assignment_start`]). Stops early at the deadline, but always ends
/// with at least one start unless an initial route is given.
fn construct_starts<C: CostModel>(
    net: &Net<C>,
    problem: &Problem<C>,
    opts: &SolveOptions,
    work: f64,
    deadline: Option<Instant>,
    assigned: Option<Tour>,
) -> Vec<Tour> {
    let mut starts: Vec<Tour> = Vec::new();
    if problem.num_tasks() > SPACE_FILLING_FROM {
        if let Some((seq, mode)) = construct::space_filling(net) {
            starts.push(Tour::new(net, seq, mode));
            return starts;
        }
    }
    // The seed pool is sized to the work (at most ~2·10⁷ arc evaluations) and, under a time
    // limit, to `START_SHARE` of it.
    let mut pool_size = ((2e7 / work.max(1.0)) as usize).clamp(1, 64);
    if let Some(tl) = opts.time_limit {
        let affordable = tl.as_secs_f64() * START_SHARE / (work.max(1.0) * ARC_SECONDS);
        pool_size = pool_size.min(affordable as usize).max(1);
    }
    let pool =
        if net.depot != u32::MAX && problem.start().is_some() { vec![0] } else { construct::seed_pool(net, pool_size) };
    starts.extend(assigned);
    let have_initial = opts.initial.is_some();
    for f in pool {
        let limit = if starts.is_empty() && !have_initial { None } else { deadline };
        match construct::nearest_neighbor(net, Some(f), limit) {
            Some((seq, mode)) if seq.len() == net.n => starts.push(Tour::new(net, seq, mode)),
            Some(_) => {}
            None => break,
        }
    }
    starts
}

/// Smallest plain tour that starts from a nearest-neighbour tour through lists (see
/// [`lists_before_starts`]) instead of the full, quadratic one: from here one tour of the seed
/// pool is all a 10 s limit affords, and at 10,000 points its scan took about 1.2 s of the
/// limit while the other threads waited.
const LIST_START_FROM: usize = 4_000;

/// True when the candidate lists are built before the starts, and the start is the nearest
/// neighbour through them (see [`lists_and_start`]): plain symmetric one-mode tours (no
/// precedence, groups or fixed edges, no fixed start) of [`LIST_START_FROM`] to
/// [`SPACE_FILLING_FROM`] nodes.
fn lists_before_starts<C: CostModel>(net: &Net<C>) -> bool {
    (LIST_START_FROM..=SPACE_FILLING_FROM).contains(&net.n) && local::plain_tour(net) && net.depot == u32::MAX
}

/// The candidate lists and a nearest-neighbour tour through lists: through the candidate
/// lists themselves, or, when they take an α pass (whose ascent's step length needs a tour's
/// cost), through the nearest lists, which the pass then starts from.
fn lists_and_start<C: CostModel>(net: &Net<C>, opts: &SolveOptions, threads: usize) -> (Neighbors, Tour) {
    let first = construct::seed_pool(net, 1).first().copied().unwrap_or(net.anchor);
    let through = |nb: &Neighbors| Tour::new(net, construct::nearest_neighbor_by_lists(net, nb, first), vec![0; net.n]);
    if alpha_plan(net, opts, threads).is_none() {
        let nb = candidate_lists(net, &[], opts, threads);
        let start = through(&nb);
        return (nb, start);
    }
    let nearest = Neighbors::build_on(net, list_length(net), threads);
    let start = through(&nearest);
    let nb = plain_candidate_lists(net, std::slice::from_ref(&start), opts, threads, Some(nearest));
    (nb, start)
}

/// The ascent steps of the α pass (see `alpha::plan`) when the lists take one.
fn alpha_plan<C: CostModel>(net: &Net<C>, opts: &SolveOptions, threads: usize) -> Option<usize> {
    alpha::plan(net.n, threads, opts.time_limit.map(|d| d.as_secs_f64())).filter(|_| net.partner.is_empty())
}

/// Length of the nearest-neighbour lists.
fn list_length<C: CostModel>(net: &Net<C>) -> usize {
    // Wider lists pay off under precedence (measured on TSPLIB SOP and SOPLIB at equal time: 16
    // beat 10 and 24).
    let k: usize = if net.n > 20_000 {
        8
    } else if net.has_prec {
        16
    } else {
        10
    };
    // The two ends of a short two-way task lie close together and take two places in every
    // list near them: twice as many places keep as many tasks.
    if net.partner.is_empty() {
        k
    } else {
        LIST_FACTOR_ENDS * k
    }
}

/// The candidate neighbours of each node (see [`plain_candidate_lists`]), each node's fixed
/// partner first where there are fixed edges (see `two_way`).
fn candidate_lists<C: CostModel>(net: &Net<C>, starts: &[Tour], opts: &SolveOptions, threads: usize) -> Neighbors {
    let nb = plain_candidate_lists(net, starts, opts, threads, None);
    if net.partner.is_empty() {
        nb
    } else {
        nb.with_partners_first(net)
    }
}

/// The nearest neighbours of each node, replaced on symmetric one-mode tours by the lowest-α
/// ones when they are affordable (see `alpha`), else on planar ones by nearest and quadrant
/// neighbours.
fn plain_candidate_lists<C: CostModel>(
    net: &Net<C>,
    starts: &[Tour],
    opts: &SolveOptions,
    threads: usize,
    nearest: Option<Neighbors>,
) -> Neighbors {
    let k = list_length(net);
    // Not α on two-way tasks' ends: on 1,500 short strokes its lists left a 420-unit arc that
    // a 2-opt move removes (the fixed edges distort the 1-trees); quadrant lists left none.
    let alpha_steps = alpha_plan(net, opts, threads);
    // Without α, nearest lists miss the arcs between clusters; quadrant neighbours keep them.
    // gauss-10000 (100 clusters, 10 s, seeds 1-2): 1,588,315 / 1,572,931 -> 1,539,073 /
    // 1,540,787 (fast-tsp 1,545,361 / 1,545,751); uniform 20,000 and portc-10000 within 0.06 %.
    // (Built before the nearest lists, which they do not need: on 100,000 random points
    // those take 1.4 s.)
    let quadrants = || {
        if net.has_prec || net.has_groups {
            return None;
        }
        neighbors::quadrant_lists(net, k.saturating_sub(2 * QUADRANT_K).max(3), QUADRANT_K)
    };
    if alpha_steps.is_none() {
        if let Some(lists) = quadrants() {
            return lists;
        }
    }
    let nb = nearest.unwrap_or_else(|| Neighbors::build_on(net, k, threads));
    if let Some(steps) = alpha_steps {
        let ub = starts.iter().map(|t| t.cost).fold(Cost::INFINITY, Cost::min);
        if let Some(lists) = alpha::candidates(net, &nb, steps, ub, threads) {
            return lists;
        }
        if let Some(lists) = quadrants() {
            return lists;
        }
    }
    nb
}

/// The iterated local search in epochs: each thread's chain kicks and descends for an epoch,
/// then the best chain wins, chains are merged where their tours allow it, and chains that fell
/// behind adopt the best. Returns the kicks done; `best` is the best tour found.
fn search_epochs<C: CostModel>(
    net: &Net<C>,
    ils: &Ils<'_, '_, C>,
    best: &mut Tour,
    opts: &SolveOptions,
    clock: &Clock,
    threads: usize,
    eps: Cost,
) -> u64 {
    let t0 = clock.started();
    let mut iterations = 0u64;
    let mut stalled = 0u32;
    let total_kicks = opts.iterations.unwrap_or(u64::MAX);
    let epochs_planned = EPOCHS_PLANNED as u64;
    let per_epoch = match opts.iterations {
        Some(it) => (it / (epochs_planned * threads as u64)).max(1),
        None => u64::MAX,
    };
    let slice =
        opts.time_limit.map(|d| (d / epochs_planned as u32).clamp(Duration::from_millis(50), Duration::from_secs(2)));
    // The search stops a little early to leave time for a last full pass of the local search
    // (don't-look bits leave a few improving moves behind on large instances): 20 µs a node, at
    // most a tenth of the limit (on 100,000 strokes the pass takes about 1 s).
    let search_end = clock.deadline().map(|d| {
        let reserve =
            opts.time_limit.map_or(Duration::ZERO, |tl| (tl / 10).min(Duration::from_secs_f64(net.n as f64 * 20e-6)));
        d - reserve
    });
    let merge_chains = threads > 1 && local::uses_or3(net);
    // On plain tours, a population of chains from starts of their own for the first epochs
    // (see `population`), where the budget allows it.
    let per_thread = population::chains_per_thread(net, opts, threads);
    let mut population_epochs = if per_thread > 1 { population::EPOCHS } else { 0 };
    let mut chains: Vec<ils::Chain> = (0..threads * per_thread)
        .map(|t| {
            let mut chain = ils::Chain::new(best, opts.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ t as u64);
            // a portfolio on plain tours: every second chain restarts often (clustered geometry)
            chain.restless = t % 2 == 1 && local::uses_or3(net);
            chain.fresh = t > 0 && per_thread > 1;
            chain
        })
        .collect();
    while iterations < total_kicks {
        if search_end.is_some_and(|d| Instant::now() >= d) || clock.cancelled() {
            break;
        }
        let epoch_deadline = match (search_end, slice) {
            (Some(d), Some(s)) => Some(d.min(Instant::now() + s)),
            _ => None,
        };
        let left = total_kicks - iterations;
        let kicks_each = per_epoch.min(left.div_ceil(threads as u64));
        let frac = budget_used(opts, t0, iterations).unwrap_or(1.0);
        let temperature = acceptance_temperature(net, best.cost, frac);
        let slack = acceptance_slack(net, best.cost);
        let budget = Budget { kicks: kicks_each, deadline: epoch_deadline, hard: search_end, temperature, slack };
        let cancel = clock.cancel_flag().map(|c| &**c);
        let group = chains.len() / threads;
        let done: u64 = if threads == 1 {
            population::run_thread(ils, &mut chains, budget, slice, cancel)
        } else {
            std::thread::scope(|s| {
                let handles: Vec<_> = chains
                    .chunks_mut(group)
                    .map(|chains| {
                        let ils = &ils;
                        s.spawn(move || population::run_thread(ils, chains, budget, slice, cancel))
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().expect("solver thread panicked")).sum()
            })
        };
        let before = best.cost;
        if population_epochs > 1 {
            // the population: the chains keep their own tours
            population_epochs -= 1;
            take_cheapest(best, &chains, eps);
        } else {
            if population_epochs == 1 {
                population_epochs = 0;
                population::merge_all(net, ils, best, &mut chains, threads, search_end, eps);
            }
            share_best(net, ils, best, &mut chains, merge_chains, search_end, eps);
        }
        iterations += done;
        // (a population is not stalled before its merge)
        stalled = if best.cost < before - eps || population_epochs > 0 { 0 } else { stalled + 1 };
        if opts.stall_epochs.is_some_and(|k| stalled >= k) {
            break;
        }
        if let Some(cb) = &opts.progress {
            let fraction = budget_used(opts, t0, iterations).unwrap_or(0.0);
            cb(&Progress { elapsed: t0.elapsed(), best_cost: best.cost, iterations, fraction });
        }
        if done == 0 {
            break;
        }
    }
    iterations
}

/// Kicks per node a budget must allow for chains to backtrack over two first-level moves (see
/// [`SolveOptions::lk_breadth`]). On clustered and TSPLIB instances at 10 s on 2 threads
/// (medians of 3-12 seeds), breadth 2 gained where 1 gave 20-50 kicks per node (portc 2,000 and
/// 5,000, pcb3038), was neutral or lost within the spread at 7-40 (fnl4461, Gaussian clusters of
/// 2,000-10,000 points, portc 10,000).
pub const BREADTH_KICKS_PER_NODE: f64 = 40.0;

/// Kicks per node a budget must allow for chains to backtrack over three first-level moves:
/// on portc-2000 three lost to two at 10 s (100 per node as [`SolveOptions::lk_breadth`]
/// counts them) and gained at 30 s (300), as on portc-5000 at 68 s (272; 3 seeds each).
pub const BREADTH3_KICKS_PER_NODE: f64 = 200.0;

/// Time one kick takes on one thread, for turning a time limit into kicks (about 10,000 a
/// second on fnl4461; see `bench/kick_rate.py`).
const KICK_SECONDS: f64 = 100e-6;

/// The first-level breadth of 3-opt chains: as asked, else by the budget's kicks per node.
fn lk_breadth<C: CostModel>(net: &Net<C>, opts: &SolveOptions, threads: usize) -> usize {
    if let Some(b) = opts.lk_breadth {
        return b.clamp(1, local::lk3::MAX_BREADTH1);
    }
    let n = net.n.max(1) as f64;
    let per_node = match (opts.iterations, opts.time_limit) {
        (Some(it), _) => it as f64 / n,
        (None, Some(tl)) => tl.as_secs_f64() * threads as f64 / KICK_SECONDS / n,
        (None, None) => 0.0,
    };
    if per_node >= BREADTH3_KICKS_PER_NODE {
        3
    } else if per_node >= BREADTH_KICKS_PER_NODE {
        2
    } else {
        1
    }
}

/// Epochs a search plans: its budget is spent in this many rounds of kicks (fewer when a time
/// limit makes an epoch longer than 2 s), each ending with the chains sharing their best.
const EPOCHS_PLANNED: usize = 20;

/// The end of an epoch: the best chain wins (lowest index on ties); where the chains' tours can
/// be merged, the merge keeps every chain's improvements instead of only the best chain's; chains
/// that fell behind adopt the best.
fn share_best<C: CostModel>(
    net: &Net<C>,
    ils: &Ils<'_, '_, C>,
    best: &mut Tour,
    chains: &mut [ils::Chain],
    merge_chains: bool,
    search_end: Option<Instant>,
    eps: Cost,
) {
    take_cheapest(best, chains, eps);
    if merge_chains {
        merge_into_best(net, ils, best, chains, search_end, eps);
    }
    for c in chains.iter_mut() {
        if c.best.cost > best.cost + eps {
            c.adopt(best);
        }
    }
}

/// Makes `best` the cheapest chain's best tour where that is cheaper (the lowest index on ties).
fn take_cheapest(best: &mut Tour, chains: &[ils::Chain], eps: Cost) {
    for c in chains {
        if c.best.cost < best.cost - eps {
            best.clone_from(&c.best);
        }
    }
}

/// Merges each chain's best tour into `best` in turn by partition crossover (plain symmetric
/// one-mode tours), each merge polished by the local search and kept when cheaper.
fn merge_into_best<C: CostModel>(
    net: &Net<C>,
    ils: &Ils<'_, '_, C>,
    best: &mut Tour,
    chains: &[ils::Chain],
    search_end: Option<Instant>,
    eps: Cost,
) {
    for c in chains {
        if let Some((seq, changed)) = merge::partition_crossover(net, best, &c.best, eps) {
            let mut child = Tour::new(net, seq, vec![0; net.n]);
            if ils.polish(&mut child, &changed, search_end) && child.cost < best.cost - eps {
                *best = child;
            }
        }
    }
}

/// Fraction of the budget used, in 0..=1: of the work budget when there is one, else of the
/// time limit; `None` without either.
fn budget_used(opts: &SolveOptions, t0: Instant, iterations: u64) -> Option<f64> {
    let f = match (opts.time_limit, opts.iterations) {
        (_, Some(it)) => iterations as f64 / it as f64,
        (Some(tl), None) => t0.elapsed().as_secs_f64() / tl.as_secs_f64(),
        (None, None) => return None,
    };
    Some(f.min(1.0))
}

/// Temperature of the kick acceptance at a fraction `frac` of the budget. Under precedence,
/// where kicks are few and the search easily stays in one basin, a kick that makes the tour
/// dearer by Δ is kept with probability exp(-Δ/T) (simulated-annealing acceptance); T starts at
/// twice the mean arc of the best tour and falls as (1 - frac)² (chosen on TSPLIB SOP and
/// SOPLIB instances; the figures are in the history of this function). Other problems keep
/// "not worse" acceptance.
fn acceptance_temperature<C: CostModel>(net: &Net<C>, best: Cost, frac: f64) -> Cost {
    if !net.has_prec {
        return 0.0;
    }
    let mean_arc = if best.abs() < net.forbidden { best.abs() / net.n as f64 } else { net.typical_arc };
    2.0 * mean_arc * (1.0 - frac).powi(2)
}

/// Record-to-record slack of the kick acceptance on plain tours, in mean arcs of the best tour:
/// a kicked and repaired tour is kept while it costs at most the chain's best plus this (the
/// record-to-record travel of Dueck 1993). 10 s, 2 threads, medians with no slack -> 0.03,
/// alternating by seed: gauss-2000 seeds 1-6 735,393 -> 735,236 and seeds 7-14 735,246 ->
/// 735,236 (worst run 736,367 -> 735,762); portc-2000 1,093,812 -> 1,093,938 and 1,093,865 ->
/// 1,093,724; seeds 1-6: gauss-5000 1,094,728 -> 1,093,696, portc-5000 1,767,100 -> 1,766,768,
/// pcb3038 137,758 -> 137,732, fnl4461 182,648 -> 182,676, gauss-10000 within the spread.
/// 0.05 and 0.1 did no better on the 2,000-point files.
const RECORD_SLACK: f64 = 0.03;

/// Slack of the kick acceptance (see [`RECORD_SLACK`]): on plain tours only (the 3-opt chains'
/// problems with no two-way tasks); precedence has its annealing instead
/// ([`acceptance_temperature`]), other problems accept no dearer tour.
fn acceptance_slack<C: CostModel>(net: &Net<C>, best: Cost) -> Cost {
    if !local::plain_tour(net) || best.abs() >= net.forbidden {
        return 0.0;
    }
    RECORD_SLACK * best.abs() / net.n as f64
}

/// Share of a time limit the construction and the first descents may take. On seed-004-like
/// rural-postman instances (20–40 required edges, 0.8 ms, one thread) a tenth reached the
/// 100 ms answer in 53–60 of 125 runs, a quarter in 40–44: kicks pay more than starts.
const START_SHARE: f64 = 0.1;

/// Share of a time limit that decides between descending from one start or from three.
const DESCENT_SHARE: f64 = 0.25;

/// Time of one arc evaluation, as assumed when sizing work to a time limit.
const ARC_SECONDS: f64 = 5e-9;

/// True when the time limit is too short to spend on descending from several starts (three
/// descents taken as four times a construction's work each).
fn pool_is_short(opts: &SolveOptions, work: f64) -> bool {
    opts.time_limit.is_some_and(|tl| tl.as_secs_f64() * DESCENT_SHARE < 3.0 * 4.0 * work * ARC_SECONDS)
}

fn optimize_final<C: CostModel>(net: &Net<C>, tour: &mut Tour, eps: Cost) {
    // wrapped reversals may have moved the anchor off position 0
    tour.rotate_to(net.anchor);
    modes::optimize_modes(net, tour, eps);
    tour.cost = tour.full_cost(net);
}

fn tour_from_steps<C: CostModel>(net: &Net<C>, steps: &[Step]) -> Tour {
    let mut seq = Vec::with_capacity(net.n);
    let mut mode = vec![0u32; net.n];
    if net.depot != u32::MAX {
        seq.push(net.depot);
    }
    for s in steps {
        seq.push(s.task.0);
        mode[s.task.index()] = s.mode;
    }
    construct::rotate_to_anchor(net, &mut seq);
    Tour::new(net, seq, mode)
}

fn steps_from_tour<C: CostModel>(net: &Net<C>, tour: &Tour) -> Vec<Step> {
    tour.nodes().filter(|&(v, _)| v != net.depot).map(|(v, m)| Step { task: TaskId(v), mode: m }).collect()
}

/// How much longer the candidate lists of two-way tasks' ends are (see `two_way`).
const LIST_FACTOR_ENDS: usize = 2;

/// Above this many tasks the construction is a space-filling curve (nearest neighbour is
/// quadratic).
const SPACE_FILLING_FROM: usize = 12_000;

/// Quadrant neighbours per quadrant in the candidate lists of large planar tours (see
/// `neighbors::quadrant_lists`), beside the nearest ones that fill the rest of the list.
const QUADRANT_K: usize = 2;

/// Share of the time limit the branch and bound on the assignment may take (see
/// [`assignment_start`]); it stops sooner when it proves its route optimal.
const AP_BRANCH_SHARE: f64 = 0.25;

/// Longest the branch and bound on the assignment may take whatever the limit: the searches
/// that prove their route do so within a second on 600 nodes (measured on TSPLIB ATSP and
/// SOPLIB), and the first progress report waits for it.
const AP_BRANCH_MAX: Duration = Duration::from_secs(5);

/// Branch-and-bound nodes per tour node when no time limit is set.
const AP_BRANCH_NODES_PER_NODE: u64 = 20;

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    use super::testing::random_tour_problem;
    use super::*;

    /// Chains backtrack over two first-level moves only where the budget gives about 40 kicks a
    /// node, over three from 200; an explicit breadth is kept within 1..=4.
    #[test]
    fn lk_breadth_follows_the_budget() {
        let p = random_tour_problem(&mut Pcg64Mcg::seed_from_u64(1), 500, 1000.0);
        let net = Net::new(&p);
        let worked = |it: u64| SolveOptions { time_limit: None, iterations: Some(it), ..Default::default() };
        let at = (BREADTH_KICKS_PER_NODE * net.n as f64).ceil() as u64;
        assert_eq!(lk_breadth(&net, &worked(at), 2), 2);
        assert_eq!(lk_breadth(&net, &worked(at - 1), 2), 1);
        let at3 = (BREADTH3_KICKS_PER_NODE * net.n as f64).ceil() as u64;
        assert_eq!(lk_breadth(&net, &worked(at3 - 1), 2), 2);
        assert_eq!(lk_breadth(&net, &worked(at3), 2), 3);
        // 10 s on 2 threads: 200,000 kicks, 3 at 1,000 nodes and below, 2 at 5,000 and below
        let timed = |secs: f64| SolveOptions { time_limit: Some(Duration::from_secs_f64(secs)), ..Default::default() };
        let limit = |n: usize, per: f64| 10.0 * 2.0 / KICK_SECONDS / per >= n as f64;
        assert!(limit(5000, BREADTH_KICKS_PER_NODE) && !limit(5001, BREADTH_KICKS_PER_NODE));
        assert!(limit(1000, BREADTH3_KICKS_PER_NODE) && !limit(1001, BREADTH3_KICKS_PER_NODE));
        assert_eq!(lk_breadth(&net, &timed(10.0), 2), 3);
        assert_eq!(lk_breadth(&net, &timed(1.0), 2), 2);
        assert_eq!(lk_breadth(&net, &timed(0.01), 2), 1);
        for (asked, got) in [(0, 1), (1, 1), (3, 3), (9, local::lk3::MAX_BREADTH1)] {
            let opts = SolveOptions { lk_breadth: Some(asked), ..timed(0.01) };
            assert_eq!(lk_breadth(&net, &opts, 2), got);
        }
    }

    /// Every breadth gives a deterministic solve under a work budget whose route the checker
    /// agrees with.
    #[test]
    fn solves_at_every_breadth_are_deterministic_and_checked() {
        let p = random_tour_problem(&mut Pcg64Mcg::seed_from_u64(7), 120, 1000.0);
        for breadth in 1..=local::lk3::MAX_BREADTH1 {
            let opts = SolveOptions {
                time_limit: None,
                iterations: Some(3_000),
                threads: 2,
                seed: 3,
                lk_breadth: Some(breadth),
                ..Default::default()
            };
            let a = solve(&p, &opts).expect("solves");
            let b = solve(&p, &opts).expect("solves");
            assert_eq!(a.solution.steps, b.solution.steps, "breadth {breadth}");
            let cost = check(&p, &a.solution.steps).expect("feasible");
            assert!((cost - a.solution.cost).abs() < 1e-6 * cost, "breadth {breadth}");
        }
    }

    /// Plain tours of 4,000 to 12,000 points start from the nearest neighbour through lists:
    /// their candidate lists (quadrant lists: without a time limit above 8,000 points) or, when
    /// those take an α pass, the nearest lists, whose tour gives the ascent its step length;
    /// such a solve is deterministic and checked.
    #[test]
    fn large_plain_tours_start_from_their_lists() {
        let worked = SolveOptions { time_limit: None, iterations: Some(200), threads: 2, ..Default::default() };
        let small = random_tour_problem(&mut Pcg64Mcg::seed_from_u64(5), 3_000, 10_000.0);
        assert!(!lists_before_starts(&Net::new(&small)));
        for (n, alpha) in [(4_500, true), (8_500, false)] {
            let p = random_tour_problem(&mut Pcg64Mcg::seed_from_u64(5), n, 10_000.0);
            let net = Net::new(&p);
            assert!(lists_before_starts(&net));
            assert_eq!(alpha_plan(&net, &worked, 2).is_some(), alpha, "{n} points");
            let a = solve(&p, &worked).expect("solves");
            let b = solve(&p, &worked).expect("solves");
            assert_eq!(a.solution.steps, b.solution.steps);
            assert_eq!(a.solution.steps.len(), n);
            let cost = check(&p, &a.solution.steps).expect("feasible");
            assert!((cost - a.solution.cost).abs() < 1e-6 * cost, "{n} points");
        }
    }
}
