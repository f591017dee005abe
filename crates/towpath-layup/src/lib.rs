//! towpath-layup: AFP course generation on mold surfaces.
//!
//! - [`field`]: design directions (rosette axis, guide curves, orientation samples) with the ply
//!   angle (seed 001 Algorithms 3 and 5, seed 002 eq. 6).
//! - [`trace`]: course tracing across triangles in both directions (seed 001 Algorithm 4), field
//!   steered or geodesic, with smooth normals.
//! - [`ply`]: covering a ply with parallel courses (seed 002 §3–4) — [`ply::plan`] is the entry
//!   point — with [`section`] trimming every tow at the ply boundary ([`boundary`]) under a
//!   coverage rule, and [`quality`] figures; on a closed surface a closing course is trimmed
//!   against the courses already laid ([`laid`]).
//! - [`accuracy`]: deviations from closed-form geodesics on analytic surfaces (seed 001 §4).
//! - [`output`]: courses as JSON, CSV and a G-code program.
//! - [`request`]: a whole job as one call — [`request::LayupRequest`] (what the command line
//!   and a server fill in), validated in one place, its work bounded before it starts, run by
//!   [`request::run`] to a [`request::LayupResult`] with warnings; [`units`]: input units.

// `!(a > b)` is used on purpose: it is also true when a or b is NaN, which input checks rely on.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accuracy;
pub mod boundary;
pub mod course;
pub mod field;
pub mod input;
pub mod laid;
pub mod output;
pub mod ply;
pub mod quality;
pub mod request;
pub mod section;
pub mod trace;
pub mod units;
