//! Design fiber directions on the surface: the [`DirectionField`] trait and its three sources.
//!
//! - [`Rosette`]: a fixed reference axis t; datum m = (n × t) × n (seed 001 Algorithm 3, steps
//!   3–4: the axis projected into the tangent plane), rotated about n by the ply angle θ (eq. 7).
//! - [`Guides`]: the same with t the tangent of the nearest guide curve at the point's
//!   projection onto it; several guides are blended by distance (seed 001 Algorithm 5).
//! - [`Samples`]: given orientations at sample points blended by inverse distance within one band
//!   width (seed 002 eqs. 3–6).
//!
//! Directions are line directions (a fiber has no arrow): callers align the sign with their
//! previous direction.

use glam::DVec3;

/// A design direction at every surface point.
pub trait DirectionField: Send + Sync {
    /// The unit design direction at surface point `p` with unit normal `n`, in the tangent plane,
    /// or `None` where the field is undefined there (the reference axis along the normal).
    fn direction(&self, p: DVec3, n: DVec3) -> Option<DVec3>;
}

/// Rotates the tangent vector `m` about the unit normal `n` by `theta` radians (seed 001 eq. 7).
#[inline]
pub fn rotate_about(m: DVec3, n: DVec3, theta: f64) -> DVec3 {
    if theta == 0.0 {
        return m;
    }
    let (s, c) = theta.sin_cos();
    m * c + n.cross(m) * s + n * (n.dot(m) * (1.0 - c))
}

/// Datum direction m = (n × t) × n, normalized (seed 001 Algorithm 3); `None` when t ∥ n.
#[inline]
pub fn datum(t: DVec3, n: DVec3) -> Option<DVec3> {
    let m = n.cross(t).cross(n);
    let l = m.length();
    (l > 1e-9 * t.length().max(1e-300)).then(|| m / l)
}

/// A fixed reference axis (rosette) and a ply angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rosette {
    /// The 0° reference axis.
    pub axis: DVec3,
    /// Ply angle θ in radians, counter-clockwise about the outward normal.
    pub angle: f64,
}

impl DirectionField for Rosette {
    fn direction(&self, _p: DVec3, n: DVec3) -> Option<DVec3> {
        Some(rotate_about(datum(self.axis, n)?, n, self.angle))
    }
}

/// A polyline in space with fast closest-point queries for guide curves.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    points: Vec<DVec3>,
    cum: Vec<f64>,
}

impl Polyline {
    /// A polyline through `points` (consecutive duplicates removed). Needs two distinct points.
    pub fn new(points: Vec<DVec3>) -> Option<Polyline> {
        let mut pts: Vec<DVec3> = Vec::with_capacity(points.len());
        for p in points {
            if pts.last().is_none_or(|q: &DVec3| q.distance(p) > 0.0) {
                pts.push(p);
            }
        }
        if pts.len() < 2 {
            return None;
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            cum.push(cum[cum.len() - 1] + w[0].distance(w[1]));
        }
        Some(Polyline { points: pts, cum })
    }
    /// Vertices.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }
    /// Total length.
    pub fn length(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }
    /// Closest point: (point, unit tangent there, arc length, whether the foot lies strictly
    /// inside the curve rather than at an end). The tangent is interpolated along each segment
    /// between the vertex tangents (mean of the adjacent segment directions), so a field taken
    /// from a finely sampled curve turns smoothly instead of in steps.
    pub fn closest(&self, p: DVec3) -> (DVec3, DVec3, f64, bool) {
        let mut best = (f64::INFINITY, DVec3::ZERO, 0usize, 0.0, false);
        let last = self.points.len() - 2;
        for (i, w) in self.points.windows(2).enumerate() {
            let ab = w[1] - w[0];
            let l2 = ab.length_squared();
            let t = ((p - w[0]).dot(ab) / l2).clamp(0.0, 1.0);
            let q = w[0] + ab * t;
            let d = q.distance_squared(p);
            if d < best.0 {
                let inside = !((i == 0 && t <= 0.0) || (i == last && t >= 1.0));
                best = (d, q, i, t, inside);
            }
        }
        let (_, q, i, t, inside) = best;
        let n = self.points.len();
        let seg = |k: usize| (self.points[k + 1] - self.points[k]).normalize();
        let at_vertex = |k: usize| -> DVec3 {
            // Vertex k's tangent: mean of the segments meeting there.
            if k == 0 {
                seg(0)
            } else if k == n - 1 {
                seg(k - 1)
            } else {
                (seg(k - 1) + seg(k)).normalize_or_zero()
            }
        };
        // Point and interpolated tangent at arc length σ.
        let frame = |sigma: f64| -> (DVec3, DVec3) {
            let k = self.cum.partition_point(|&c| c <= sigma).clamp(1, n - 1) - 1;
            let len = self.cum[k + 1] - self.cum[k];
            let u = if len > 0.0 { ((sigma - self.cum[k]) / len).clamp(0.0, 1.0) } else { 0.0 };
            let tan = at_vertex(k).lerp(at_vertex(k + 1), u).try_normalize().unwrap_or_else(|| seg(k));
            (self.points[k].lerp(self.points[k + 1], u), tan)
        };
        // The foot along the smooth tangent field: (p − γ(σ)) · T(σ) = 0 near the closest
        // segment, by bisection. At a polyline vertex the plain closest point stays put while p
        // sweeps the vertex's wedge; this foot moves smoothly, so the field turns smoothly.
        let lo = self.cum[i.saturating_sub(1)];
        let hi = self.cum[(i + 2).min(n - 1)];
        let f = |sigma: f64| {
            let (g, tan) = frame(sigma);
            (p - g).dot(tan)
        };
        let (mut a, mut b) = (lo, hi);
        let (fa, fb) = (f(a), f(b));
        if fa > 0.0 && fb < 0.0 {
            for _ in 0..40 {
                let m = 0.5 * (a + b);
                if f(m) > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            let sigma = 0.5 * (a + b);
            let (g, tan) = frame(sigma);
            return (g, tan, sigma, inside);
        }
        let (_, tan) = frame(self.cum[i] + t * (self.cum[i + 1] - self.cum[i]));
        (q, tan, self.cum[i] + t * (self.cum[i + 1] - self.cum[i]), inside)
    }
}

/// Guide curves (seed 001 §3.2). With one guide, t is its tangent at the closest point; with
/// several, Algorithm 5 picks the pair of guides whose projection points span the polygon edge
/// nearest to the point and blends their tangents by distance.
///
/// Seed 001 eq. 14 as printed weights each tangent by its *own* distance,
/// t = (t₁·dist₁ + t₂·dist₂)/(dist₁ + dist₂), which on guide L_a (dist₁ = 0) gives L_b's tangent;
/// towpath uses the interpolating form t = (t₁·dist₂ + t₂·dist₁)/(dist₁ + dist₂), which equals
/// each guide's tangent on that guide and blends smoothly between them (the behaviour the paper's
/// Figure 6 shows).
#[derive(Debug, Clone, PartialEq)]
pub struct Guides {
    /// Guide curves in the order they lie across the surface.
    pub curves: Vec<Polyline>,
    /// Ply angle θ in radians.
    pub angle: f64,
}

impl Guides {
    /// The blended guide tangent t at `p` (before projection into the tangent plane).
    pub fn tangent(&self, p: DVec3) -> Option<DVec3> {
        let proj: Vec<(DVec3, DVec3, f64)> = self
            .curves
            .iter()
            .map(|c| {
                let (q, t, _, _) = c.closest(p);
                (q, t, q.distance(p))
            })
            .collect();
        match proj.len() {
            0 => None,
            1 => Some(proj[0].1),
            _ => {
                // Polygon of projection points A, B, C, … in guide order (Algorithm 5 step 1);
                // project p on each edge, skip edges where the foot falls outside (step 3), take the
                // nearest (steps 4–5).
                let mut best: Option<(f64, usize)> = None;
                for i in 0..proj.len() - 1 {
                    let (a, b) = (proj[i].0, proj[i + 1].0);
                    let ab = b - a;
                    let l2 = ab.length_squared();
                    if l2 <= 0.0 {
                        continue;
                    }
                    let t = (p - a).dot(ab) / l2;
                    if !(0.0..=1.0).contains(&t) {
                        continue;
                    }
                    let dist = (a + ab * t).distance(p);
                    if best.is_none_or(|(d, _)| dist < d) {
                        best = Some((dist, i));
                    }
                }
                let Some((_, i)) = best else {
                    // Outside every edge: the nearest guide alone.
                    let k = (0..proj.len()).min_by(|&a, &b| proj[a].2.total_cmp(&proj[b].2))?;
                    return Some(proj[k].1);
                };
                let (t1, d1) = (proj[i].1, proj[i].2);
                let (mut t2, d2) = (proj[i + 1].1, proj[i + 1].2);
                if t1.dot(t2) < 0.0 {
                    t2 = -t2;
                }
                let sum = d1 + d2;
                if sum <= 0.0 {
                    return Some(t1);
                }
                (t1 * d2 + t2 * d1).try_normalize()
            }
        }
    }
}

impl DirectionField for Guides {
    fn direction(&self, p: DVec3, n: DVec3) -> Option<DVec3> {
        Some(rotate_about(datum(self.tangent(p)?, n)?, n, self.angle))
    }
}

/// Orientation samples (seed 002 §2.1): fiber directions given at points, blended at a query
/// point by inverse distance over the samples within one band width W, the distance R_k being
/// measured in the query point's tangent plane (eqs. 3–5: the distance from the sample to the
/// normal line through the query point). A sample at R_k = 0 is taken as is. Where no sample lies
/// within W the nearest sample is used ([`Samples::blend`] says whether that happened).
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    points: Vec<DVec3>,
    dirs: Vec<DVec3>,
    band: f64,
    /// Ply angle θ in radians, added to the blended orientation (usually 0).
    pub angle: f64,
    grid: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl Samples {
    /// Samples `(point, direction)`; `band` is the band width W (course width).
    pub fn new(samples: Vec<(DVec3, DVec3)>, band: f64, angle: f64) -> Option<Samples> {
        if samples.is_empty() || !(band > 0.0) {
            return None;
        }
        let (points, dirs): (Vec<DVec3>, Vec<DVec3>) =
            samples.into_iter().filter_map(|(p, d)| Some((p, d.try_normalize()?))).unzip();
        if points.is_empty() {
            return None;
        }
        let mut grid: std::collections::HashMap<[i64; 3], Vec<u32>> = std::collections::HashMap::new();
        for (i, p) in points.iter().enumerate() {
            grid.entry(cell(*p, band)).or_default().push(i as u32);
        }
        Some(Samples { points, dirs, band, angle, grid })
    }

    /// Blended orientation at p (normal n) before the ply angle, and whether a sample lay within
    /// one band width.
    pub fn blend(&self, p: DVec3, n: DVec3) -> Option<(DVec3, bool)> {
        let c = cell(p, self.band);
        let mut acc = DVec3::ZERO;
        let mut wsum = 0.0;
        let mut reference: Option<DVec3> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else { continue };
                    for &k in list {
                        let q = self.points[k as usize];
                        let r = q - p;
                        // Tangential distance: remove the component along the normal (eqs. 4–5).
                        let rk = (r - n * r.dot(n)).length();
                        if rk > self.band {
                            continue;
                        }
                        let mut v = self.dirs[k as usize];
                        v -= n * v.dot(n);
                        let Some(v) = v.try_normalize() else { continue };
                        let v = match reference {
                            None => {
                                reference = Some(v);
                                v
                            }
                            Some(r0) if r0.dot(v) < 0.0 => -v,
                            Some(_) => v,
                        };
                        if rk <= 1e-12 * self.band {
                            return Some((v, true));
                        }
                        acc += v / rk;
                        wsum += 1.0 / rk;
                    }
                }
            }
        }
        if wsum > 0.0 {
            return acc.try_normalize().map(|v| (v, true));
        }
        // Nearest sample.
        let k = (0..self.points.len())
            .min_by(|&a, &b| self.points[a].distance_squared(p).total_cmp(&self.points[b].distance_squared(p)))?;
        let v = self.dirs[k] - n * self.dirs[k].dot(n);
        v.try_normalize().map(|v| (v, false))
    }
}

fn cell(p: DVec3, size: f64) -> [i64; 3] {
    let f = p / size;
    [f.x.floor() as i64, f.y.floor() as i64, f.z.floor() as i64]
}

impl DirectionField for Samples {
    fn direction(&self, p: DVec3, n: DVec3) -> Option<DVec3> {
        let (v, _) = self.blend(p, n)?;
        Some(rotate_about(v, n, self.angle))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosette_on_a_tilted_plane_projects_then_rotates() {
        let n = DVec3::new(0.0, -1.0, 1.0).normalize();
        let r = Rosette { axis: DVec3::Y, angle: 0.0 };
        let d = r.direction(DVec3::ZERO, n).unwrap();
        assert!(d.dot(n).abs() < 1e-15);
        assert!((d - DVec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-12);
        let r90 = Rosette { axis: DVec3::Y, angle: 90f64.to_radians() };
        let d90 = r90.direction(DVec3::ZERO, n).unwrap();
        assert!((d90 - n.cross(d)).length() < 1e-12);
        assert!(Rosette { axis: n, angle: 0.0 }.direction(DVec3::ZERO, n).is_none());
    }

    #[test]
    fn guides_interpolate_between_two_lines() {
        // Guide a along x at y = 0, guide b along y-ish direction at y = 10.
        let a = Polyline::new(vec![DVec3::new(-100.0, 0.0, 0.0), DVec3::new(100.0, 0.0, 0.0)]).unwrap();
        let dir_b = DVec3::new(1.0, 1.0, 0.0).normalize();
        let b =
            Polyline::new(vec![DVec3::new(0.0, 10.0, 0.0) - dir_b * 100.0, DVec3::new(0.0, 10.0, 0.0) + dir_b * 100.0])
                .unwrap();
        let g = Guides { curves: vec![a, b], angle: 0.0 };
        let on_a = g.tangent(DVec3::new(0.0, 0.0, 0.0)).unwrap();
        assert!((on_a - DVec3::X).length() < 1e-12);
        let mid = g.tangent(DVec3::new(0.0, 5.0, 0.0)).unwrap();

        let (d1, d2) = (5.0, 5.0 / 2f64.sqrt()); // distances to a and to b
        let expect = (DVec3::X * d2 + dir_b * d1).normalize();
        assert!((mid - expect).length() < 1e-12, "{mid}");
    }

    #[test]
    fn samples_blend_by_inverse_tangential_distance_within_the_band() {
        let s = Samples::new(
            vec![
                (DVec3::new(0.0, 0.0, 0.0), DVec3::X),
                (DVec3::new(30.0, 0.0, 0.0), DVec3::Y),
                (DVec3::new(500.0, 0.0, 0.0), -DVec3::X),
            ],
            100.0,
            0.0,
        )
        .unwrap();
        // At x = 10 (R = 10 and 20): weights 1/10 and 1/20 → (2 X + Y)/3, normalized.
        let (v, within) = s.blend(DVec3::new(10.0, 0.0, 7.0), DVec3::Z).unwrap();
        assert!(within);
        assert!((v - DVec3::new(2.0, 1.0, 0.0).normalize()).length() < 1e-12);
        // Exactly on a sample.
        assert!((s.blend(DVec3::new(30.0, 0.0, 3.0), DVec3::Z).unwrap().0 - DVec3::Y).length() < 1e-12);
        // Far from all: nearest, flagged.
        let (v, within) = s.blend(DVec3::new(300.0, 0.0, 0.0), DVec3::Z).unwrap();
        assert!(!within);
        assert!((v.abs() - DVec3::X).length() < 1e-12);
    }
}
