//! Topology partition (placeholder until the next step): the piece as one cell.

use towpath_geom::Mesh;

/// Splits a projectable piece into hole-free, nearly convex cells.
pub fn split(_mesh: &Mesh, faces: &[u32], _scale: f64) -> Vec<Vec<u32>> {
    vec![faces.to_vec()]
}
