//! Exact closest point of a triangle to a point (Voronoi-region classification of the point
//! against the triangle's vertices, edges and face, as in real-time collision detection texts).

use glam::DVec3;

/// Closest point on triangle (a, b, c) to p, returned as barycentric weights (wa, wb, wc) that
/// sum to one. Degenerate triangles are handled: the answer is then a point of the closest edge.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return DVec3::new(1.0, 0.0, 0.0);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return DVec3::new(0.0, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return DVec3::new(1.0 - v, v, 0.0);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return DVec3::new(0.0, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return DVec3::new(1.0 - w, 0.0, w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return DVec3::new(0.0, 1.0 - w, w);
    }
    let sum = va + vb + vc;
    if !(sum.abs() > 0.0) || !sum.is_finite() {
        // Degenerate triangle: best of the three edges.
        let cands = [seg(p, a, b, 0, 1), seg(p, b, c, 1, 2), seg(p, a, c, 0, 2)];
        let at = |w: DVec3| a * w.x + b * w.y + c * w.z;
        return cands
            .into_iter()
            .min_by(|x, y| at(*x).distance_squared(p).total_cmp(&at(*y).distance_squared(p)))
            .unwrap_or(DVec3::new(1.0, 0.0, 0.0));
    }
    let denom = 1.0 / sum;
    let v = vb * denom;
    let w = vc * denom;
    DVec3::new(1.0 - v - w, v, w)
}

fn seg(p: DVec3, a: DVec3, b: DVec3, ia: usize, ib: usize) -> DVec3 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 { ((p - a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    let mut w = [0.0; 3];
    w[ia] += 1.0 - t;
    w[ib] += t;
    DVec3::from_array(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn at(w: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
        a * w.x + b * w.y + c * w.z
    }

    proptest! {
        // The answer is no farther than any sampled point of the triangle (brute force check).
        #[test]
        fn no_sampled_point_is_closer(
            a in prop::array::uniform3(-10.0f64..10.0),
            b in prop::array::uniform3(-10.0f64..10.0),
            c in prop::array::uniform3(-10.0f64..10.0),
            p in prop::array::uniform3(-20.0f64..20.0),
        ) {
            let (a, b, c, p) = (DVec3::from(a), DVec3::from(b), DVec3::from(c), DVec3::from(p));
            let w = closest_point_on_triangle(p, a, b, c);
            prop_assert!((w.x + w.y + w.z - 1.0).abs() < 1e-9);
            prop_assert!(w.min_element() >= -1e-9);
            let d = at(w, a, b, c).distance(p);
            let n = 40;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = a * (1.0 - u - v) + b * u + c * v;
                    prop_assert!(d <= q.distance(p) + 1e-9);
                }
            }
        }
    }
}
