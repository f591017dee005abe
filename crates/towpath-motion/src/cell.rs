//! The cell: every obstacle triangle (mold tool, fixtures, stringers) in the part frame, under
//! one bounding volume hierarchy, with the distance queries the move checker asks.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode, TraversalAction};
use towpath_geom::{DVec3, Soup};

use crate::error::CellError;
use crate::geometry::{segment_box_linf, segment_hits_box, segment_triangle_dist, triangle_triangle_dist};

/// Triangles per BVH leaf: consecutive triangles in Morton order of their centres share a leaf,
/// which makes the tree several times quicker to build than one leaf per triangle.
const LEAF_SIZE: usize = 4;

/// The obstacles of a cell, merged into one BVH (parry's binned-SAH [`Bvh`]).
///
/// Build it once per cell with [`Cell::from_soups`] (the meshes as read by
/// [`towpath_geom::io`]) and share it: queries take `&self` and the cell is `Send + Sync`.
#[derive(Clone)]
pub struct Cell {
    /// Triangle corners, in leaf order.
    tris: Vec<[DVec3; 3]>,
    /// Leaf `i` holds triangles `i·LEAF_SIZE ..`.
    bvh: Bvh,
    bounds: Option<(DVec3, DVec3)>,
}

impl std::fmt::Debug for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cell").field("triangles", &self.tris.len()).field("bounds", &self.bounds).finish()
    }
}

fn to_parry(v: DVec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn arr(v: Vector) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// A 30-bit Morton code of a point in the box `lo .. lo + 1/inv`.
fn morton(p: DVec3, lo: DVec3, inv: DVec3) -> u32 {
    fn spread(mut x: u32) -> u32 {
        x &= 0x3ff;
        x = (x | (x << 16)) & 0x030000ff;
        x = (x | (x << 8)) & 0x0300f00f;
        x = (x | (x << 4)) & 0x030c30c3;
        x = (x | (x << 2)) & 0x09249249;
        x
    }
    let q = (p - lo) * inv * 1023.0;
    let c = |v: f64| v.clamp(0.0, 1023.0) as u32;
    spread(c(q.x)) | (spread(c(q.y)) << 1) | (spread(c(q.z)) << 2)
}

impl Cell {
    /// A cell with no obstacles: every move is clear.
    pub fn empty() -> Cell {
        Cell { tris: Vec::new(), bvh: Bvh::new(), bounds: None }
    }

    /// The cell of these meshes (in the part frame), merged. Refuses meshes with indices out of
    /// range or coordinates that are not finite, naming the mesh.
    pub fn from_soups(soups: &[Soup]) -> Result<Cell, CellError> {
        let mut tris = Vec::with_capacity(soups.iter().map(|s| s.triangles.len()).sum());
        for (mesh, s) in soups.iter().enumerate() {
            s.validate().map_err(|source| CellError::Mesh { mesh, source })?;
            tris.extend(s.triangles.iter().map(|t| t.map(|i| s.positions[i as usize])));
        }
        Ok(Cell::from_triangles(tris))
    }

    /// The cell of these triangles (corners in the part frame; every coordinate must be finite,
    /// as [`Cell::from_soups`] checks).
    pub fn from_triangles(mut tris: Vec<[DVec3; 3]>) -> Cell {
        tris.retain(|t| t.iter().all(|p| p.is_finite()));
        if tris.is_empty() {
            return Cell::empty();
        }
        let (mut lo, mut hi) = (tris[0][0], tris[0][0]);
        for t in &tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        // Morton order of the centres, so that a leaf's triangles lie close together.
        let ext = (hi - lo).max(DVec3::splat(1e-9));
        let inv = DVec3::ONE / ext;
        let mut keyed: Vec<(u32, u32)> =
            tris.iter().enumerate().map(|(i, t)| (morton((t[0] + t[1] + t[2]) / 3.0, lo, inv), i as u32)).collect();
        keyed.sort_unstable();
        let tris: Vec<[DVec3; 3]> = keyed.iter().map(|&(_, i)| tris[i as usize]).collect();
        let leaves: Vec<Aabb> = tris
            .chunks(LEAF_SIZE)
            .map(|chunk| {
                let (mut a, mut b) = (chunk[0][0], chunk[0][0]);
                for t in chunk {
                    for p in t {
                        a = a.min(*p);
                        b = b.max(*p);
                    }
                }
                Aabb::new(to_parry(a), to_parry(b))
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        Cell { tris, bvh, bounds: Some((lo, hi)) }
    }

    /// Number of obstacle triangles.
    pub fn num_triangles(&self) -> usize {
        self.tris.len()
    }

    /// The triangles, in the cell's own order.
    pub fn triangles(&self) -> &[[DVec3; 3]] {
        &self.tris
    }

    /// The bounding box of every obstacle, `None` for an empty cell.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.bounds
    }

    /// The largest distance of an obstacle point from the line through `origin` along the unit
    /// vector `dir` (0 for an empty cell).
    pub fn max_radius(&self, origin: DVec3, dir: DVec3) -> f64 {
        let mut r2: f64 = 0.0;
        for t in &self.tris {
            for p in t {
                let v = *p - origin;
                r2 = r2.max((v - dir * v.dot(dir)).length_squared());
            }
        }
        r2.sqrt()
    }

    fn leaf(&self, leaf: u32) -> &[[DVec3; 3]] {
        let a = leaf as usize * LEAF_SIZE;
        let b = (a + LEAF_SIZE).min(self.tris.len());
        self.tris.get(a..b).unwrap_or(&[])
    }

    /// The distance from segment `p q` to the nearest obstacle, or `cap` if nothing is nearer
    /// than `cap`. The search stops as soon as something is found at or below `stop`, returning
    /// that distance (pass a negative `stop` for the exact minimum).
    pub fn segment_distance(&self, p: DVec3, q: DVec3, cap: f64, stop: f64) -> f64 {
        let (pa, d) = ([p.x, p.y, p.z], [q.x - p.x, q.y - p.y, q.z - p.z]);
        let mut best = cap;
        self.bvh.traverse(|node: &BvhNode| {
            if !segment_hits_box(pa, d, arr(node.mins()), arr(node.maxs()), [best; 3]) {
                return TraversalAction::Prune;
            }
            if let Some(leaf) = node.leaf_data() {
                let mut found = f64::INFINITY;
                for t in self.leaf(leaf) {
                    found = found.min(segment_triangle_dist(p, q, t));
                }
                best = best.min(found);
                if found <= stop {
                    return TraversalAction::EarlyExit;
                }
            }
            TraversalAction::Continue
        });
        best
    }

    /// The distance from the quadrilateral `a0 b0 b1 a1`, taken as the two triangles
    /// `a0 b0 b1` and `a0 b1 a1`, to the nearest obstacle, or `cap` if nothing is nearer;
    /// stops early at or below `stop` like [`Cell::segment_distance`]. (The head's sweep over a
    /// piece of a move: `a` the bottom and `b` the top of its axis at either end.)
    pub fn quad_distance(&self, a0: DVec3, b0: DVec3, b1: DVec3, a1: DVec3, cap: f64, stop: f64) -> f64 {
        let (m0, m1) = ((a0 + b0) * 0.5, (a1 + b1) * 0.5);
        let (h0, h1) = (b0 - a0, b1 - a1);
        let half = [
            0.5 * h0.x.abs().max(h1.x.abs()),
            0.5 * h0.y.abs().max(h1.y.abs()),
            0.5 * h0.z.abs().max(h1.z.abs()),
        ];
        let quad = [[a0, b0, b1], [a0, b1, a1]];
        let (pa, d) = ([m0.x, m0.y, m0.z], [m1.x - m0.x, m1.y - m0.y, m1.z - m0.z]);
        let mut best = cap;
        self.bvh.traverse(|node: &BvhNode| {
            // Every point of the quadrilateral is within `half` (per axis) of its spine m0 m1.
            let grow = [best + half[0], best + half[1], best + half[2]];
            if !segment_hits_box(pa, d, arr(node.mins()), arr(node.maxs()), grow) {
                return TraversalAction::Prune;
            }
            if let Some(leaf) = node.leaf_data() {
                let mut found = f64::INFINITY;
                for t in self.leaf(leaf) {
                    for q in &quad {
                        found = found.min(triangle_triangle_dist(q, t));
                    }
                }
                best = best.min(found);
                if found <= stop {
                    return TraversalAction::EarlyExit;
                }
            }
            TraversalAction::Continue
        });
        best
    }

    /// The least distance from segment `p q` to the obstacles, found best first (nearest BVH
    /// node first, by its L∞ distance): the answer `d` (or `cap` when nothing is nearer)
    /// is within `slack` above the truth — nodes that cannot hold anything nearer than
    /// `d − slack` are not opened. Much quicker than the exact search when a long segment runs
    /// at a near-constant distance from a dense mesh.
    pub fn segment_min(&self, p: DVec3, q: DVec3, cap: f64, slack: f64) -> f64 {
        let (pa, d) = ([p.x, p.y, p.z], [q.x - p.x, q.y - p.y, q.z - p.z]);
        self.bvh
            .find_best(
                cap,
                |node: &BvhNode, _| segment_box_linf(pa, d, arr(node.mins()), arr(node.maxs()), [0.0; 3]) + slack,
                |leaf, _| Some(self.leaf(leaf).iter().map(|t| segment_triangle_dist(p, q, t)).fold(f64::INFINITY, f64::min)),
            )
            .map_or(cap, |(_, d)| d.min(cap))
    }

    /// [`Cell::quad_distance`] found best first, within `slack` above the truth like
    /// [`Cell::segment_min`].
    pub fn quad_min(&self, a0: DVec3, b0: DVec3, b1: DVec3, a1: DVec3, cap: f64, slack: f64) -> f64 {
        let (m0, m1) = ((a0 + b0) * 0.5, (a1 + b1) * 0.5);
        let (h0, h1) = (b0 - a0, b1 - a1);
        let half = [
            0.5 * h0.x.abs().max(h1.x.abs()),
            0.5 * h0.y.abs().max(h1.y.abs()),
            0.5 * h0.z.abs().max(h1.z.abs()),
        ];
        let quad = [[a0, b0, b1], [a0, b1, a1]];
        let (pa, d) = ([m0.x, m0.y, m0.z], [m1.x - m0.x, m1.y - m0.y, m1.z - m0.z]);
        self.bvh
            .find_best(
                cap,
                |node: &BvhNode, _| segment_box_linf(pa, d, arr(node.mins()), arr(node.maxs()), half) + slack,
                |leaf, _| {
                    Some(
                        self.leaf(leaf)
                            .iter()
                            .flat_map(|t| quad.iter().map(move |q| triangle_triangle_dist(q, t)))
                            .fold(f64::INFINITY, f64::min),
                    )
                },
            )
            .map_or(cap, |(_, d)| d.min(cap))
    }

    /// The distance from point `p` to the nearest obstacle, or `cap` if nothing is nearer.
    pub fn point_distance(&self, p: DVec3, cap: f64) -> f64 {
        self.segment_distance(p, p, cap, -1.0)
    }
}
