//! Ply regions on a mesh: the whole mesh, or the part inside a closed boundary curve.
//!
//! A boundary curve is given as points near the surface; it is densified, projected onto the
//! mesh, and oriented counter-clockwise about the outward normal (interior on the left). Membership
//! of a surface point is the sign of its distance to the nearest boundary segment, taken in the
//! tangent plane, with the bisector rule at polyline vertices (exact for plane polygons; on curved
//! surfaces it relies on the boundary being closer along the surface than across it). Only segments
//! whose surface normal faces the same way as the point's count, so a boundary on one skin of a
//! thin part does not take in the other skin.
//! The mesh's own boundary loops are indexed the same way, for fast "far from any edge" tests.

use glam::DVec3;
use rstar::{PointDistance, RTree, RTreeObject, AABB};
use towpath_geom::Mesh;

/// A set of closed polylines with nearest-segment queries.
#[derive(Debug)]
pub struct Loops {
    /// Segment end points (a, b) and the outward unit normal of the segment in the tangent plane.
    tree: RTree<Seg>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Seg {
    a: DVec3,
    b: DVec3,
    /// Outward (right-hand) unit normal in the surface's tangent plane.
    out: DVec3,
    /// Outward normals of the segments before and after (for the vertex bisector rule).
    out_prev: DVec3,
    out_next: DVec3,
    /// The surface normal along the segment.
    normal: DVec3,
}

impl RTreeObject for Seg {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        AABB::from_corners(self.a.min(self.b).to_array(), self.a.max(self.b).to_array())
    }
}

impl PointDistance for Seg {
    fn distance_2(&self, q: &[f64; 3]) -> f64 {
        let q = DVec3::from(*q);
        let ab = self.b - self.a;
        let l2 = ab.length_squared();
        let t = if l2 > 0.0 { ((q - self.a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
        (self.a + ab * t).distance_squared(q)
    }
}

impl Loops {
    /// Closed loops given as point lists with normals (interior on the left of the direction of
    /// travel, looking down the normal).
    pub fn new(loops: &[Vec<(DVec3, DVec3)>]) -> Loops {
        let mut segs = Vec::new();
        for lp in loops {
            let n = lp.len();
            if n < 2 {
                continue;
            }
            let outs: Vec<DVec3> = (0..n)
                .map(|i| {
                    let (a, na) = lp[i];
                    let (b, nb) = lp[(i + 1) % n];
                    let nrm = (na + nb).normalize_or_zero();
                    (b - a).cross(nrm).normalize_or_zero()
                })
                .collect();
            for i in 0..n {
                let (a, na) = lp[i];
                let (b, nb) = lp[(i + 1) % n];
                segs.push(Seg {
                    a,
                    b,
                    out: outs[i],
                    out_prev: outs[(i + n - 1) % n],
                    out_next: outs[(i + 1) % n],
                    normal: (na + nb).normalize_or_zero(),
                });
            }
        }
        Loops { tree: RTree::bulk_load(segs) }
    }

    /// Whether there are no segments.
    pub fn is_empty(&self) -> bool {
        self.tree.size() == 0
    }

    /// Signed distance of `q` to the loops: positive inside (left of the loops), negative outside;
    /// +∞ when there are no loops.
    pub fn signed_distance(&self, q: DVec3) -> f64 {
        let Some(s) = self.tree.nearest_neighbor(&q.to_array()) else { return f64::INFINITY };
        Self::side_of(s, q)
    }

    /// Signed distance of a surface point `q` with unit normal `n` to the nearest segment on the
    /// same side of the part (segment normal within 90° of `n`), among the 32 nearest: on a thin
    /// part, a loop drawn on one skin is near the other skin in space but not along the surface.
    /// A point with no such segment near is outside, at the distance of the nearest segment;
    /// +∞ when there are no loops.
    pub fn signed_distance_facing(&self, q: DVec3, n: DVec3) -> f64 {
        let mut nearest: Option<f64> = None;
        for s in self.tree.nearest_neighbor_iter(&q.to_array()).take(32) {
            if s.normal.dot(n) > 0.0 || s.normal == DVec3::ZERO || n == DVec3::ZERO {
                return Self::side_of(s, q);
            }
            if nearest.is_none() {
                nearest = Some(s.distance_2(&q.to_array()).sqrt());
            }
        }
        nearest.map_or(f64::INFINITY, |d| -d)
    }

    fn side_of(s: &Seg, q: DVec3) -> f64 {
        let ab = s.b - s.a;
        let l2 = ab.length_squared();
        let t = if l2 > 0.0 { ((q - s.a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
        let foot = s.a + ab * t;
        let out = if t <= 0.0 {
            (s.out + s.out_prev).normalize_or_zero()
        } else if t >= 1.0 {
            (s.out + s.out_next).normalize_or_zero()
        } else {
            s.out
        };
        let d = foot.distance(q);
        if (q - foot).dot(out) > 0.0 {
            -d
        } else {
            d
        }
    }

    /// Unsigned distance to the nearest segment (+∞ when empty).
    pub fn distance(&self, q: DVec3) -> f64 {
        self.signed_distance(q).abs()
    }
}

/// The region a ply covers.
#[derive(Debug)]
pub struct Region {
    /// The ply boundary (empty: the whole mesh).
    pub curve: Loops,
    /// The mesh's boundary loops.
    pub mesh_edges: Loops,
    /// The boundary curve's points as projected onto the mesh (empty for the whole mesh).
    pub curve_points: Vec<DVec3>,
}

impl Region {
    /// The whole mesh.
    pub fn whole(mesh: &Mesh) -> Region {
        Region { curve: Loops::new(&[]), mesh_edges: mesh_loops(mesh), curve_points: Vec::new() }
    }

    /// The part of the mesh inside a closed curve. Points are projected onto the mesh; segments
    /// are densified to at most `max_seg`. The curve's orientation is chosen so that `inside`
    /// (a point known to be in the ply, if given) is inside, else so that the enclosed area is
    /// positive about the mean normal.
    pub fn curve(mesh: &Mesh, points: &[DVec3], max_seg: f64, inside: Option<DVec3>) -> Option<Region> {
        let mut pts: Vec<DVec3> = points.to_vec();
        if pts.len() >= 2 && pts[0].distance(pts[pts.len() - 1]) < 1e-9 {
            pts.pop();
        }
        if pts.len() < 3 {
            return None;
        }
        let mut dense = Vec::new();
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            let k = ((a.distance(b) / max_seg).ceil() as usize).clamp(1, 100_000);
            for j in 0..k {
                dense.push(a.lerp(b, j as f64 / k as f64));
            }
        }
        let mut proj: Vec<(DVec3, DVec3)> = dense
            .iter()
            .filter_map(|&p| {
                let sp = mesh.closest_point(p)?;
                Some((mesh.point(sp), mesh.smooth_normal(sp)))
            })
            .collect();
        proj.dedup_by(|a, b| a.0.distance(b.0) < 1e-9);
        if proj.len() < 3 {
            return None;
        }
        let mut loops = Loops::new(std::slice::from_ref(&proj));
        let flip = match inside {
            Some(q) => loops.signed_distance(q) < 0.0,
            None => {
                let c = proj.iter().map(|x| x.0).sum::<DVec3>() / proj.len() as f64;
                let nm = proj.iter().map(|x| x.1).sum::<DVec3>().normalize_or_zero();
                let mut a = 0.0;
                for i in 0..proj.len() {
                    let (p, q) = (proj[i].0 - c, proj[(i + 1) % proj.len()].0 - c);
                    a += p.cross(q).dot(nm);
                }
                a < 0.0
            }
        };
        if flip {
            proj.reverse();
            loops = Loops::new(std::slice::from_ref(&proj));
        }
        Some(Region { curve: loops, mesh_edges: mesh_loops(mesh), curve_points: proj.iter().map(|x| x.0).collect() })
    }

    /// Whether the ply has a boundary curve (else it is the whole mesh).
    pub fn has_curve(&self) -> bool {
        !self.curve.is_empty()
    }

    /// Signed distance of the surface point `q` with unit normal `n` to the ply boundary curve
    /// (+∞ for the whole mesh): positive inside. Only boundary segments on the same side of the
    /// part as `q` count ([`Loops::signed_distance_facing`]).
    pub fn curve_distance(&self, q: DVec3, n: DVec3) -> f64 {
        self.curve.signed_distance_facing(q, n)
    }
}

fn mesh_loops(mesh: &Mesh) -> Loops {
    let loops: Vec<Vec<(DVec3, DVec3)>> = mesh
        .boundary_loops()
        .iter()
        .map(|lp| lp.iter().map(|&v| (mesh.positions()[v as usize], mesh.vertex_normal(v))).collect())
        .collect();
    Loops::new(&loops)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_signed_distance_with_concave_corner() {
        // An L-shaped loop in the plane z = 0, counter-clockwise about +z.
        let pts = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
        let lp: Vec<(DVec3, DVec3)> = pts.iter().map(|&(x, y)| (DVec3::new(x, y, 0.0), DVec3::Z)).collect();
        let l = Loops::new(&[lp]);
        assert!((l.signed_distance(DVec3::new(0.5, 0.5, 0.0)) - 0.5).abs() < 1e-12);
        assert!((l.signed_distance(DVec3::new(3.0, 0.5, 0.0)) + 1.0).abs() < 1e-12);
        // Outside, near the concave corner (1, 1).
        assert!((l.signed_distance(DVec3::new(1.5, 1.5, 0.0)) + 0.5).abs() < 1e-12);
        // Inside near the concave corner.
        assert!(l.signed_distance(DVec3::new(0.9, 0.9, 0.0)) > 0.0);
        // Outside beyond a convex corner.
        assert!(l.signed_distance(DVec3::new(-1.0, -1.0, 0.0)) < 0.0);
    }

    #[test]
    fn only_segments_on_the_same_side_of_the_part_count() {
        // A unit square on the top skin (normal +z) of a part 0.1 thick.
        let lp: Vec<(DVec3, DVec3)> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(x, y)| (DVec3::new(x, y, 0.1), DVec3::Z))
            .collect();
        let l = Loops::new(&[lp]);
        let top = DVec3::new(0.5, 0.3, 0.1);
        assert!((l.signed_distance_facing(top, DVec3::Z) - 0.3).abs() < 1e-12);
        // Right under it on the bottom skin: inside by position, outside along the surface.
        let bottom = DVec3::new(0.5, 0.3, 0.0);
        assert!(l.signed_distance(bottom) > 0.0);
        let d = l.signed_distance_facing(bottom, -DVec3::Z);
        assert!(d < 0.0 && (d + (0.3f64 * 0.3 + 0.01).sqrt()).abs() < 1e-12, "{d}");
    }
}
