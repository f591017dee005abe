//! # towpath-seq: the sequencing engine
//!
//! One model for every toolpath-ordering job. A [`Problem`] holds **tasks** (pieces of
//! productive motion done exactly once), each with one or more [`Mode`]s (ways of doing it, with
//! entry and exit states), a precedence DAG, optional consecutive groups, and the route's ends.
//! Transition costs come from a [`CostModel`]: a dense [`MatrixCost`], on-demand [`PointCost`]
//! distances, or any model another crate provides (machine motion, for instance).
//!
//! - [`solve`] runs towpath's solver: construction (nearest neighbour from Doherty et al.'s
//!   (2022) seed pool, or a space-filling curve on huge instances), α-nearness candidate lists
//!   (Helsgaun 2000), local search (Lin–Kernighan chains of 2-opt or sequential 3-opt moves,
//!   Or-opt, segment exchange, mode re-selection by exact DP over a layered graph) and iterated
//!   local search on several threads whose best tours are merged by a partition crossover,
//!   within a time or work budget. Deterministic under a work budget.
//! - [`solve_exact`] is Held–Karp dynamic programming for small instances.
//! - [`check`] independently verifies a route and recomputes its cost.
//! - [`Clock`] is the one deadline and cancel flag of a run, shared by every solver and by the
//!   instance builders that run before them.
//!
//! Costs are `f64`s. A problem whose route could cost more than [`MAX_ROUTE_COST`] is refused
//! when it is built (for the models that know a bound on their costs, see
//! [`CostModel::cost_bound`]), so sums never overflow; integer costs are exact while a route's
//! total stays below [`EXACT_INTEGER_LIMIT`].
//!
//! This crate knows nothing of files, programs or HTTP.

#![warn(missing_docs)]

mod clock;
mod cost;
mod exact;
mod model;
mod precedence;
mod search;
mod solution;

pub use clock::Clock;
pub use cost::{
    ceil_nonneg, nint, norm, Cost, CostModel, MatrixCost, Metric, PlanarEuclid, PointCost, PointMetric, Rounding,
    StateId, EXACT_INTEGER_LIMIT, MAX_ROUTE_COST,
};
pub use exact::{solve_exact, ExactError, MAX_EXACT_TASKS};
pub use model::{End, Mode, ModelError, Problem, ProblemBuilder, TaskId};
pub use precedence::Precedence;
pub use search::{
    solve, solve_reversible, Progress, ProgressFn, SolveError, SolveOptions, SolveReport, BREADTH3_KICKS_PER_NODE,
    BREADTH_KICKS_PER_NODE, MAX_REVERSIBLE_TASKS, MAX_THREADS,
};
pub use solution::{check, Solution, Step, Violation};
