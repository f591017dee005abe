//! Tensor-product NURBS patches (seed 001 eq. 2): evaluation with first derivatives by the
//! Cox–de Boor recursion, closest points by Newton iteration from the best of a sample grid.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{ClosestPoint, Surface};

/// A rational (or, with unit weights, polynomial) B-spline patch.
///
/// Control points are stored u-major: point (i, j) is `control[i * count_v + j]`, i along u.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nurbs {
    /// Degree in u (p).
    pub degree_u: usize,
    /// Degree in v (q).
    pub degree_v: usize,
    /// Knot vector in u (count_u + p + 1 non-decreasing values).
    pub knots_u: Vec<f64>,
    /// Knot vector in v (count_v + q + 1 non-decreasing values).
    pub knots_v: Vec<f64>,
    /// Number of control points along u.
    pub count_u: usize,
    /// Number of control points along v.
    pub count_v: usize,
    /// Control points, u-major.
    pub control: Vec<[f64; 3]>,
    /// Weights (empty: all one).
    #[serde(default)]
    pub weights: Vec<f64>,
}

/// A NURBS definition that is not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("NURBS patch: {0}")]
pub struct NurbsError(pub String);

impl Nurbs {
    /// Reads a patch from its JSON text (the fields of [`Nurbs`]; unknown fields are refused) and
    /// validates it. Syntax and field errors name the line and column.
    pub fn from_json(text: &str) -> Result<Nurbs, NurbsError> {
        let n: Nurbs = serde_json::from_str(text).map_err(|e| {
            NurbsError(format!("line {}, column {}: {}", e.line(), e.column(), strip_position(&e.to_string())))
        })?;
        n.validate()?;
        Ok(n)
    }

    /// A clamped uniform B-spline patch through a grid of control points (`grid[i][j]`, i along u).
    pub fn clamped(degree_u: usize, degree_v: usize, grid: &[Vec<DVec3>]) -> Result<Nurbs, NurbsError> {
        let count_u = grid.len();
        let count_v = grid.first().map_or(0, Vec::len);
        if grid.iter().any(|row| row.len() != count_v) {
            return Err(NurbsError("control grid rows differ in length".into()));
        }
        let n = Nurbs {
            degree_u,
            degree_v,
            knots_u: clamped_knots(count_u, degree_u),
            knots_v: clamped_knots(count_v, degree_v),
            count_u,
            count_v,
            control: grid.iter().flatten().map(|p| p.to_array()).collect(),
            weights: Vec::new(),
        };
        n.validate()?;
        Ok(n)
    }

    /// Checks degrees, knot vectors, counts, weights and finiteness.
    pub fn validate(&self) -> Result<(), NurbsError> {
        let e = |m: String| Err(NurbsError(m));
        if self.degree_u == 0 || self.degree_v == 0 || self.degree_u > 15 || self.degree_v > 15 {
            return e(format!("degrees must be 1..=15, got {} × {}", self.degree_u, self.degree_v));
        }
        if self.count_u <= self.degree_u || self.count_v <= self.degree_v {
            return e(format!(
                "need more control points than the degree in each direction, got {} × {} for degree {} × {}",
                self.count_u, self.count_v, self.degree_u, self.degree_v
            ));
        }
        if self.count_u.checked_mul(self.count_v) != Some(self.control.len()) {
            return e(format!(
                "{} control points given, count_u × count_v = {} × {}",
                self.control.len(),
                self.count_u,
                self.count_v
            ));
        }
        for (name, k, n, p) in
            [("u", &self.knots_u, self.count_u, self.degree_u), ("v", &self.knots_v, self.count_v, self.degree_v)]
        {
            if k.len() != n + p + 1 {
                return e(format!("knots_{name} has {} values, expected count + degree + 1 = {}", k.len(), n + p + 1));
            }
            if k.iter().any(|x| !x.is_finite()) || k.windows(2).any(|w| w[1] < w[0]) {
                return e(format!("knots_{name} must be finite and non-decreasing"));
            }
            if !(k[n] > k[p]) {
                return e(format!("knots_{name} span an empty domain"));
            }
        }
        if !self.weights.is_empty() && self.weights.len() != self.control.len() {
            return e(format!("{} weights for {} control points", self.weights.len(), self.control.len()));
        }
        if self.weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return e("weights must be positive and finite".into());
        }
        if self.control.iter().flatten().any(|x| !x.is_finite()) {
            return e("control points must be finite".into());
        }
        Ok(())
    }

    fn weight(&self, k: usize) -> f64 {
        self.weights.get(k).copied().unwrap_or(1.0)
    }
}

/// serde_json's message without its trailing " at line L column C".
fn strip_position(msg: &str) -> &str {
    match msg.rfind(" at line ") {
        Some(i) => &msg[..i],
        None => msg,
    }
}

fn clamped_knots(n: usize, p: usize) -> Vec<f64> {
    let inner = n.saturating_sub(p + 1);
    let mut k = vec![0.0; p + 1];
    for i in 1..=inner {
        k.push(i as f64 / (inner + 1) as f64);
    }
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

/// Knot span index of `t` (NURBS Book A2.1), clamped to the valid range.
fn find_span(knots: &[f64], n: usize, p: usize, t: f64) -> usize {
    if t >= knots[n] {
        // Last non-empty span.
        let mut s = n - 1;
        while s > p && knots[s] >= knots[n] {
            s -= 1;
        }
        return s;
    }
    if t <= knots[p] {
        let mut s = p;
        while s + 1 < n && knots[s + 1] <= knots[p] {
            s += 1;
        }
        return s;
    }
    let (mut lo, mut hi) = (p, n);
    let mut mid = (lo + hi) / 2;
    while t < knots[mid] || t >= knots[mid + 1] {
        if t < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
        mid = (lo + hi) / 2;
    }
    mid
}

/// Basis functions and first derivatives at `t` in span `s` (NURBS Book A2.3, first order).
fn basis_with_derivative(knots: &[f64], s: usize, p: usize, t: f64) -> (Vec<f64>, Vec<f64>) {
    // ndu table as in the book: ndu[j][r] basis, ndu[r][j] knot differences.
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[s + 1 - j];
        right[j] = knots[s + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = if ndu[j][r] != 0.0 { ndu[r][j - 1] / ndu[j][r] } else { 0.0 };
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let n: Vec<f64> = (0..=p).map(|j| ndu[j][p]).collect();
    let mut d = vec![0.0; p + 1];
    for r in 0..=p {
        // First derivative: p * (N_{r-1,p-1}/(u_{s+r}-u_{s+r-p}) - N_{r,p-1}/(u_{s+r+1}-u_{s+r+1-p})).
        let mut v = 0.0;
        if r >= 1 {
            let den = ndu[p][r - 1];
            if den != 0.0 {
                v += ndu[r - 1][p - 1] / den;
            }
        }
        if r < p {
            let den = ndu[p][r];
            if den != 0.0 {
                v -= ndu[r][p - 1] / den;
            }
        }
        d[r] = v * p as f64;
    }
    (n, d)
}

impl Surface for Nurbs {
    fn domain(&self) -> [[f64; 2]; 2] {
        [
            [self.knots_u[self.degree_u], self.knots_u[self.count_u]],
            [self.knots_v[self.degree_v], self.knots_v[self.count_v]],
        ]
    }

    fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.derivatives(u, v).0
    }

    fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (p, q) = (self.degree_u, self.degree_v);
        let su = find_span(&self.knots_u, self.count_u, p, u);
        let sv = find_span(&self.knots_v, self.count_v, q, v);
        let (nu, du) = basis_with_derivative(&self.knots_u, su, p, u);
        let (nv, dv) = basis_with_derivative(&self.knots_v, sv, q, v);
        // Homogeneous sums A = Σ N N w P, w = Σ N N w and their u, v derivatives.
        let (mut a, mut au, mut av) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        let (mut w, mut wu, mut wv) = (0.0, 0.0, 0.0);
        for i in 0..=p {
            let ci = su - p + i;
            for j in 0..=q {
                let cj = sv - q + j;
                let k = ci * self.count_v + cj;
                let wk = self.weight(k);
                let pk = DVec3::from(self.control[k]) * wk;
                let (b, bu, bv) = (nu[i] * nv[j], du[i] * nv[j], nu[i] * dv[j]);
                a += pk * b;
                au += pk * bu;
                av += pk * bv;
                w += wk * b;
                wu += wk * bu;
                wv += wk * bv;
            }
        }
        let s = a / w;
        (s, (au - s * wu) / w, (av - s * wv) / w)
    }

    fn closest(&self, p: DVec3) -> ClosestPoint {
        let [[u0, u1], [v0, v1]] = self.domain();
        let n = 24;
        let mut best = (f64::INFINITY, u0, v0);
        for i in 0..=n {
            for j in 0..=n {
                let (u, v) = (u0 + (u1 - u0) * i as f64 / n as f64, v0 + (v1 - v0) * j as f64 / n as f64);
                let d = self.eval(u, v).distance_squared(p);
                if d < best.0 {
                    best = (d, u, v);
                }
            }
        }
        let (_, mut u, mut v) = best;
        // Gauss–Newton on the tangent plane, clamped to the domain.
        for _ in 0..30 {
            let (s, su, sv) = self.derivatives(u, v);
            let r = p - s;
            let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
            let (g0, g1) = (r.dot(su), r.dot(sv));
            let det = a * c - b * b;
            if !(det.abs() > 1e-300) {
                break;
            }
            let du = (c * g0 - b * g1) / det;
            let dv = (a * g1 - b * g0) / det;
            let (nu, nv) = ((u + du).clamp(u0, u1), (v + dv).clamp(v0, v1));
            let moved = (nu - u).abs() + (nv - v).abs();
            u = nu;
            v = nv;
            if moved < 1e-14 * (1.0 + u1 - u0 + v1 - v0) {
                break;
            }
        }
        ClosestPoint { point: self.eval(u, v), normal: self.normal(u, v), uv: [u, v] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_patches_are_read_and_unknown_fields_refused_with_their_line() {
        let good = r#"{"degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
            "count_u": 2, "count_v": 2, "control": [[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]]}"#;
        let n = Nurbs::from_json(good).unwrap();
        assert_eq!(n.eval(1.0, 1.0), DVec3::new(1.0, 1.0, 0.0));
        // A misspelt field ("weight" for "weights") on line 3 is refused, not ignored.
        let typo = good.replace("]]}", "]],\n\"weight\": [1, 1, 1, 2]}");
        let e = Nurbs::from_json(&typo).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("unknown field `weight`"), "{e}");
        assert!(!e.contains(" at line "), "the position is said once: {e}");
        let e = Nurbs::from_json("{\"degree_u\": 1,\n \"degree_v\": x}").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
        // Valid JSON, invalid patch.
        let e = Nurbs::from_json(&good.replace("\"count_u\": 2", "\"count_u\": 3")).unwrap_err().to_string();
        assert!(e.contains("control points"), "{e}");
    }

    /// A quarter cylinder as an exact rational quadratic patch: radius 2, height 3.
    fn quarter_cylinder() -> Nurbs {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let arc = [DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 2.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
        let mut control = Vec::new();
        let mut weights = Vec::new();
        for (i, c) in arc.iter().enumerate() {
            for z in [0.0, 3.0] {
                control.push([c.x, c.y, z]);
                weights.push(if i == 1 { w } else { 1.0 });
            }
        }
        Nurbs {
            degree_u: 2,
            degree_v: 1,
            knots_u: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            knots_v: vec![0.0, 0.0, 1.0, 1.0],
            count_u: 3,
            count_v: 2,
            control,
            weights,
        }
    }

    #[test]
    fn rational_patch_is_exactly_a_cylinder() {
        let s = quarter_cylinder();
        s.validate().unwrap();
        for i in 0..=10 {
            for j in 0..=4 {
                let (u, v) = (i as f64 / 10.0, j as f64 / 4.0);
                let (p, su, sv) = s.derivatives(u, v);
                assert!(((p.x * p.x + p.y * p.y).sqrt() - 2.0).abs() < 1e-12);
                assert!((p.z - 3.0 * v).abs() < 1e-12);
                let h = 1e-6;
                let fu =
                    (s.eval((u + h).min(1.0), v) - s.eval((u - h).max(0.0), v)) / ((u + h).min(1.0) - (u - h).max(0.0));
                assert!((fu - su).length() < 1e-5, "{fu} vs {su}");
                assert!((sv - DVec3::new(0.0, 0.0, 3.0)).length() < 1e-9);
                let n = s.normal(u, v);
                assert!((n - DVec3::new(p.x, p.y, 0.0).normalize()).length() < 1e-9);
            }
        }
    }

    #[test]
    fn rational_patch_tessellation_meets_both_tolerances() {
        // The quarter cylinder (R 2, height 3) under D_l2s = 0.002 and L_seg = 0.3: every edge at
        // most L_seg long and its midpoint within D_l2s of the exact cylinder.
        let s = quarter_cylinder();
        let (d, l) = (0.002, 0.3);
        let soup = crate::surface::tessellate(&s, &crate::surface::Tessellation::Chord { d_l2s: d, l_seg: l }).unwrap();
        assert!(soup.triangles.len() > 50);
        for t in &soup.triangles {
            for k in 0..3 {
                let (a, b) = (soup.positions[t[k] as usize], soup.positions[t[(k + 1) % 3] as usize]);
                assert!(a.distance(b) <= l + 1e-9, "edge {}", a.distance(b));
                let m = (a + b) * 0.5;
                let dev = 2.0 - (m.x * m.x + m.y * m.y).sqrt();
                assert!((-1e-12..=d + 1e-9).contains(&dev), "deviation {dev}");
            }
        }
    }

    #[test]
    fn clamped_bilinear_patch_is_the_plane_and_closest_point_works() {
        let grid = vec![
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
                DVec3::new(0.0, 3.0, 0.0),
            ],
            vec![
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(1.0, 2.0, 0.0),
                DVec3::new(1.0, 3.0, 0.0),
            ],
            vec![
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(2.0, 1.0, 0.0),
                DVec3::new(2.0, 2.0, 0.0),
                DVec3::new(2.0, 3.0, 0.0),
            ],
            vec![
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(3.0, 1.0, 0.0),
                DVec3::new(3.0, 2.0, 0.0),
                DVec3::new(3.0, 3.0, 0.0),
            ],
        ];
        let s = Nurbs::clamped(3, 3, &grid).unwrap();
        let c = s.closest(DVec3::new(1.3, 2.2, 5.0));
        assert!((c.point - DVec3::new(1.3, 2.2, 0.0)).length() < 1e-9);
        assert!((c.normal - DVec3::Z).length() < 1e-12);
    }

    #[test]
    fn refuses_bad_definitions() {
        let mut s = quarter_cylinder();
        s.knots_u.pop();
        assert!(s.validate().unwrap_err().0.contains("knots_u"));
        let mut s = quarter_cylinder();
        s.weights[0] = -1.0;
        assert!(s.validate().is_err());
        let mut s = quarter_cylinder();
        s.knots_v = vec![0.0, 1.0, 0.5, 1.0];
        assert!(s.validate().is_err());
    }
}
