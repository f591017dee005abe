//! Piece geometry: paths of straight lines, circular arcs (bulge form, as DXF polylines store
//! them) and cubic Bézier curves. Every operation the ordering needs is exact on this form:
//! reversal (a line runs back, an arc negates its bulge, a cubic swaps its control points) and
//! starting a closed path elsewhere (the segment under the new start is split in two: a line at
//! a point, an arc at an angle, a cubic by de Casteljau), so a reordered piece keeps the same
//! geometry, not a re-sampled copy of it.

/// A point in the plane.
pub type P2 = [f64; 2];

/// One segment of a path; it starts where the previous one ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seg {
    /// A straight line to the point.
    Line(P2),
    /// A circular arc to `to`; `bulge` is tan(sweep / 4), positive counter-clockwise (the DXF
    /// convention). A bulge of 0 is a straight line; |bulge| = 1 a half circle.
    Arc {
        /// End point.
        to: P2,
        /// tan(sweep / 4).
        bulge: f64,
    },
    /// A cubic Bézier curve with control points `c1`, `c2` to `to`.
    Cubic {
        /// First control point.
        c1: P2,
        /// Second control point.
        c2: P2,
        /// End point.
        to: P2,
    },
}

impl Seg {
    /// Where the segment ends.
    pub fn end(&self) -> P2 {
        match *self {
            Seg::Line(p) => p,
            Seg::Arc { to, .. } | Seg::Cubic { to, .. } => to,
        }
    }
}

/// A path: a start point and segments; `closed` when it ends where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    /// The first point.
    pub start: P2,
    /// The segments, in drawing order.
    pub segs: Vec<Seg>,
    /// Whether the path is a closed contour (its last segment ends at `start`).
    pub closed: bool,
}

/// A place on a path: segment index and parameter in `[0, 1]` along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    /// Segment index.
    pub seg: usize,
    /// Parameter along the segment (for an arc: the fraction of its sweep).
    pub t: f64,
}

/// Distance between two points: the square root of the squares (libm's `hypot`, which guards
/// against overflow no drawing reaches, took 7 % of ordering 2,939 glyph outlines).
#[inline]
pub fn dist(a: P2, b: P2) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}

/// Squared distance from `p` to the segment `a`–`b` (no `hypot`, which guards against an
/// overflow no drawing reaches and is many times slower).
#[inline]
pub fn seg_dist2(p: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    let (qx, qy) = (a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
    qx * qx + qy * qy
}

fn lerp(a: P2, b: P2, t: f64) -> P2 {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// Centre, radius, start angle and sweep of an arc from `from` to `to` with `bulge`
/// (`None` when the bulge is 0 or the chord has no length).
pub fn arc_geometry(from: P2, to: P2, bulge: f64) -> Option<(P2, f64, f64, f64)> {
    let chord = dist(from, to);
    if bulge == 0.0 || chord == 0.0 || !bulge.is_finite() {
        return None;
    }
    let sweep = 4.0 * bulge.atan();
    let m = lerp(from, to, 0.5);
    // Left normal of the chord; the centre lies on it at (1 - b²) / (4 b) chords from the middle.
    let n = [-(to[1] - from[1]), to[0] - from[0]];
    let k = (1.0 - bulge * bulge) / (4.0 * bulge);
    let c = [m[0] + n[0] * k, m[1] + n[1] * k];
    let r = dist(c, from);
    let a0 = (from[1] - c[1]).atan2(from[0] - c[0]);
    Some((c, r, a0, sweep))
}

/// The point at parameter `t` of a segment starting at `from`.
pub fn seg_point(from: P2, seg: &Seg, t: f64) -> P2 {
    match *seg {
        Seg::Line(p) => lerp(from, p, t),
        Seg::Arc { to, bulge } => match arc_geometry(from, to, bulge) {
            Some((c, r, a0, sw)) => {
                if t <= 0.0 {
                    from
                } else if t >= 1.0 {
                    to
                } else {
                    let a = a0 + sw * t;
                    [c[0] + r * a.cos(), c[1] + r * a.sin()]
                }
            }
            None => lerp(from, to, t),
        },
        Seg::Cubic { c1, c2, to } => {
            let u = 1.0 - t;
            let (a, b, c, d) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
            [a * from[0] + b * c1[0] + c * c2[0] + d * to[0], a * from[1] + b * c1[1] + c * c2[1] + d * to[1]]
        }
    }
}

/// The segment split at parameter `t` into the part before and the part after.
pub fn seg_split(from: P2, seg: &Seg, t: f64) -> (Seg, Seg) {
    match *seg {
        Seg::Line(p) => {
            let m = seg_point(from, seg, t);
            (Seg::Line(m), Seg::Line(p))
        }
        Seg::Arc { to, bulge } => {
            let m = seg_point(from, seg, t);
            let sw = 4.0 * bulge.atan();
            (Seg::Arc { to: m, bulge: (sw * t / 4.0).tan() }, Seg::Arc { to, bulge: (sw * (1.0 - t) / 4.0).tan() })
        }
        Seg::Cubic { c1, c2, to } => {
            let p01 = lerp(from, c1, t);
            let p12 = lerp(c1, c2, t);
            let p23 = lerp(c2, to, t);
            let p012 = lerp(p01, p12, t);
            let p123 = lerp(p12, p23, t);
            let m = lerp(p012, p123, t);
            (Seg::Cubic { c1: p01, c2: p012, to: m }, Seg::Cubic { c1: p123, c2: p23, to })
        }
    }
}

/// Appends the segment's points (not `from`) flattened within `tol` to `out`.
pub fn seg_flatten(from: P2, seg: &Seg, tol: f64, out: &mut Vec<P2>) {
    let tol = if tol > 0.0 && tol.is_finite() { tol } else { 0.01 };
    match *seg {
        Seg::Line(p) => out.push(p),
        Seg::Arc { to, bulge } => match arc_geometry(from, to, bulge) {
            Some((_, r, _, sw)) => {
                let step = if tol >= r { std::f64::consts::FRAC_PI_2 } else { 2.0 * (1.0 - tol / r).acos() };
                let n = ((sw.abs() / step.max(1e-6)).ceil() as usize).clamp(1, 4096);
                for i in 1..n {
                    out.push(seg_point(from, seg, i as f64 / n as f64));
                }
                out.push(to);
            }
            None => out.push(to),
        },
        Seg::Cubic { c1, c2, to } => {
            let dd = |a: P2, b: P2, c: P2| (a[0] - 2.0 * b[0] + c[0]).hypot(a[1] - 2.0 * b[1] + c[1]);
            let d = dd(from, c1, c2).max(dd(c1, c2, to));
            let n = ((0.75 * d / tol).sqrt().ceil() as usize).clamp(1, 4096);
            for i in 1..n {
                out.push(seg_point(from, seg, i as f64 / n as f64));
            }
            out.push(to);
        }
    }
}

/// The length of a segment (arcs exactly, cubics by fine flattening).
pub fn seg_length(from: P2, seg: &Seg) -> f64 {
    match *seg {
        Seg::Line(p) => dist(from, p),
        Seg::Arc { to, bulge } => match arc_geometry(from, to, bulge) {
            Some((_, r, _, sw)) => r * sw.abs(),
            None => dist(from, to),
        },
        Seg::Cubic { .. } => {
            let mut pts = Vec::new();
            seg_flatten(from, seg, 1e-4, &mut pts);
            let mut prev = from;
            let mut len = 0.0;
            for p in pts {
                len += dist(prev, p);
                prev = p;
            }
            len
        }
    }
}

/// The segment reversed; it starts at `seg`'s end and ends at `from`.
pub fn seg_reversed(from: P2, seg: &Seg) -> Seg {
    match *seg {
        Seg::Line(_) => Seg::Line(from),
        Seg::Arc { bulge, .. } => Seg::Arc { to: from, bulge: -bulge },
        Seg::Cubic { c1, c2, .. } => Seg::Cubic { c1: c2, c2: c1, to: from },
    }
}

/// An axis-aligned box `[min_x, min_y, max_x, max_y]`.
pub type BBox = [f64; 4];

impl Path {
    /// A polyline through the points (closed: the last point joins the first).
    pub fn polyline(points: &[P2], closed: bool) -> Option<Path> {
        let (&start, rest) = points.split_first()?;
        let mut segs: Vec<Seg> = rest.iter().map(|&p| Seg::Line(p)).collect();
        if closed && segs.last().map(|s| s.end()) != Some(start) {
            segs.push(Seg::Line(start));
        }
        Some(Path { start, segs, closed })
    }

    /// Where the path ends.
    pub fn end(&self) -> P2 {
        self.segs.last().map_or(self.start, |s| s.end())
    }

    /// The start point of segment `i`.
    pub fn seg_start(&self, i: usize) -> P2 {
        if i == 0 {
            self.start
        } else {
            self.segs.get(i - 1).map_or(self.start, |s| s.end())
        }
    }

    /// Total length.
    pub fn length(&self) -> f64 {
        let mut prev = self.start;
        let mut len = 0.0;
        for s in &self.segs {
            len += seg_length(prev, s);
            prev = s.end();
        }
        len
    }

    /// The point at a place.
    pub fn point(&self, at: Place) -> P2 {
        match self.segs.get(at.seg) {
            Some(s) => seg_point(self.seg_start(at.seg), s, at.t),
            None => self.end(),
        }
    }

    /// The path flattened within `tol`: its points from the start.
    pub fn flatten(&self, tol: f64) -> Vec<P2> {
        let mut out = vec![self.start];
        let mut prev = self.start;
        for s in &self.segs {
            seg_flatten(prev, s, tol, &mut out);
            prev = s.end();
        }
        out
    }

    /// The path run backwards.
    pub fn reversed(&self) -> Path {
        let mut segs = Vec::with_capacity(self.segs.len());
        let mut prev = self.start;
        for s in &self.segs {
            segs.push(seg_reversed(prev, s));
            prev = s.end();
        }
        segs.reverse();
        Path { start: self.end(), segs, closed: self.closed }
    }

    /// A closed path started at `at` instead (same geometry; the segment under `at` split in two
    /// unless `at` is a segment end). An open path is returned unchanged.
    pub fn started_at(&self, at: Place) -> Path {
        if !self.closed || self.segs.is_empty() {
            return self.clone();
        }
        let (k, t) = (at.seg.min(self.segs.len() - 1), at.t.clamp(0.0, 1.0));
        let mut segs = Vec::with_capacity(self.segs.len() + 1);
        if t <= 0.0 || t >= 1.0 {
            let k = if t >= 1.0 { (k + 1) % self.segs.len() } else { k };
            let start = self.seg_start(k);
            segs.extend_from_slice(&self.segs[k..]);
            segs.extend_from_slice(&self.segs[..k]);
            return Path { start, segs, closed: true };
        }
        let (a, b) = seg_split(self.seg_start(k), &self.segs[k], t);
        let start = a.end();
        segs.push(b);
        segs.extend_from_slice(&self.segs[k + 1..]);
        segs.extend_from_slice(&self.segs[..k]);
        segs.push(a);
        Path { start, segs, closed: true }
    }

    /// The bounding box of the path flattened within `tol`.
    pub fn bbox(&self, tol: f64) -> BBox {
        bbox_of(&self.flatten(tol))
    }

    /// Places at arc-length spacing `spacing` along the path (segment ends not included),
    /// at most `max` of them.
    pub fn places_at_spacing(&self, spacing: f64, max: usize) -> Vec<Place> {
        let mut out = Vec::new();
        if spacing.is_nan() || spacing <= 0.0 || max == 0 {
            return out;
        }
        let mut next = spacing;
        let mut acc = 0.0;
        let mut prev = self.start;
        for (i, s) in self.segs.iter().enumerate() {
            let len = seg_length(prev, s);
            while next < acc + len && out.len() < max {
                let t = (next - acc) / len;
                if t > 1e-9 && t < 1.0 - 1e-9 {
                    out.push(Place { seg: i, t });
                }
                next += spacing;
            }
            acc += len;
            prev = s.end();
        }
        out
    }
}

impl Path {
    /// The place on the path closest to `p` (sampled within `tol`, then refined by golden
    /// section on the best segment piece).
    pub fn closest_place(&self, p: P2, tol: f64) -> Place {
        let mut best = (f64::INFINITY, Place { seg: 0, t: 0.0 }, 2.0);
        let mut tmp = Vec::new();
        for (i, s) in self.segs.iter().enumerate() {
            tmp.clear();
            let from = self.seg_start(i);
            seg_flatten(from, s, tol, &mut tmp);
            let m = tmp.len().clamp(1, 256);
            for j in 0..=m {
                let t = j as f64 / m as f64;
                let d = dist(p, seg_point(from, s, t));
                if d < best.0 {
                    best = (d, Place { seg: i, t }, m as f64);
                }
            }
        }
        let Some(s) = self.segs.get(best.1.seg) else { return best.1 };
        let from = self.seg_start(best.1.seg);
        let (mut lo, mut hi) = ((best.1.t - 1.0 / best.2).max(0.0), (best.1.t + 1.0 / best.2).min(1.0));
        let g = 0.618_033_988_749_894_9;
        for _ in 0..60 {
            let a = hi - g * (hi - lo);
            let b = lo + g * (hi - lo);
            if dist(p, seg_point(from, s, a)) <= dist(p, seg_point(from, s, b)) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let t = 0.5 * (lo + hi);
        if dist(p, seg_point(from, s, t)) < best.0 {
            Place { seg: best.1.seg, t }
        } else {
            best.1
        }
    }
}

/// The bounding box of points (an empty box of NaNs for none).
pub fn bbox_of(points: &[P2]) -> BBox {
    let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for p in points {
        b[0] = b[0].min(p[0]);
        b[1] = b[1].min(p[1]);
        b[2] = b[2].max(p[0]);
        b[3] = b[3].max(p[1]);
    }
    b
}

/// Signed area of a closed polygon (positive counter-clockwise).
pub fn signed_area(poly: &[P2]) -> f64 {
    let n = poly.len();
    let mut a = 0.0;
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        a += p[0] * q[1] - q[0] * p[1];
    }
    a / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: P2, b: P2) -> bool {
        dist(a, b) < 1e-9
    }

    #[test]
    fn half_circle_arc_has_the_analytic_length_and_midpoint() {
        let s = Seg::Arc { to: [2.0, 0.0], bulge: 1.0 };
        // counter-clockwise from (0,0) to (2,0) around (1,0): passes below, through (1,-1)
        assert!((seg_length([0.0, 0.0], &s) - std::f64::consts::PI).abs() < 1e-12);
        assert!(close(seg_point([0.0, 0.0], &s, 0.5), [1.0, -1.0]));
    }

    #[test]
    fn split_arc_and_cubic_keep_points() {
        let from = [0.0, 0.0];
        for s in
            [Seg::Arc { to: [2.0, 0.0], bulge: 0.7 }, Seg::Cubic { c1: [0.0, 1.0], c2: [2.0, 1.0], to: [2.0, 0.0] }]
        {
            let (a, b) = seg_split(from, &s, 0.3);
            let m = a.end();
            assert!(close(m, seg_point(from, &s, 0.3)));
            // a point of the second half lies on the original
            let q = seg_point(m, &b, 0.5);
            let mut best = f64::INFINITY;
            for i in 0..=20000 {
                best = best.min(dist(q, seg_point(from, &s, i as f64 / 20000.0)));
            }
            assert!(best < 1e-3, "{best}");
            let total = seg_length(from, &s);
            assert!((seg_length(from, &a) + seg_length(m, &b) - total).abs() < 1e-6);
        }
    }

    #[test]
    fn reversal_twice_is_identity_and_restart_keeps_length() {
        let p = Path {
            start: [0.0, 0.0],
            segs: vec![
                Seg::Line([4.0, 0.0]),
                Seg::Arc { to: [4.0, 2.0], bulge: 1.0 },
                Seg::Cubic { c1: [3.0, 3.0], c2: [1.0, 3.0], to: [0.0, 2.0] },
                Seg::Line([0.0, 0.0]),
            ],
            closed: true,
        };
        let r = p.reversed().reversed();
        assert_eq!(r.start, p.start);
        for (a, b) in r.segs.iter().zip(&p.segs) {
            assert!(close(a.end(), b.end()));
        }
        let q = p.started_at(Place { seg: 1, t: 0.25 });
        assert!((q.length() - p.length()).abs() < 1e-6);
        assert!(close(q.start, q.end()));
        assert_eq!(q.segs.len(), p.segs.len() + 1);
    }
}
