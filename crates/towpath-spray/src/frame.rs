//! A flat patch seen in projection on the plane of its mean normal (Tewolde & Sheng 2008 §III-A:
//! "it is sufficient to analyze the corresponding 2-D projection"), with the way back onto the
//! surface.
//!
//! - The patch's border as oriented 2D segments (interior on the left), each classified by what
//!   lies across it: the mesh's own boundary (*free*), another patch across a sharp edge
//!   (*crease*), or another patch continuing the surface (*seam*); each carries the distance
//!   passes run past it ([`BorderEdge::ext`]).
//! - [`Frame::lift`]: a 2D point back to a 3D surface point and normal: inside the patch by
//!   locating its triangle (the patch's own vertex normals are interpolated, so a crease does not
//!   bend the normal), outside by extending the surface in the tangent plane at the nearest border
//!   point, keeping the point's projection.
//! - [`Frame::line_intervals`]: where a line of the plane runs over the patch or within the
//!   run-out band of its free and crease edges (measured square to each edge, with the wedge at
//!   a convex corner between two such edges filled).

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use rstar::{primitives::GeomWithData, RTree, RTreeObject, AABB};
use towpath_geom::{Mesh, NO_FACE};

use crate::partition::Partition;

/// What lies across a border edge of a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EdgeKind {
    /// The mesh's own boundary.
    Free,
    /// Another patch across a sharp edge (normals at least 60° apart: full run-out), or a
    /// milder one (partial run-out).
    Crease,
    /// Another patch continuing the surface (normals less than 10° apart).
    Seam,
}

/// What `patch_of` answers in [`Frame::of_faces`] for a face whose edges count as free.
pub const ABSORBED: u32 = u32::MAX;

/// Normals further apart than this across an edge make it a crease.
pub const CREASE_DEG: f64 = 10.0;
/// Normals this far apart across a crease give the full run-out.
pub const FULL_RUNOUT_DEG: f64 = 60.0;

/// One edge of a patch border.
#[derive(Debug, Clone, Copy)]
pub struct BorderEdge {
    /// Start and end in the plane.
    pub a: DVec2,
    /// End in the plane.
    pub b: DVec2,
    /// Start on the surface.
    pub a3: DVec3,
    /// End on the surface.
    pub b3: DVec3,
    /// Patch vertex normal at the start.
    pub na: DVec3,
    /// Patch vertex normal at the end.
    pub nb: DVec3,
    /// What lies across.
    pub kind: EdgeKind,
    /// How far passes run past this edge (mm).
    pub ext: f64,
    /// The patch across (`u32::MAX` for free edges).
    pub neighbor: u32,
    /// Mesh vertices of the start and end.
    pub va: u32,
    /// Mesh vertex of the end.
    pub vb: u32,
}

type Seg = GeomWithData<rstar::primitives::Line<[f64; 2]>, u32>;

#[derive(Debug, Clone)]
struct Tri2 {
    face: u32,
    p: [DVec2; 3],
}

impl RTreeObject for Tri2 {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        let lo = self.p[0].min(self.p[1]).min(self.p[2]);
        let hi = self.p[0].max(self.p[1]).max(self.p[2]);
        AABB::from_corners([lo.x, lo.y], [hi.x, hi.y])
    }
}

/// A patch in its projection plane.
pub struct Frame<'m> {
    mesh: &'m Mesh,
    /// Unit mean normal N of the patch.
    pub normal: DVec3,
    /// First in-plane axis (u).
    pub eu: DVec3,
    /// Second in-plane axis (v); eu × ev = N.
    pub ev: DVec3,
    /// Origin of the plane coordinates.
    pub origin: DVec3,
    vnormal: HashMap<u32, DVec3>,
    tris: RTree<Tri2>,
    /// The border, as oriented segments.
    pub border: Vec<BorderEdge>,
    /// Border edges chained into loops (indices into `border`).
    pub loops: Vec<Vec<usize>>,
    segs: RTree<Seg>,
    /// Previous and next edge of every border edge in its loop (`usize::MAX` at a broken chain).
    links: Vec<(usize, usize)>,
    /// Half-planes (point, inward normal) that bound each run-out band where it meets a seam.
    clips: Vec<Vec<(DVec2, DVec2)>>,
    /// Projected area of the patch.
    pub area2: f64,
    /// Area-weighted centroid in the plane.
    pub centroid: DVec2,
    /// Second moments about the centroid (xx, xy, yy) in the plane.
    pub moments: [f64; 3],
}

/// Two unit vectors completing `n` to a right-handed frame.
pub fn plane_axes(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.6 {
        DVec3::X
    } else if n.y.abs() < 0.6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let eu = (helper - n * n.dot(helper)).normalize();
    let ev = n.cross(eu);
    (eu, ev)
}

impl<'m> Frame<'m> {
    /// The frame of patch `patch` of a partition; free and sharp edges get a run-out of
    /// `overrun` mm, milder creases a share of it growing with the angle. Edges to a patch
    /// marked in `absorbed` (too small to get passes of its own) count as free: passes run over
    /// it.
    pub fn new(mesh: &'m Mesh, partition: &Partition, patch: u32, overrun: f64, absorbed: &[bool]) -> Frame<'m> {
        let p = &partition.patches[patch as usize];
        let member = |g: u32| partition.patch_of[g as usize] == patch;
        let other = |g: u32| {
            let q = partition.patch_of[g as usize];
            if absorbed.get(q as usize).copied().unwrap_or(false) {
                ABSORBED
            } else {
                q
            }
        };
        Frame::of_faces(mesh, &p.faces, p.normal, &member, &other, overrun)
    }

    /// The frame of any face set with mean normal `normal`; `member(g)` says whether face g is in
    /// the set, `patch_of(g)` names the patch of a face outside it ([`ABSORBED`]: treat the edge
    /// as free).
    pub fn of_faces(
        mesh: &'m Mesh,
        faces: &[u32],
        normal: DVec3,
        member: &dyn Fn(u32) -> bool,
        patch_of: &dyn Fn(u32) -> u32,
        overrun: f64,
    ) -> Frame<'m> {
        let (eu, ev) = plane_axes(normal);
        let origin = faces.first().map_or(DVec3::ZERO, |&f| mesh.corners(f)[0]);
        let to2 = |p: DVec3| DVec2::new((p - origin).dot(eu), (p - origin).dot(ev));
        let mut vnormal: HashMap<u32, DVec3> = HashMap::with_capacity(faces.len());
        let mut tris = Vec::with_capacity(faces.len());
        let mut area2 = 0.0;
        let mut cen = DVec2::ZERO;
        let mut mom = [0.0; 3];
        let mut border = Vec::new();
        for &f in faces {
            let t = mesh.triangles()[f as usize];
            let c = mesh.corners(f);
            let cr = (c[1] - c[0]).cross(c[2] - c[0]);
            for &v in &t {
                *vnormal.entry(v).or_insert(DVec3::ZERO) += cr;
            }
            let p = [to2(c[0]), to2(c[1]), to2(c[2])];
            let a = 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]);
            let g = (p[0] + p[1] + p[2]) / 3.0;
            area2 += a;
            cen += g * a;
            // Second moments of a triangle about the origin: A/12 (Σ x_i² + (Σ x_i)²) etc.
            let sx = p[0].x + p[1].x + p[2].x;
            let sy = p[0].y + p[1].y + p[2].y;
            mom[0] += a / 12.0 * (p.iter().map(|q| q.x * q.x).sum::<f64>() + sx * sx);
            mom[1] += a / 12.0 * (p.iter().map(|q| q.x * q.y).sum::<f64>() + sx * sy);
            mom[2] += a / 12.0 * (p.iter().map(|q| q.y * q.y).sum::<f64>() + sy * sy);
            tris.push(Tri2 { face: f, p });
            for k in 0..3 {
                let g = mesh.neighbor(f, k);
                if g != NO_FACE && member(g) {
                    continue;
                }
                let across = if g == NO_FACE { ABSORBED } else { patch_of(g) };
                let (kind, ext, neighbor) = if across == ABSORBED {
                    (EdgeKind::Free, overrun, u32::MAX)
                } else {
                    let ang = mesh.face_normal(f).dot(mesh.face_normal(g)).clamp(-1.0, 1.0).acos().to_degrees();
                    if ang < CREASE_DEG {
                        (EdgeKind::Seam, 0.0, across)
                    } else {
                        let share = ((1.0 - ang.to_radians().cos()) / (1.0 - FULL_RUNOUT_DEG.to_radians().cos()))
                            .clamp(0.0, 1.0);
                        (EdgeKind::Crease, overrun * share, across)
                    }
                };
                let (va, vb) = (t[k], t[(k + 1) % 3]);
                border.push(BorderEdge {
                    a: p[k],
                    b: p[(k + 1) % 3],
                    a3: c[k],
                    b3: c[(k + 1) % 3],
                    na: DVec3::ZERO,
                    nb: DVec3::ZERO,
                    kind,
                    ext,
                    neighbor,
                    va,
                    vb,
                });
            }
        }
        for n in vnormal.values_mut() {
            *n = n.try_normalize().unwrap_or(normal);
        }
        for e in &mut border {
            e.na = vnormal[&e.va];
            e.nb = vnormal[&e.vb];
        }
        let centroid = if area2.abs() > 0.0 { cen / area2 } else { DVec2::ZERO };
        let moments = if area2.abs() > 0.0 {
            [
                mom[0] - area2 * centroid.x * centroid.x,
                mom[1] - area2 * centroid.x * centroid.y,
                mom[2] - area2 * centroid.y * centroid.y,
            ]
        } else {
            [0.0; 3]
        };
        let loops = chain_loops(&border);
        let mut links = vec![(usize::MAX, usize::MAX); border.len()];
        for lp in &loops {
            let n = lp.len();
            let closed = n > 1 && border[lp[n - 1]].vb == border[lp[0]].va;
            for k in 0..n {
                if k + 1 < n || closed {
                    links[lp[k]].1 = lp[(k + 1) % n];
                    links[lp[(k + 1) % n]].0 = lp[k];
                }
            }
        }
        let clips = seam_clips(&border, &links);
        let segs = RTree::bulk_load(
            border
                .iter()
                .enumerate()
                .map(|(i, e)| GeomWithData::new(rstar::primitives::Line::new([e.a.x, e.a.y], [e.b.x, e.b.y]), i as u32))
                .collect(),
        );
        Frame {
            mesh,
            normal,
            eu,
            ev,
            origin,
            vnormal,
            tris: RTree::bulk_load(tris),
            border,
            loops,
            segs,
            links,
            clips,
            area2,
            centroid,
            moments,
        }
    }

    /// A point of space in plane coordinates.
    pub fn to2(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.origin).dot(self.eu), (p - self.origin).dot(self.ev))
    }

    /// A plane direction as a 3D vector.
    pub fn dir3(&self, d: DVec2) -> DVec3 {
        self.eu * d.x + self.ev * d.y
    }

    /// The surface point above plane point `q` and its unit normal; `true` if `q` is over the
    /// patch, `false` if the point was extended from the nearest border point.
    pub fn lift(&self, q: DVec2) -> (DVec3, DVec3, bool) {
        let env = AABB::from_point([q.x, q.y]);
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for t in self.tris.locate_in_envelope_intersecting(&env) {
            let [a, b, c] = t.p;
            let den = (b - a).perp_dot(c - a);
            if den.abs() <= 0.0 {
                continue;
            }
            let w1 = (q - a).perp_dot(c - a) / den;
            let w2 = (b - a).perp_dot(q - a) / den;
            let w0 = 1.0 - w1 - w2;
            let worst = w0.min(w1).min(w2);
            if worst >= -1e-9 && best.is_none_or(|bb| worst > bb.0) {
                best = Some((worst, t.face, [w0, w1, w2]));
            }
        }
        if let Some((_, f, w)) = best {
            let c = self.mesh.corners(f);
            let t = self.mesh.triangles()[f as usize];
            let p = c[0] * w[0] + c[1] * w[1] + c[2] * w[2];
            let n = (self.vnormal[&t[0]] * w[0] + self.vnormal[&t[1]] * w[1] + self.vnormal[&t[2]] * w[2])
                .try_normalize()
                .unwrap_or(self.mesh.face_normal(f));
            return (p, n, true);
        }
        let Some(seg) = self.segs.nearest_neighbor(&[q.x, q.y]) else {
            return (self.origin + self.dir3(q), self.normal, false);
        };
        let e = &self.border[seg.data as usize];
        let ab = e.b - e.a;
        let s = if ab.length_squared() > 0.0 { ((q - e.a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
        let foot = e.a + ab * s;
        let b3 = e.a3.lerp(e.b3, s);
        let nb = e.na.lerp(e.nb, s).try_normalize().unwrap_or(self.normal);
        let d = self.dir3(q - foot);
        let den = self.normal.dot(nb);
        let lam = if den.abs() > 0.05 { -d.dot(nb) / den } else { 0.0 };
        (b3 + d + self.normal * lam, nb, false)
    }

    /// The intervals (parameters along `dir`, sorted, disjoint) where the line
    /// `{ p : p·m = c }` (m = dir rotated +90°) lies over the patch or within the run-out band
    /// of an edge that has one. `dir` is a unit plane vector.
    pub fn line_intervals(&self, dir: DVec2, c: f64) -> Vec<(f64, f64)> {
        let m = dir.perp();
        let mut cuts: Vec<f64> = Vec::new();
        let mut ivs: Vec<(f64, f64)> = Vec::new();
        for (i, e) in self.border.iter().enumerate() {
            let (da, db) = (e.a.dot(m) - c, e.b.dot(m) - c);
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                cuts.push((e.a + (e.b - e.a) * t).dot(dir));
            }
            if e.ext > 0.0 {
                let clip = |iv: (f64, f64)| -> Option<(f64, f64)> {
                    let (mut lo, mut hi) = iv;
                    for &(o, n) in &self.clips[i] {
                        slab(&mut lo, &mut hi, (m * c - o).dot(n), dir.dot(n), 0.0, f64::INFINITY);
                    }
                    (lo < hi).then_some((lo, hi))
                };
                if let Some(iv) = band_interval(e.a, e.b, e.ext, dir, c).and_then(clip) {
                    ivs.push(iv);
                }
                // The wedge a convex corner leaves between this band and the next one.
                let nx = self.links[i].1;
                if nx != usize::MAX && self.border[nx].ext > 0.0 {
                    let f = &self.border[nx];
                    if let Some(iv) = wedge_interval(e.b, e.ext.max(f.ext), e.b - e.a, f.b - f.a, dir, c).and_then(clip)
                    {
                        ivs.push(iv);
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        for w in cuts.chunks_exact(2) {
            ivs.push((w[0], w[1]));
        }
        merge_intervals(ivs)
    }

    /// Extent of the patch along plane direction `m`: (min, max) of border points' p·m.
    pub fn extent(&self, m: DVec2) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for e in &self.border {
            let x = e.a.dot(m);
            lo = lo.min(x);
            hi = hi.max(x);
        }
        (lo, hi)
    }

    /// Largest run-out of any border edge.
    pub fn max_ext(&self) -> f64 {
        self.border.iter().map(|e| e.ext).fold(0.0, f64::max)
    }

    /// The distance from plane point `q` to the nearest border edge, and that edge.
    pub fn border_distance(&self, q: DVec2) -> Option<(f64, usize)> {
        let seg = self.segs.nearest_neighbor(&[q.x, q.y])?;
        let e = &self.border[seg.data as usize];
        Some((seg_distance(q, e.a, e.b), seg.data as usize))
    }

    /// Whether plane point `q` lies over the patch.
    pub fn covers(&self, q: DVec2) -> bool {
        self.lift(q).2
    }
}

fn seg_distance(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let s = if ab.length_squared() > 0.0 { ((q - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    q.distance(a + ab * s)
}

/// Where a run-out edge meets a seam, the band past the run-out edge must stop at the seam's
/// continuation (the neighbour's band stops there too, from the other side): the half-plane on
/// the patch's side of the line through the corner along the seam's chord over one run-out
/// length. Every band within twice its run-out of the corner is bounded by it.
fn seam_clips(border: &[BorderEdge], links: &[(usize, usize)]) -> Vec<Vec<(DVec2, DVec2)>> {
    let mut corners: Vec<(DVec2, DVec2)> = Vec::new();
    let reach = border.iter().map(|e| e.ext).fold(0.0, f64::max);
    if !(reach > 0.0) {
        return vec![Vec::new(); border.len()];
    }
    for (i, e) in border.iter().enumerate() {
        if e.ext > 0.0 {
            continue;
        }
        let (prev, next) = links[i];
        if prev != usize::MAX && border[prev].ext > 0.0 {
            // The seam starts at e.a: its direction from there, forwards.
            let (mut j, mut len, mut p) = (i, 0.0, e.a);
            while j != usize::MAX && border[j].ext == 0.0 && len < reach {
                len += border[j].a.distance(border[j].b);
                p = border[j].b;
                j = links[j].1;
            }
            if let Some(u) = (p - e.a).try_normalize() {
                corners.push((e.a, u.perp()));
            }
        }
        if next != usize::MAX && border[next].ext > 0.0 {
            // The seam ends at e.b: its direction arriving there.
            let (mut j, mut len, mut p) = (i, 0.0, e.b);
            while j != usize::MAX && border[j].ext == 0.0 && len < reach {
                len += border[j].a.distance(border[j].b);
                p = border[j].a;
                j = links[j].0;
            }
            if let Some(u) = (e.b - p).try_normalize() {
                corners.push((e.b, u.perp()));
            }
        }
    }
    border
        .iter()
        .map(|e| {
            if e.ext > 0.0 {
                corners.iter().copied().filter(|&(o, _)| seg_distance(o, e.a, e.b) <= 2.0 * e.ext).collect()
            } else {
                Vec::new()
            }
        })
        .collect()
}

/// Border edges chained into loops: each edge followed by an edge starting at its end vertex.
fn chain_loops(border: &[BorderEdge]) -> Vec<Vec<usize>> {
    let mut starts: HashMap<u32, Vec<usize>> = HashMap::new();
    for (i, e) in border.iter().enumerate() {
        starts.entry(e.va).or_default().push(i);
    }
    let mut used = vec![false; border.len()];
    let mut loops = Vec::new();
    for s in 0..border.len() {
        if used[s] {
            continue;
        }
        let mut lp = vec![s];
        used[s] = true;
        let mut cur = s;
        loop {
            let end = border[cur].vb;
            let next = starts.get(&end).and_then(|v| v.iter().copied().find(|&j| !used[j]));
            match next {
                Some(j) => {
                    used[j] = true;
                    lp.push(j);
                    cur = j;
                }
                None => break,
            }
        }
        loops.push(lp);
    }
    loops
}

/// Narrows `[lo, hi]` to the parameters s where `min ≤ base + s·slope ≤ max`.
fn slab(lo: &mut f64, hi: &mut f64, base: f64, slope: f64, min: f64, max: f64) {
    if slope.abs() < 1e-15 {
        if base < min || base > max {
            *lo = f64::INFINITY;
            *hi = f64::NEG_INFINITY;
        }
    } else {
        let (t0, t1) = ((min - base) / slope, (max - base) / slope);
        *lo = lo.max(t0.min(t1));
        *hi = hi.min(t0.max(t1));
    }
}

/// The interval of the line `{p·m = c}` (m = dir.perp(), p = c·m + s·dir) within distance `r`
/// of segment ab, measured square to the segment (the rectangle along it, no round ends).
fn band_interval(a: DVec2, b: DVec2, r: f64, dir: DVec2, c: f64) -> Option<(f64, f64)> {
    let ab = b - a;
    let len = ab.length();
    if !(len > 0.0) {
        return None;
    }
    let u = ab / len;
    let w = u.perp();
    let p0 = dir.perp() * c;
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    slab(&mut lo, &mut hi, (p0 - a).dot(u), dir.dot(u), 0.0, len);
    slab(&mut lo, &mut hi, (p0 - a).dot(w), dir.dot(w), -r, r);
    (lo <= hi).then_some((lo, hi))
}

/// The interval of the line within distance `r` of corner `o` and in the wedge past the end of
/// the edge arriving along `u1` and before the start of the edge leaving along `u2`: the part
/// of the round cap that the two bands leave uncovered at a convex corner (empty where the
/// edges are collinear).
fn wedge_interval(o: DVec2, r: f64, u1: DVec2, u2: DVec2, dir: DVec2, c: f64) -> Option<(f64, f64)> {
    let m = dir.perp();
    let off = o.dot(m) - c;
    if !(off.abs() < r) {
        return None;
    }
    let h = (r * r - off * off).sqrt();
    let so = o.dot(dir);
    let (mut lo, mut hi) = (so - h, so + h);
    let p0 = m * c;
    slab(&mut lo, &mut hi, (p0 - o).dot(u1), dir.dot(u1), 0.0, f64::INFINITY);
    slab(&mut lo, &mut hi, (p0 - o).dot(u2), dir.dot(u2), f64::NEG_INFINITY, 0.0);
    (lo < hi).then_some((lo, hi))
}

/// Sorts and merges overlapping intervals; drops empty ones.
pub(crate) fn merge_intervals(mut ivs: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    ivs.retain(|iv| iv.1 > iv.0);
    ivs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(ivs.len());
    for iv in ivs {
        match out.last_mut() {
            Some(last) if iv.0 <= last.1 + 1e-9 => last.1 = last.1.max(iv.1),
            _ => out.push(iv),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_and_corner_intervals() {
        // Segment along x from 0 to 10, radius 2; lines along x at y = c.
        let (a, b) = (DVec2::ZERO, DVec2::new(10.0, 0.0));
        let dir = DVec2::X; // m = (0, 1)
        let iv = band_interval(a, b, 2.0, dir, 1.0).unwrap();
        assert!((iv.0).abs() < 1e-12 && (iv.1 - 10.0).abs() < 1e-12, "{iv:?}");
        assert!(band_interval(a, b, 2.0, dir, 2.5).is_none());
        // A line across the segment (along y at x = 4): |y| ≤ 2.
        let iv = band_interval(a, b, 2.0, DVec2::Y, -4.0).unwrap();
        assert!((iv.0 + 2.0).abs() < 1e-12 && (iv.1 - 2.0).abs() < 1e-12, "{iv:?}");
        // Convex corner at (10, 0), the next edge going up (+y): the wedge is x ≥ 10, y ≤ 0.
        let h = (4.0f64 - 1.0).sqrt();
        let iv = wedge_interval(b, 2.0, DVec2::X, DVec2::Y, dir, -1.0).unwrap();
        assert!((iv.0 - 10.0).abs() < 1e-12 && (iv.1 - 10.0 - h).abs() < 1e-12, "{iv:?}");
        assert!(wedge_interval(b, 2.0, DVec2::X, DVec2::Y, dir, 1.0).is_none());
        // Collinear edges leave no wedge.
        assert!(wedge_interval(b, 2.0, DVec2::X, DVec2::X, dir, -1.0).is_none());
    }

    #[test]
    fn intervals_merge() {
        let m = merge_intervals(vec![(3.0, 4.0), (0.0, 1.0), (0.5, 2.0), (5.0, 5.0)]);
        assert_eq!(m, vec![(0.0, 2.0), (3.0, 4.0)]);
    }
}
