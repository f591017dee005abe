//! The cell: every obstacle triangle (mold tool, fixtures, stringers) in the part frame, under
//! one bounding volume hierarchy, with the distance queries the move checker asks.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode, TraversalAction};
use towpath_geom::{DVec3, Soup};

use crate::error::CellError;
use crate::geometry::{segment_box_dist, segment_hits_box, segment_triangle_dist, triangle_triangle_dist};

/// Triangles per BVH leaf: consecutive triangles in Morton order of their centres share a leaf,
/// which makes the tree several times quicker to build than one leaf per triangle.
const LEAF_SIZE: usize = 8;

/// Cells with more triangles than this build their hierarchy in two halves on two threads.
const SPLIT_ABOVE: usize = 100_000;

/// The obstacles of a cell, merged under bounding volume hierarchies (parry's binned-SAH
/// [`Bvh`]): one, or for large cells two built side by side (the two halves of the triangles in
/// Morton order), searched one after the other with a shared best distance.
///
/// Build it once per cell with [`Cell::from_soups`] (the meshes as read by
/// [`towpath_geom::io`]) and share it: queries take `&self` and the cell is `Send + Sync`.
#[derive(Clone)]
pub struct Cell {
    /// Triangle corners, in leaf order.
    tris: Vec<[DVec3; 3]>,
    /// Each hierarchy with the index of its first triangle; its leaf `i` holds triangles
    /// `first + i·LEAF_SIZE ..`.
    parts: Vec<(Bvh, usize)>,
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

fn arr3(v: DVec3) -> [f64; 3] {
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

/// The hierarchy over consecutive triangles, `LEAF_SIZE` to a leaf.
fn build(tris: &[[DVec3; 3]]) -> Bvh {
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
    Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves)
}

/// The bounding box of a triangle.
fn tri_box(t: &[DVec3; 3]) -> ([f64; 3], [f64; 3]) {
    (arr3(t[0].min(t[1]).min(t[2])), arr3(t[0].max(t[1]).max(t[2])))
}

impl Cell {
    /// A cell with no obstacles: every move is clear.
    pub fn empty() -> Cell {
        Cell { tris: Vec::new(), parts: Vec::new(), bounds: None }
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

    /// The cell of these triangles (corners in the part frame; triangles with a coordinate
    /// that is not finite are dropped, which [`Cell::from_soups`] refuses instead).
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
        let parts = if tris.len() > SPLIT_ABOVE {
            // Two halves (a whole number of leaves in the first), built on two threads.
            let mid = (tris.len() / 2).div_ceil(LEAF_SIZE) * LEAF_SIZE;
            let (a, b) = tris.split_at(mid);
            let (ba, bb) = std::thread::scope(|s| {
                let h = s.spawn(|| build(b));
                let ba = build(a);
                (ba, h.join().unwrap_or_else(|_| build(b)))
            });
            vec![(ba, 0), (bb, mid)]
        } else {
            vec![(build(&tris), 0)]
        };
        Cell { tris, parts, bounds: Some((lo, hi)) }
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

    fn leaf(&self, first: usize, leaf: u32) -> &[[DVec3; 3]] {
        let a = first + leaf as usize * LEAF_SIZE;
        let b = (a + LEAF_SIZE).min(self.tris.len());
        self.tris.get(a..b).unwrap_or(&[])
    }

    /// Depth-first search of every hierarchy for the least `dist` of a triangle, below `cap`
    /// (returned when nothing is nearer), stopping once one is found at or below `stop`.
    /// `near(lo, hi, r)` must be true for every box holding a point nearer than `r`.
    fn search(
        &self,
        cap: f64,
        stop: f64,
        near: impl Fn([f64; 3], [f64; 3], f64) -> bool,
        dist: impl Fn(&[DVec3; 3]) -> f64,
    ) -> f64 {
        let mut best = cap;
        for (bvh, first) in &self.parts {
            let mut done = false;
            bvh.traverse(|node: &BvhNode| {
                if !near(arr(node.mins()), arr(node.maxs()), best) {
                    return TraversalAction::Prune;
                }
                if let Some(leaf) = node.leaf_data() {
                    let mut found = f64::INFINITY;
                    for t in self.leaf(*first, leaf) {
                        let (lo, hi) = tri_box(t);
                        if near(lo, hi, best.min(found)) {
                            found = found.min(dist(t));
                        }
                    }
                    best = best.min(found);
                    if found <= stop {
                        done = true;
                        return TraversalAction::EarlyExit;
                    }
                }
                TraversalAction::Continue
            });
            if done {
                break;
            }
        }
        best
    }

    /// Best-first search of every hierarchy for the least `dist` of a triangle, below `cap`
    /// (returned when nothing is nearer), to within `slack`: `bound(lo, hi)` is a lower bound
    /// of the distance of anything in a box, and boxes whose bound is within `slack` of the
    /// best found are not opened.
    fn best_first(
        &self,
        cap: f64,
        slack: f64,
        bound: impl Fn([f64; 3], [f64; 3]) -> f64,
        dist: impl Fn(&[DVec3; 3]) -> f64,
    ) -> f64 {
        let mut best = cap;
        for (bvh, first) in &self.parts {
            let found = bvh.find_best(
                best,
                |node: &BvhNode, _| bound(arr(node.mins()), arr(node.maxs())) + slack,
                |leaf, so_far| {
                    let mut found = f64::INFINITY;
                    for t in self.leaf(*first, leaf) {
                        let (lo, hi) = tri_box(t);
                        if bound(lo, hi) + slack < so_far.min(found) {
                            found = found.min(dist(t));
                        }
                    }
                    Some(found)
                },
            );
            if let Some((_, d)) = found {
                best = best.min(d);
            }
        }
        best
    }

    /// The distance from segment `p q` to the nearest obstacle, or `cap` if nothing is nearer
    /// than `cap`. The search stops as soon as something is found at or below `stop`, returning
    /// that distance (pass a negative `stop` for the exact minimum).
    pub fn segment_distance(&self, p: DVec3, q: DVec3, cap: f64, stop: f64) -> f64 {
        let (pa, d) = (arr3(p), arr3(q - p));
        self.search(cap, stop, |lo, hi, r| segment_hits_box(pa, d, lo, hi, [r; 3]), |t| segment_triangle_dist(p, q, t))
    }

    /// The distance from the quadrilateral `a0 b0 b1 a1`, taken as the two triangles
    /// `a0 b0 b1` and `a0 b1 a1`, to the nearest obstacle, or `cap` if nothing is nearer;
    /// stops early at or below `stop` like [`Cell::segment_distance`]. (The head's sweep over a
    /// piece of a move: `a` the bottom and `b` the top of its axis at either end.)
    pub fn quad_distance(&self, a0: DVec3, b0: DVec3, b1: DVec3, a1: DVec3, cap: f64, stop: f64) -> f64 {
        let (pa, d, half) = spine(a0, b0, b1, a1);
        let quad = [[a0, b0, b1], [a0, b1, a1]];
        self.search(
            cap,
            stop,
            // Every point of the quadrilateral is within `half` (per axis) of its spine.
            |lo, hi, r| segment_hits_box(pa, d, lo, hi, [r + half[0], r + half[1], r + half[2]]),
            |t| triangle_triangle_dist(&quad[0], t).min(triangle_triangle_dist(&quad[1], t)),
        )
    }

    /// The least distance from segment `p q` to the obstacles, found best first (nearest box
    /// first, by its exact distance from the segment): the answer `d` (or `cap` when nothing is
    /// nearer) is within `slack` above the truth — boxes that cannot hold anything nearer than
    /// `d − slack` are not opened. Much quicker than the exact search when a long segment runs
    /// at a near-constant distance from a dense mesh.
    pub fn segment_min(&self, p: DVec3, q: DVec3, cap: f64, slack: f64) -> f64 {
        let (pa, d) = (arr3(p), arr3(q - p));
        self.best_first(
            cap,
            slack,
            |lo, hi| segment_box_dist(pa, d, lo, hi, [0.0; 3]),
            |t| segment_triangle_dist(p, q, t),
        )
    }

    /// [`Cell::quad_distance`] found best first, within `slack` above the truth like
    /// [`Cell::segment_min`].
    pub fn quad_min(&self, a0: DVec3, b0: DVec3, b1: DVec3, a1: DVec3, cap: f64, slack: f64) -> f64 {
        let (pa, d, half) = spine(a0, b0, b1, a1);
        let quad = [[a0, b0, b1], [a0, b1, a1]];
        self.best_first(
            cap,
            slack,
            |lo, hi| segment_box_dist(pa, d, lo, hi, half),
            |t| triangle_triangle_dist(&quad[0], t).min(triangle_triangle_dist(&quad[1], t)),
        )
    }

    /// The distance from point `p` to the nearest obstacle, or `cap` if nothing is nearer.
    pub fn point_distance(&self, p: DVec3, cap: f64) -> f64 {
        self.segment_distance(p, p, cap, -1.0)
    }
}

/// The spine of the quadrilateral `a0 b0 b1 a1` (from the middle of `a0 b0` to the middle of
/// `a1 b1`, as start and direction) and how far, per axis, its points can be from the spine.
fn spine(a0: DVec3, b0: DVec3, b1: DVec3, a1: DVec3) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let (m0, m1) = ((a0 + b0) * 0.5, (a1 + b1) * 0.5);
    let (h0, h1) = (b0 - a0, b1 - a1);
    let half = [0.5 * h0.x.abs().max(h1.x.abs()), 0.5 * h0.y.abs().max(h1.y.abs()), 0.5 * h0.z.abs().max(h1.z.abs())];
    (arr3(m0), arr3(m1 - m0), half)
}
