//! # towpath-motion: motion safety
//!
//! Every move towpath writes is checked against the cell (the mold tool, fixtures and
//! stringers) and the machine's travel limits, and transits go over obstacles only as high as
//! they must. `docs/motion.md` describes the model in full.
//!
//! - [`Cell`]: the obstacle meshes, in the part frame (which turns with the mandrel), merged
//!   under one bounding volume hierarchy (parry's [`parry3d_f64::partitioning::Bvh`]).
//! - [`Rig`]: the machine's kinematics ([`towpath_machine::Kinematics`]) with an optional
//!   [`Head`] (a capsule along the tool axis, the `[head]` table of the machine file):
//!   the tool point and head axis in the part frame for an axis state, and a bound on how
//!   sharply a move's path bends ([`Rig::bend_bound`]).
//! - [`Checker`]: checks one move (all axes interpolated linearly together, wrapping axes the
//!   short way) for its least clearance, collision, near miss and axis-limit violations
//!   ([`MoveCheck`]). The path is cut into pieces whose chords it leaves by at most M·h²/8; each
//!   piece's exact distance (segment or swept quadrilateral against every triangle under the
//!   BVH) is widened by that error, and pieces are split until the answer is known within the
//!   tolerance. Reported clearances are lower bounds at most the tolerance below the truth, so
//!   no collision is missed. Moves that start or end on the part ([`Contact`]) count only
//!   collisions near that end.
//! - [`Planner`]: one transit rule for pricing and writing. Straight when that keeps the
//!   clearance; otherwise up (along the tool axis, a clearance axis, or radially away from the
//!   mandrel), across at one level, and down, at the least level that clears, found by
//!   doubling then bisection to within a step. A typed [`PlanError`] when no level within the
//!   travel limits clears.
//! - [`TransitCost`]: a [`towpath_seq::CostModel`] pricing each arc as its planned transit
//!   under a [`towpath_machine::MachineCost`], cached for the solver.
//! - [`check_laid_points`], [`check_mandrel_radius`], [`check_states`]: degenerate set-ups
//!   refused with a [`SetupError`].

#![warn(missing_docs)]
// `!(a > b)` is used on purpose: it is also true when a or b is NaN, which input checks rely on.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod cell;
mod check;
mod cost;
mod error;
mod geometry;
mod head;
mod plan;
mod rig;
mod setup;

pub use cell::Cell;
pub use check::{Body, CheckOptions, Checker, Contact, LimitViolation, MoveCheck};
pub use cost::TransitCost;
pub use error::{CellError, PlanError, SetupError};
pub use plan::{LiftRule, PlanOptions, Planner, Transit};
pub use rig::{Pose, Rig};
pub use setup::{check_laid_points, check_mandrel_radius, check_states};
pub use towpath_machine::Head;
