//! Exact distances between the primitives a swept body is made of (points, segments, triangles)
//! and an obstacle triangle, and the segment-against-box test that prunes the BVH.

use towpath_geom::{closest_point_on_triangle, DVec3};

/// Squared distance between segments `p1 q1` and `p2 q2` (closed segments; degenerate ones are
/// points). After the classic clamped parametric solution (Ericson, *Real-Time Collision
/// Detection*, 5.1.9).
pub(crate) fn segment_segment_dist2(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    const EPS: f64 = 1e-300;
    let (s, t);
    if a <= EPS && e <= EPS {
        return r.length_squared();
    }
    if a <= EPS {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let c1 = p1 + d1 * s;
    let c2 = p2 + d2 * t;
    (c1 - c2).length_squared()
}

/// Squared distance from point `p` to triangle `t`.
pub(crate) fn point_triangle_dist2(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let w = closest_point_on_triangle(p, t[0], t[1], t[2]);
    let q = t[0] * w.x + t[1] * w.y + t[2] * w.z;
    (p - q).length_squared()
}

/// True when segment `p q` meets the interior or boundary of triangle `t` (up to rounding:
/// touching an edge may go either way, which the distance through the edges then settles).
pub(crate) fn segment_crosses_triangle(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let n = e1.cross(e2);
    let dp = (p - t[0]).dot(n);
    let dq = (q - t[0]).dot(n);
    if (dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq {
        return false;
    }
    // The point where the segment crosses the triangle's plane.
    let s = dp / (dp - dq);
    let x = p + (q - p) * s;
    // Inside test by the signs of the sub-triangle normals against n.
    let c0 = (t[1] - t[0]).cross(x - t[0]).dot(n);
    let c1 = (t[2] - t[1]).cross(x - t[1]).dot(n);
    let c2 = (t[0] - t[2]).cross(x - t[2]).dot(n);
    (c0 >= 0.0 && c1 >= 0.0 && c2 >= 0.0) || (c0 <= 0.0 && c1 <= 0.0 && c2 <= 0.0)
}

/// Distance between segment `p q` and triangle `t`: zero when it crosses the triangle, else the
/// least of its end points' distances to the triangle and its distances to the triangle's edges
/// (where the minimum of a segment that does not cross a triangle lies).
pub(crate) fn segment_triangle_dist(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> f64 {
    if segment_crosses_triangle(p, q, t) {
        return 0.0;
    }
    let mut d2 = point_triangle_dist2(p, t).min(point_triangle_dist2(q, t));
    for k in 0..3 {
        d2 = d2.min(segment_segment_dist2(p, q, t[k], t[(k + 1) % 3]));
    }
    d2.sqrt()
}

/// Distance between two triangles: the least distance of an edge of either to the other
/// (zero when they meet, as then an edge of one crosses the other).
pub(crate) fn triangle_triangle_dist(a: &[DVec3; 3], b: &[DVec3; 3]) -> f64 {
    let mut d = f64::INFINITY;
    for k in 0..3 {
        d = d.min(segment_triangle_dist(a[k], a[(k + 1) % 3], b));
        if d == 0.0 {
            return 0.0;
        }
        d = d.min(segment_triangle_dist(b[k], b[(k + 1) % 3], a));
        if d == 0.0 {
            return 0.0;
        }
    }
    d
}

/// True when the segment `p + s·d`, s ∈ [0, 1], meets the box `[lo − grow, hi + grow]` (slab
/// test). Used to prune BVH nodes: a box grown by r on every side contains every point within
/// r of the original box, so a segment that misses the grown box is farther than r from it.
#[inline]
pub(crate) fn segment_hits_box(p: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3], grow: [f64; 3]) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (a, b) = (lo[k] - grow[k], hi[k] + grow[k]);
        if d[k] == 0.0 {
            if p[k] < a || p[k] > b {
                return false;
            }
        } else {
            let inv = 1.0 / d[k];
            let (mut ta, mut tb) = ((a - p[k]) * inv, (b - p[k]) * inv);
            if ta > tb {
                std::mem::swap(&mut ta, &mut tb);
            }
            t0 = t0.max(ta);
            t1 = t1.min(tb);
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// The Euclidean distance between the segment `p + s·d`, s ∈ [0, 1], and the box
/// `[lo − grow, hi + grow]`. A point's squared distance to a box is the sum over the axes of
/// its squared distance to each interval, which along the segment is a convex piecewise
/// quadratic in s with breaks where the segment crosses a face plane: minimized exactly on each
/// piece.
pub(crate) fn segment_box_dist(p: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3], grow: [f64; 3]) -> f64 {
    let lo = [lo[0] - grow[0], lo[1] - grow[1], lo[2] - grow[2]];
    let hi = [hi[0] + grow[0], hi[1] + grow[1], hi[2] + grow[2]];
    let mut ts = [0.0f64; 8];
    let mut n = 0;
    ts[n] = 0.0;
    n += 1;
    for k in 0..3 {
        if d[k] != 0.0 {
            for face in [lo[k], hi[k]] {
                let t = (face - p[k]) / d[k];
                if t > 0.0 && t < 1.0 {
                    ts[n] = t;
                    n += 1;
                }
            }
        }
    }
    ts[n] = 1.0;
    n += 1;
    let ts = &mut ts[..n];
    ts.sort_unstable_by(f64::total_cmp);
    let mut best = f64::INFINITY;
    for w in ts.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        let tm = 0.5 * (ta + tb);
        // On this piece each axis is below, inside or above its interval throughout.
        let (mut a2, mut ab, mut b2) = (0.0, 0.0, 0.0);
        for k in 0..3 {
            let x = p[k] + tm * d[k];
            let (a, b) = if x < lo[k] {
                (lo[k] - p[k], -d[k])
            } else if x > hi[k] {
                (p[k] - hi[k], d[k])
            } else {
                continue;
            };
            a2 += a * a;
            ab += a * b;
            b2 += b * b;
        }
        let t = if b2 > 0.0 { (-ab / b2).clamp(ta, tb) } else { ta };
        best = best.min((a2 + 2.0 * ab * t + b2 * t * t).max(0.0));
        if best == 0.0 {
            return 0.0;
        }
    }
    best.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn closed_forms() {
        let t = [v(0.0, 0.0, 0.0), v(10.0, 0.0, 0.0), v(0.0, 10.0, 0.0)];
        // A vertical segment through the triangle, one beside it, one above it.
        assert_eq!(segment_triangle_dist(v(1.0, 1.0, -1.0), v(1.0, 1.0, 1.0), &t), 0.0);
        assert!((segment_triangle_dist(v(-3.0, 1.0, -1.0), v(-3.0, 1.0, 1.0), &t) - 3.0).abs() < 1e-12);
        assert!((segment_triangle_dist(v(1.0, 1.0, 2.0), v(2.0, 2.0, 5.0), &t) - 2.0).abs() < 1e-12);
        // Skew segments: the x axis and a line along y at z = 4.
        let d = segment_segment_dist2(v(-5.0, 0.0, 0.0), v(5.0, 0.0, 0.0), v(1.0, -5.0, 4.0), v(1.0, 5.0, 4.0));
        assert!((d - 16.0).abs() < 1e-12);
        // Two triangles 3 apart, one above the other.
        let u = [v(1.0, 1.0, 3.0), v(2.0, 1.0, 3.0), v(1.0, 2.0, 3.0)];
        assert!((triangle_triangle_dist(&t, &u) - 3.0).abs() < 1e-12);
        // Interlocked: a vertical triangle piercing t.
        let w = [v(1.0, 1.0, -1.0), v(2.0, 1.0, 1.0), v(1.0, 2.0, 1.0)];
        assert_eq!(triangle_triangle_dist(&t, &w), 0.0);
        // Boxes: a segment passing 2 above a unit box misses it grown by 1, meets it grown by 2.
        let (lo, hi) = ([0.0; 3], [1.0; 3]);
        assert!(!segment_hits_box([-5.0, 0.5, 3.0], [10.0, 0.0, 0.0], lo, hi, [1.0; 3]));
        assert!(segment_hits_box([-5.0, 0.5, 3.0], [10.0, 0.0, 0.0], lo, hi, [2.0; 3]));
        // A segment that stops short.
        assert!(!segment_hits_box([-5.0, 0.5, 0.5], [3.0, 0.0, 0.0], lo, hi, [0.5; 3]));
        assert!(segment_hits_box([-5.0, 0.5, 0.5], [4.6, 0.0, 0.0], lo, hi, [0.5; 3]));
        // Segment-box distances: 2 above the box; against the least distance of 20,001 points
        // of random segments, and never more than the distance of either end.
        assert!((segment_box_dist([-5.0, 0.5, 3.0], [10.0, 0.0, 0.0], lo, hi, [0.0; 3]) - 2.0).abs() < 1e-12);
        assert!((segment_box_dist([-5.0, 0.5, 3.0], [10.0, 0.0, 0.0], lo, hi, [0.5; 3]) - 1.5).abs() < 1e-12);
        let mut x = 12345u64;
        let mut r = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 10.0 - 5.0
        };
        let point_box =
            |q: [f64; 3]| (0..3).map(|k| (lo[k] - q[k]).max(q[k] - hi[k]).max(0.0).powi(2)).sum::<f64>().sqrt();
        for _ in 0..300 {
            let (p, d) = ([r(), r(), r()], [r(), r(), r()]);
            let g = segment_box_dist(p, d, lo, hi, [0.0; 3]);
            let sampled = (0..=20_000)
                .map(|i| {
                    let s = i as f64 / 20_000.0;
                    point_box([p[0] + s * d[0], p[1] + s * d[1], p[2] + s * d[2]])
                })
                .fold(f64::INFINITY, f64::min);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!(g <= sampled + 1e-9 && g >= sampled - len / 20_000.0 - 1e-9, "{g} {sampled}");
        }
    }
}
