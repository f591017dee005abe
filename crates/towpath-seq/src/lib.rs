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
//!
//! This crate knows nothing of files, programs or HTTP.

#![warn(missing_docs)]

mod cost;
mod exact;
mod model;
mod precedence;
mod search;
mod solution;

pub use cost::{Cost, CostModel, MatrixCost, Metric, PointCost, StateId};
pub use exact::{solve_exact, ExactError, MAX_EXACT_TASKS};
pub use model::{End, Mode, ModelError, Problem, ProblemBuilder, TaskId};
pub use precedence::Precedence;
pub use search::{solve, Progress, ProgressFn, SolveError, SolveOptions, SolveReport};
pub use solution::{check, Solution, Step, Violation};
