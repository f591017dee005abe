//! # towpath-baselines: the seed papers' own algorithms, beside towpath's solver
//!
//! Each seed system works here as its paper describes it, on the generic
//! [`towpath_seq::Problem`] model, so users and reviewers can compare them with towpath's solver
//! on the same inputs:
//!
//! - [`solve_doherty`] — seed 000 §3.2: per precedence set, a seed pool with nearest neighbour,
//!   then a depth-first and a breadth-first local search ([`DohertyParams`]).
//! - [`solve_castelino`] — seed 003: the generalized TSP with precedence turned into an ATSP of
//!   size 2n (Dimitrijevic–Saric), solved by towpath's SOP/TSP search, mapped back
//!   ([`transform`], [`map_back`]).
//! - [`solve_ga`] — seed 004 §IV: order crossover with direction bits, reciprocal-exchange
//!   mutation ([`GaParams`]).
//! - [`solve_aco`] — seed 004 §V: an ant system with one (ACO1) or two (ACO2) ants per required
//!   edge ([`AcoParams`]).
//!
//! [`solve_with`] runs any of them, or towpath's own [`towpath_seq::solve`], by
//! [`SolverName`], so every command that sequences can offer `--solver NAME`. Every answer is
//! checked with [`towpath_seq::check`] before it is returned, and a given initial route is
//! returned instead when it is cheaper. The randomized solvers are repeatable by
//! `SolveOptions::seed`; the deterministic ones are bit-for-bit repeatable. All stop early when
//! `SolveOptions::time_limit` passes or `cancel` is set (only then may a run differ).
//!
//! Mapping of the papers' objects to the model: a required edge (seed 004) is a task with two
//! modes (one per direction); an AFP course (seed 000) is a task with forward and, when
//! bidirectional layup is allowed, reverse modes; a GTSP cluster / toolpath cell (seed 003) is a
//! task with one mode per candidate entry node.

#![warn(missing_docs)]

mod aco;
mod castelino;
mod common;
mod doherty;
mod ga;
mod generate;
mod order;
mod registry;

pub use aco::{solve_aco, update_trails, AcoParams, ACO_MAX_ANTS_PER_TASK, ACO_MAX_STATES, ACO_MAX_WALK};
pub use castelino::{
    lift, map_back, solve_castelino, transform, transformed_problem, CastelinoParams, Transformed, CASTELINO_MAX_NODES,
    CASTELINO_MAX_PRECEDENCE_PAIRS,
};
pub use doherty::{
    sets_from_precedence, solve_doherty, solve_doherty_traced, DohertyParams, PrecedenceSet, SetTrace, DOHERTY_MAX_PASS,
};
pub use ga::{bit_crossover, order_crossover, solve_ga, GaParams, GA_MAX_BYTES, GA_MAX_RATE};
pub use generate::random_gtsp;
pub use registry::{solve_with, BaselineError, BaselineParams, SolverName};
