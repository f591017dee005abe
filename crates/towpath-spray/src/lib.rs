//! # towpath-spray: spray forming and painting
//!
//! Plans how a spray robot covers a part to a target thickness, as evenly as possible, with the
//! least travel, after Tewolde & Sheng (2008) (§II–III, Fig. 3): divide and conquer.
//!
//! 1. [`partition`](mod@partition): the part is split into hole-free, nearly convex cells (topology) and then
//!    into flat patches by region growing under a maximum deviation angle β_th; the patches form
//!    an adjacency graph.
//! 2. [`passes`]: each patch gets zigzag passes along the sweep direction with the fewest turns,
//!    or a spiral of rings, at the spacing that minimises the thickness error of the
//!    [deposition model](deposition) ([`spacing`]), running out past free and sharp edges, with
//!    the gun at the standoff along the surface normal; the speed gives the target thickness.
//! 3. [`sequence`]: every pass is a task with two directions; towpath's solver (or the paper's
//!    GA / ant colony, `towpath-baselines`) orders them into one open path from an optional home,
//!    [`transit`]s lifting where a straight move would come closer to the part than the standoff
//!    allows, priced as they are written.
//! 4. [`path`]: the poses with time stamps; [`modulation`]: the speed along the passes adjusted
//!    so the thickness is as even as the passes allow (seams included); [`thickness`]: the
//!    predicted thickness on the part from any path; [`output`]: the path file, CSV, thickness
//!    PLY and summary.
//!
//! [`plan()`] runs steps 1–4. Lengths are in mm, times in s, thickness in µm, flow in mm³/s.

// `!(a > b)` is used on purpose: it is also true when a or b is NaN, which input checks rely on.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![warn(missing_docs)]

pub mod deposition;
mod error;
pub mod frame;
pub mod modulation;
pub mod output;
pub mod partition;
pub mod passes;
pub mod path;
mod plan;
pub mod profile;
pub mod sequence;
mod slicer;
pub mod spacing;
pub mod thickness;
pub mod transit;

pub use deposition::{simulate, Gun, Pose, SamplePoints, DEFAULT_FLOW};
pub use error::SprayError;
pub use partition::{partition, Partition, PartitionOptions, Patch};
pub use passes::{Pass, PatchPlan, Pattern, PatternChoice};
pub use plan::{plan, SprayParams, SprayPlan, Timings, DEFAULT_MAX_DEVIATION, DEFAULT_TRAVEL_SPEED, MAX_PASSES};
pub use profile::Profile;
pub use sequence::SeqOptions;
pub use thickness::{ThicknessMap, ThicknessStats};
pub use towpath_baselines::SolverName;
