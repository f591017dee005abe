//! Accuracy against exact references (seed 001 §4): traced paths compared with closed-form
//! geodesics on analytic surfaces — a helix on a cylinder, a great circle on a sphere, a straight
//! line of the development on a cone — split into normal and geodesic parts (eq. 15), and angle
//! deviations (eqs. 16–17).

use glam::DVec3;
use serde::Serialize;
use towpath_geom::surface::{Analytic, Surface};

use crate::trace::PathPoint;

/// A closed-form geodesic through a surface point with a unit tangent, by arc length.
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    surface: Analytic,
    /// Start point on the exact surface.
    start: DVec3,
    /// Unit tangent at the start.
    dir: DVec3,
}

impl Reference {
    /// The geodesic of `surface` through the closest surface point to `p` with the direction `d`
    /// projected into the tangent plane there. `None` for planes' degenerate directions.
    pub fn new(surface: Analytic, p: DVec3, d: DVec3) -> Option<Reference> {
        let c = surface.closest(p);
        let dir = (d - c.normal * d.dot(c.normal)).try_normalize()?;
        Some(Reference { surface, start: c.point, dir })
    }

    /// The point at signed arc length `s` from the start.
    pub fn at(&self, s: f64) -> DVec3 {
        match self.surface {
            Analytic::Plane { .. } => self.start + self.dir * s,
            Analytic::Sphere { r, .. } => {
                let u = self.start / r;
                let (sn, cs) = (s / r).sin_cos();
                (u * cs + self.dir * sn) * r
            }
            Analytic::Cylinder { r, .. } => {
                let phi0 = self.start.y.atan2(self.start.x);
                let e_phi = DVec3::new(-phi0.sin(), phi0.cos(), 0.0);
                let (a, b) = (self.dir.dot(e_phi), self.dir.z);
                let phi = phi0 + s * a / r;
                DVec3::new(r * phi.cos(), r * phi.sin(), self.start.z + s * b)
            }
            Analytic::Cone { r0, r1, l, .. } => {
                // Development: a point at slant distance ρ from the apex and polar angle φ maps to
                // the plane point ρ (cos φ sinα, sin φ sinα) with sinα = (r0 − r1) / slant.
                let slant = (l * l + (r1 - r0).powi(2)).sqrt();
                let sin_a = (r0 - r1) / slant;
                let z_apex = if (r0 - r1).abs() > 0.0 { l * r0 / (r0 - r1) } else { f64::INFINITY };
                let rho_of = |p: DVec3| ((p.x * p.x + p.y * p.y) + (p.z - z_apex).powi(2)).sqrt();
                let phi0 = self.start.y.atan2(self.start.x);
                let rho0 = rho_of(self.start);
                let psi0 = phi0 * sin_a;
                // Tangent in the development: radial (away from apex) and angular components.
                let e_phi = DVec3::new(-phi0.sin(), phi0.cos(), 0.0);
                let radial = (self.start - DVec3::new(0.0, 0.0, z_apex)).normalize();
                let (dr, dp) = (self.dir.dot(radial), self.dir.dot(e_phi));
                let q0 = glam::DVec2::new(rho0 * psi0.cos(), rho0 * psi0.sin());
                let er = glam::DVec2::new(psi0.cos(), psi0.sin());
                let ep = glam::DVec2::new(-psi0.sin(), psi0.cos());
                let q = q0 + (er * dr + ep * dp) * s;
                let (rho, psi) = (q.length(), q.y.atan2(q.x));
                // Unwrap ψ near ψ0.
                let mut psi = psi;
                while psi - psi0 > std::f64::consts::PI {
                    psi -= std::f64::consts::TAU;
                }
                while psi - psi0 < -std::f64::consts::PI {
                    psi += std::f64::consts::TAU;
                }
                let phi = psi / sin_a;
                let radius = rho * sin_a;
                let cos_a = (1.0 - sin_a * sin_a).sqrt();
                // z decreases from the apex for r0 > r1 (apex above); sign from the geometry.
                let z = z_apex - rho * cos_a * (z_apex - 0.0).signum();
                DVec3::new(radius * phi.cos(), radius * phi.sin(), z)
            }
        }
    }

    /// Unit tangent at arc length `s` (central difference).
    pub fn tangent(&self, s: f64) -> DVec3 {
        let h = 1e-4;
        (self.at(s + h) - self.at(s - h)).normalize()
    }

    /// The arc length of the reference point closest to `q`, searched near `s_guess`.
    pub fn closest_s(&self, q: DVec3, s_guess: f64) -> f64 {
        let mut s = s_guess;
        let h = 1e-3;
        for _ in 0..20 {
            let (a, b, c) = (self.at(s - h), self.at(s), self.at(s + h));
            let d1 = (c - a) / (2.0 * h);
            let d2 = (c - b * 2.0 + a) / (h * h);
            let g = (b - q).dot(d1);
            let gp = d1.dot(d1) + (b - q).dot(d2);
            if !(gp.abs() > 1e-300) {
                break;
            }
            let step = g / gp;
            s -= step.clamp(-50.0, 50.0);
            if step.abs() < 1e-10 {
                break;
            }
        }
        s
    }
}

/// Deviation figures in the form of seed 001 Tables 2–3.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct Deviation {
    /// Samples compared.
    pub samples: usize,
    /// Mean distance to the reference.
    pub mean: f64,
    /// Mean normal part d_N.
    pub mean_normal: f64,
    /// Mean geodesic (tangential) part d_T.
    pub mean_geodesic: f64,
    /// Maximum distance.
    pub max: f64,
    /// Maximum normal part.
    pub max_normal: f64,
    /// Maximum geodesic part.
    pub max_geodesic: f64,
    /// Mean angle deviation, degrees.
    pub mean_angle_deg: f64,
    /// Mean squared angle deviation, degrees².
    pub mse_angle_deg2: f64,
    /// Maximum angle deviation, degrees.
    pub max_angle_deg: f64,
}

/// Compares path points with the reference; `s0` is the arc length of the path's start point (the
/// reference's origin). The angle deviation compares each segment's direction, projected into the
/// exact tangent plane at its midpoint, with the reference tangent there (for a geodesic
/// reference this is the design direction): the facet's tilt out of the true tangent plane is a
/// property of the mesh, not a fiber angle error, and is left out.
pub fn deviation(reference: &Reference, points: &[PathPoint], s0: f64) -> Deviation {
    let mut dev = Deviation::default();
    let surface = reference.surface;
    let mut n_ang = 0usize;
    for (i, q) in points.iter().enumerate() {
        let s = reference.closest_s(q.p, q.s - s0);
        let r = reference.at(s);
        let v = r - q.p;
        let d = v.length();
        let n = surface.closest(q.p).normal;
        let dn = v.dot(n).abs().min(d);
        let dt = (d * d - dn * dn).max(0.0).sqrt();
        dev.samples += 1;
        dev.mean += d;
        dev.mean_normal += dn;
        dev.mean_geodesic += dt;
        dev.max = dev.max.max(d);
        dev.max_normal = dev.max_normal.max(dn);
        dev.max_geodesic = dev.max_geodesic.max(dt);
        if let Some(next) = points.get(i + 1) {
            let seg = next.p - q.p;
            if seg.length() > 1e-9 {
                let mid = (q.p + next.p) * 0.5;
                let sm = reference.closest_s(mid, 0.5 * (q.s + next.s) - s0);
                let t = reference.tangent(sm);
                // In the tangent plane of the exact surface: the facet's tilt is not a fiber angle.
                let nm = surface.closest(mid).normal;
                let seg_t = (seg - nm * seg.dot(nm)).normalize_or_zero();
                let a = seg_t.dot(t).abs().clamp(-1.0, 1.0).acos().to_degrees();
                dev.mean_angle_deg += a;
                dev.mse_angle_deg2 += a * a;
                dev.max_angle_deg = dev.max_angle_deg.max(a);
                n_ang += 1;
            }
        }
    }
    if dev.samples > 0 {
        let k = dev.samples as f64;
        dev.mean /= k;
        dev.mean_normal /= k;
        dev.mean_geodesic /= k;
    }
    if n_ang > 0 {
        dev.mean_angle_deg /= n_ang as f64;
        dev.mse_angle_deg2 /= n_ang as f64;
    }
    dev
}
