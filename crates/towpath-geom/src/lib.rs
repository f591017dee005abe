//! towpath-geom: the geometry of mold surfaces.
//!
//! - [`Soup`]: triangles as read from a file (STL, OBJ, PLY; see [`io`]), before any repair.
//! - [`Mesh`]: a welded, oriented triangle mesh with topology (edge, face and vertex adjacency,
//!   boundary loops), area-weighted vertex normals and a spatial index for closest points, built by
//!   [`Mesh::build`] which reports every repair it made in a [`RepairReport`].
//! - [`SurfacePoint`]: a point on a mesh (face and barycentric coordinates) with its smooth
//!   (interpolated) normal.
//! - [`surface`]: analytic surfaces (plane, cylinder, cone, sphere) with exact normals and closest
//!   points, tensor-product B-spline/NURBS patches, and [`surface::tessellate`] under a chord
//!   tolerance and a maximum edge length.
//!
//! The crate knows nothing of fibers, plies or files other than mesh formats.

// `!(a > b)` is used on purpose: it is also true when a or b is NaN, which input checks rely on.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod closest;
mod error;
pub mod io;
mod mesh;
mod soup;
pub mod surface;
mod topology;
mod weld;

pub use closest::closest_point_on_triangle;
pub use error::MeshError;
pub use glam::DVec3;
pub use mesh::{BuildOptions, Mesh, RepairReport, SurfacePoint, NO_FACE};
pub use soup::Soup;
pub use weld::weld;
