//! Course tracing across triangles (seed 001 Algorithm 4), with smooth normals.
//!
//! A walk starts at a surface point with a tangent direction and crosses one triangle per step:
//! the direction is projected into the triangle's plane (eq. 13), the exit edge is found from the
//! barycentric coordinates along the ray (eqs. 8–10 in barycentric form, which also handles rays
//! through vertices), and the walk continues in the neighbouring face until the mesh boundary, a
//! length limit or a caller's stop test.
//!
//! Two steerings: [`Steering::Field`] re-evaluates the design direction in every triangle
//! (Algorithm 4 step 6), [`Steering::Geodesic`] carries the direction by parallel transport (the
//! minimal rotation between consecutive normals), which traces the straightest path. Both use the
//! *smooth* normal (barycentric blend of the area-weighted vertex normals) rather than the face
//! normal, and evaluate the direction at the middle of each step (predictor–corrector), so the
//! error does not grow with curvature the way seed 001 §4.2 reports for face normals.

use glam::DVec3;
use serde::Serialize;
use towpath_geom::{Mesh, SurfacePoint, NO_FACE};

use crate::field::DirectionField;

/// How the walk chooses its direction.
#[derive(Clone, Copy)]
pub enum Steering<'a> {
    /// Follow a design direction field (steered courses).
    Field(&'a dyn DirectionField),
    /// Straightest path: parallel transport of the start direction (geodesic / natural path).
    Geodesic,
}

/// One point of a traced path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathPoint {
    /// Position (on the mesh).
    pub p: DVec3,
    /// Smooth unit normal.
    pub n: DVec3,
    /// Unit fiber direction (tangent, forward along the path).
    pub d: DVec3,
    /// Arc length from the path's first point.
    pub s: f64,
    /// A face the point lies on; along a traced path, the face of the segment ending at this
    /// point ([`NO_FACE`] where unknown).
    #[serde(skip)]
    pub face: u32,
}

/// Why a walk ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// Reached the mesh boundary (or a cut edge).
    Boundary,
    /// Reached the length limit.
    Length,
    /// The caller's stop test said so.
    Caller,
    /// The direction became undefined or ran parallel to an edge with no way forward.
    Stuck,
}

/// Rotates `v` by the minimal rotation taking unit `a` to unit `b`.
#[inline]
pub fn transport(v: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let k = a.cross(b);
    let c = a.dot(b);
    if c <= -1.0 + 1e-12 {
        return v;
    }
    v * c + k.cross(v) + k * (k.dot(v) / (1.0 + c))
}

/// Projects `v` into the plane with unit normal `n` and normalizes.
#[inline]
pub fn tangent(v: DVec3, n: DVec3) -> Option<DVec3> {
    (v - n * v.dot(n)).try_normalize()
}

/// A point on the mesh with its position and smooth normal.
#[derive(Debug, Clone, Copy)]
pub struct Located {
    /// Face and barycentric coordinates.
    pub sp: SurfacePoint,
    /// Position.
    pub p: DVec3,
    /// Smooth normal.
    pub n: DVec3,
}

impl Located {
    /// Locates a surface point.
    pub fn new(mesh: &Mesh, sp: SurfacePoint) -> Located {
        Located { sp, p: mesh.point(sp), n: mesh.smooth_normal(sp) }
    }
}

/// Barycentric rate of change along an in-plane vector `w` of face `f`.
#[inline]
fn bary_rate(c: &[DVec3; 3], w: DVec3) -> DVec3 {
    let (v0, v1) = (c[1] - c[0], c[2] - c[0]);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (w0, w1) = (w.dot(v0), w.dot(v1));
    let den = d00 * d11 - d01 * d01;
    let dv = (d11 * w0 - d01 * w1) / den;
    let dw = (d00 * w1 - d01 * w0) / den;
    DVec3::new(-dv - dw, dv, dw)
}

/// Exit of the ray b + t·db from the triangle: (t, local edge). `entry` is the local edge the walk
/// came in through (never chosen at t = 0).
#[inline]
fn exit(b: DVec3, db: DVec3, entry: Option<usize>) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for i in 0..3 {
        if db[i] < -1e-15 {
            let edge = (i + 1) % 3;
            let t = (b[i].max(0.0)) / -db[i];
            if entry == Some(edge) && t <= 1e-12 {
                continue;
            }
            if best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, edge));
            }
        }
    }
    best
}

/// Options of a walk.
#[derive(Clone, Copy, Debug)]
pub struct WalkOptions {
    /// Stop after this arc length.
    pub max_length: f64,
    /// Evaluate the direction at the middle of each step (recommended; off reproduces seed 001's
    /// entry-point rule for comparison).
    pub midpoint: bool,
    /// Smooth (interpolated vertex) normals (recommended). Off reproduces seed 001: the face
    /// normal inside a triangle and the area-weighted normal of the two faces on an edge (eq. 12).
    pub smooth_normals: bool,
    /// Longest step: a triangle longer than this along the path is crossed in several steps, the
    /// direction evaluated again after each, so a coarse mesh (a plate of two triangles) is
    /// traced as faithfully as a fine one. `∞`: one step per triangle.
    pub max_step: f64,
}

impl Default for WalkOptions {
    fn default() -> Self {
        WalkOptions { max_length: f64::INFINITY, midpoint: true, smooth_normals: true, max_step: f64::INFINITY }
    }
}

impl WalkOptions {
    /// Default options with a length limit.
    pub fn up_to(max_length: f64) -> WalkOptions {
        WalkOptions { max_length, ..WalkOptions::default() }
    }
}

/// Seed 001's normal on an edge: the area-weighted mean of the normals of the faces on it.
fn edge_normal(mesh: &Mesh, f: u32, edge: usize) -> DVec3 {
    let g = mesh.neighbor(f, edge);
    let mut n = mesh.face_normal(f) * mesh.face_area(f);
    if g != NO_FACE {
        n += mesh.face_normal(g) * mesh.face_area(g);
    }
    n.try_normalize().unwrap_or(mesh.face_normal(f))
}

/// Walks from `start` in the tangent direction `d0` (projected into the tangent plane) until a
/// stop. Returns the points after the start (the start itself is not included) and the reason.
/// `stop` is called on every new point; returning true ends the walk after that point.
pub fn walk(
    mesh: &Mesh,
    start: Located,
    d0: DVec3,
    steering: Steering<'_>,
    opts: &WalkOptions,
    mut stop: impl FnMut(&PathPoint) -> bool,
) -> (Vec<PathPoint>, Stop) {
    let mut out = Vec::new();
    let n_start = if opts.smooth_normals { start.n } else { mesh.face_normal(start.sp.face) };
    let Some(mut d) = tangent(d0, n_start) else { return (out, Stop::Stuck) };
    let mut f = start.sp.face;
    let mut b = start.sp.bary;
    let mut p = start.p;
    let mut n = if opts.smooth_normals { start.n } else { mesh.face_normal(start.sp.face) };
    let mut s = 0.0;
    let mut entry: Option<usize> = None;
    let mut zero_steps = 0u32;
    let max_steps = 4 * mesh.num_faces() + 1000;
    // Steps inside one triangle (each `max_step` long; bounded by the triangle's size, and here
    // against a `max_step` too small for it).
    let mut inner_steps = 0u32;
    let dir_at = |q: DVec3, nq: DVec3, prev: DVec3, nprev: DVec3| -> Option<DVec3> {
        match steering {
            Steering::Geodesic => tangent(transport(prev, nprev, nq), nq),
            Steering::Field(field) => {
                let v = field.direction(q, nq)?;
                Some(if v.dot(prev) < 0.0 { -v } else { v })
            }
        }
    };
    // Field steering: the direction at the start is the field's, aligned with d0.
    if let Steering::Field(_) = steering {
        match dir_at(p, n, d, n) {
            Some(v) => d = v,
            None => return (out, Stop::Stuck),
        }
    }
    let mut crossings = 0usize;
    while crossings < max_steps {
        let c = mesh.corners(f);
        let nf = mesh.face_normal(f);
        let Some(dface) = tangent(d, nf) else { return (out, Stop::Stuck) };
        let mut db = bary_rate(&c, dface);
        let Some((mut t, mut edge)) = exit(b, db, entry) else { return (out, Stop::Stuck) };
        let mut d_step = d;
        let mut n_step = n;
        if opts.midpoint && t > 0.0 {
            // Corrector: the direction at the middle of the predicted step.
            let h = t.min(opts.max_step);
            let bm = b + db * (0.5 * h);
            let sm = SurfacePoint { face: f, bary: bm };
            let nm = if opts.smooth_normals { mesh.smooth_normal(sm) } else { nf };
            let pm = p + dface * (0.5 * h);
            if let Some(dm) = dir_at(pm, nm, d, n) {
                if let Some(df2) = tangent(dm, nf) {
                    let db2 = bary_rate(&c, df2);
                    if let Some((t2, e2)) = exit(b, db2, entry) {
                        db = db2;
                        t = t2;
                        edge = e2;
                        d_step = dm;
                        n_step = nm;
                    }
                }
            }
        }
        let remaining = opts.max_length - s;
        let clipped = t >= remaining;
        // A step that ends inside the triangle (the triangle is longer than the longest step).
        let inner = !clipped && t > opts.max_step;
        if clipped {
            t = remaining.max(0.0);
        } else if inner {
            t = opts.max_step;
        }
        let mut nb = b + db * t;
        if !clipped && !inner {
            nb[(edge + 2) % 3] = 0.0; // the vertex opposite the exit edge
        }
        let nb = nb.max(DVec3::ZERO);
        let nb = nb / (nb.x + nb.y + nb.z);
        let sp = SurfacePoint { face: f, bary: nb };
        let np = mesh.point(sp);
        let nn = if opts.smooth_normals {
            mesh.smooth_normal(sp)
        } else if clipped || inner {
            nf
        } else {
            edge_normal(mesh, f, edge)
        };
        s += np.distance(p);
        let nd = dir_at(np, nn, d_step, n_step).or_else(|| tangent(transport(d_step, n_step, nn), nn));
        let Some(nd) = nd else { return (out, Stop::Stuck) };
        if t <= 1e-12 {
            zero_steps += 1;
            if zero_steps > 64 {
                return (out, Stop::Stuck);
            }
        } else {
            zero_steps = 0;
        }
        let pt = PathPoint { p: np, n: nn, d: nd, s, face: f };
        if t > 1e-12 || out.is_empty() {
            out.push(pt);
        }
        if clipped {
            return (out, Stop::Length);
        }
        if stop(&pt) {
            return (out, Stop::Caller);
        }
        if inner {
            // On in the same triangle from the point reached.
            inner_steps += 1;
            if inner_steps > 1_000_000 {
                return (out, Stop::Stuck);
            }
            b = nb;
            p = np;
            n = nn;
            d = nd;
            entry = None;
            continue;
        }
        // Cross into the neighbour.
        crossings += 1;
        inner_steps = 0;
        let g = mesh.neighbor(f, edge);
        if g == NO_FACE {
            return (out, Stop::Boundary);
        }
        let tf = mesh.triangles()[f as usize];
        let tg = mesh.triangles()[g as usize];
        let (va, vb) = (tf[edge], tf[(edge + 1) % 3]);
        let (wa, wb) = (nb[edge], nb[(edge + 1) % 3]);
        let mut gb = DVec3::ZERO;
        let mut g_entry = 0;
        for k in 0..3 {
            if tg[k] == va {
                gb[k] = wa;
            } else if tg[k] == vb {
                gb[k] = wb;
            }
            if tg[k] == vb && tg[(k + 1) % 3] == va {
                g_entry = k;
            }
        }
        f = g;
        b = gb / (gb.x + gb.y + gb.z).max(1e-300);
        p = np;
        n = nn;
        d = nd;
        entry = Some(g_entry);
    }
    (out, Stop::Stuck)
}

/// Reverses a walk (points after the start) for prepending: directions flipped and each point's
/// face made the face of the segment that leads *to* it in the reversed order, so that along a
/// path the segment from point i to point i + 1 always lies in point i + 1's face.
pub fn reverse_walk(w: &[PathPoint], start_face: u32) -> Vec<PathPoint> {
    let mut out = Vec::with_capacity(w.len());
    for j in (0..w.len()).rev() {
        let face = if j + 1 < w.len() { w[j + 1].face } else { w[j].face };
        out.push(PathPoint { d: -w[j].d, face, ..w[j] });
    }
    let _ = start_face;
    out
}

/// A path traced in both directions from a start point.
#[derive(Debug, Clone, Serialize)]
pub struct Path {
    /// Points in order, arc length from the first.
    pub points: Vec<PathPoint>,
    /// Index of the start point in `points`.
    pub start_index: usize,
    /// Why the backward and forward walks ended.
    pub stops: [Stop; 2],
}

impl Path {
    /// Total length.
    pub fn length(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.s)
    }
}

/// Traces a path through `start` in both directions (seed 001 Algorithm 4 steps 7–8): forward
/// along `d0` and backward along −d0, each until its stop; `max_length` limits each direction.
pub fn trace_both(
    mesh: &Mesh,
    start: Located,
    d0: DVec3,
    steering: Steering<'_>,
    opts: &WalkOptions,
    mut stop: impl FnMut(&PathPoint) -> bool,
) -> Option<Path> {
    let d_start = match steering {
        Steering::Field(field) => {
            let v = field.direction(start.p, start.n)?;
            if v.dot(d0) < 0.0 {
                -v
            } else {
                v
            }
        }
        Steering::Geodesic => tangent(d0, start.n)?,
    };
    let (fwd, stop_f) = walk(mesh, start, d_start, steering, opts, &mut stop);
    let (bwd, stop_b) = walk(mesh, start, -d_start, steering, opts, &mut stop);
    let mut points = Vec::with_capacity(fwd.len() + bwd.len() + 1);
    let total_b = bwd.last().map_or(0.0, |q| q.s);
    let rev = reverse_walk(&bwd, start.sp.face);
    points.extend(rev.iter().map(|q| PathPoint { s: total_b - q.s, ..*q }));
    let start_index = points.len();
    let start_face = bwd.first().map_or(start.sp.face, |q| q.face);
    points.push(PathPoint { p: start.p, n: start.n, d: d_start, s: total_b, face: start_face });
    for q in &fwd {
        points.push(PathPoint { s: total_b + q.s, ..*q });
    }
    Some(Path { points, start_index, stops: [stop_b, stop_f] })
}
