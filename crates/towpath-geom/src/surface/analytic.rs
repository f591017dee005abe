//! Analytic surfaces with exact normals and closest points, and their text descriptions
//! (`cylinder:r=300,l=1000`).

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::{ClosestPoint, Surface};

/// An analytic surface. Cylinder, cone and sphere are centred on the z axis; angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analytic {
    /// The rectangle [0, a] × [0, b] of the plane z = 0 (normal +z). u = x, v = y.
    Plane {
        /// Size along x.
        a: f64,
        /// Size along y.
        b: f64,
    },
    /// Radius `r`, z from 0 to `l`, polar angle from `a0` to `a1` (a full tube when a1 − a0 = 2π).
    /// u = angle, v = z; the normal points outwards.
    Cylinder {
        /// Radius.
        r: f64,
        /// Length.
        l: f64,
        /// Start angle.
        a0: f64,
        /// End angle.
        a1: f64,
    },
    /// Radius `r0` at z = 0 and `r1` at z = `l`, polar angle from `a0` to `a1`. u = angle, v = z.
    /// Normal outwards.
    Cone {
        /// Radius at z = 0.
        r0: f64,
        /// Radius at z = l.
        r1: f64,
        /// Length.
        l: f64,
        /// Start angle.
        a0: f64,
        /// End angle.
        a1: f64,
    },
    /// Radius `r` centred at the origin, latitude from `lat0` to `lat1` (−π/2..π/2 for the whole
    /// sphere). u = longitude (0..2π), v = latitude. Normal outwards.
    Sphere {
        /// Radius.
        r: f64,
        /// Lowest latitude.
        lat0: f64,
        /// Highest latitude.
        lat1: f64,
    },
}

/// A surface description that could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("surface '{text}': {message}")]
pub struct ParseError {
    /// The description as given.
    pub text: String,
    /// What is wrong.
    pub message: String,
}

impl Analytic {
    /// Reads a description `kind:key=value,...`:
    /// `plane:a=..,b=..`; `cylinder:r=..,l=..[,a0=deg,a1=deg]`; `cone:r0=..,r1=..,l=..[,a0,a1]`;
    /// `sphere:r=..[,lat0=deg,lat1=deg]`. Angles in degrees; lengths in the mesh unit (mm).
    pub fn parse(text: &str) -> Result<Analytic, ParseError> {
        let fail = |m: String| ParseError { text: text.to_string(), message: m };
        let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
        let mut keys: Vec<(String, f64)> = Vec::new();
        for kv in rest.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, v) = kv.split_once('=').ok_or_else(|| fail(format!("'{kv}' is not key=value")))?;
            let x: f64 = v.trim().parse().map_err(|_| fail(format!("'{v}' (for {k}) is not a number")))?;
            if !x.is_finite() {
                return Err(fail(format!("{k} = {v} is not finite")));
            }
            let k = k.trim().to_ascii_lowercase();
            if keys.iter().any(|(n, _)| *n == k) {
                return Err(fail(format!("{k} is given twice")));
            }
            keys.push((k, x));
        }
        let allowed: &[&str] = match kind {
            "plane" => &["a", "b"],
            "cylinder" => &["r", "l", "a0", "a1"],
            "cone" => &["r0", "r1", "l", "a0", "a1"],
            "sphere" => &["r", "lat0", "lat1"],
            _ => return Err(fail(format!("unknown kind '{kind}' (expected plane, cylinder, cone or sphere)"))),
        };
        if let Some((k, _)) = keys.iter().find(|(k, _)| !allowed.contains(&k.as_str())) {
            return Err(fail(format!("unknown key '{k}' for a {kind} (expected {})", allowed.join(", "))));
        }
        let get = |k: &str| keys.iter().find(|(n, _)| n == k).map(|&(_, v)| v);
        let need = |k: &str| get(k).ok_or_else(|| fail(format!("missing {k}=")));
        let positive = |k: &str| -> Result<f64, ParseError> {
            let v = need(k)?;
            if v > 0.0 {
                Ok(v)
            } else {
                Err(fail(format!("{k} must be positive, got {v}")))
            }
        };
        let angles = || -> Result<(f64, f64), ParseError> {
            let a0 = get("a0").unwrap_or(0.0).to_radians();
            let a1 = get("a1").map_or(a0 + TAU, f64::to_radians);
            if !(a1 > a0) || a1 - a0 > TAU + 1e-12 {
                return Err(fail("need a0 < a1 <= a0 + 360".into()));
            }
            Ok((a0, a1))
        };
        Ok(match kind {
            "plane" => Analytic::Plane { a: positive("a")?, b: positive("b")? },
            "cylinder" => {
                let (a0, a1) = angles()?;
                Analytic::Cylinder { r: positive("r")?, l: positive("l")?, a0, a1 }
            }
            "cone" => {
                let (a0, a1) = angles()?;
                let (r0, r1) = (need("r0")?, need("r1")?);
                if r0 < 0.0 || r1 < 0.0 || (r0 == 0.0 && r1 == 0.0) {
                    return Err(fail("radii must be >= 0 and not both zero".into()));
                }
                Analytic::Cone { r0, r1, l: positive("l")?, a0, a1 }
            }
            _ => {
                let lat0 = get("lat0").unwrap_or(-90.0).to_radians();
                let lat1 = get("lat1").unwrap_or(90.0).to_radians();
                if !(lat0 < lat1) || lat0 < -PI / 2.0 - 1e-12 || lat1 > PI / 2.0 + 1e-12 {
                    return Err(fail("need -90 <= lat0 < lat1 <= 90".into()));
                }
                Analytic::Sphere { r: positive("r")?, lat0: lat0.max(-PI / 2.0), lat1: lat1.min(PI / 2.0) }
            }
        })
    }

    /// The same surface with every length multiplied by `f` (a change of units); angles kept.
    pub fn scaled(&self, f: f64) -> Analytic {
        match *self {
            Analytic::Plane { a, b } => Analytic::Plane { a: a * f, b: b * f },
            Analytic::Cylinder { r, l, a0, a1 } => Analytic::Cylinder { r: r * f, l: l * f, a0, a1 },
            Analytic::Cone { r0, r1, l, a0, a1 } => Analytic::Cone { r0: r0 * f, r1: r1 * f, l: l * f, a0, a1 },
            Analytic::Sphere { r, lat0, lat1 } => Analytic::Sphere { r: r * f, lat0, lat1 },
        }
    }

    /// The largest length of the description (radius, side or length).
    pub fn size(&self) -> f64 {
        match *self {
            Analytic::Plane { a, b } => a.max(b),
            Analytic::Cylinder { r, l, .. } => r.max(l),
            Analytic::Cone { r0, r1, l, .. } => r0.max(r1).max(l),
            Analytic::Sphere { r, .. } => r,
        }
    }

    /// Whether u is periodic and the surface closes on itself (full tube, cone or sphere).
    pub fn is_closed_u(&self) -> bool {
        match *self {
            Analytic::Plane { .. } => false,
            Analytic::Cylinder { a0, a1, .. } | Analytic::Cone { a0, a1, .. } => (a1 - a0 - TAU).abs() < 1e-12,
            Analytic::Sphere { .. } => true,
        }
    }

    /// Exact area.
    pub fn area(&self) -> f64 {
        match *self {
            Analytic::Plane { a, b } => a * b,
            Analytic::Cylinder { r, l, a0, a1 } => r * (a1 - a0) * l,
            Analytic::Cone { r0, r1, l, a0, a1 } => 0.5 * (a1 - a0) * (r0 + r1) * (l * l + (r1 - r0).powi(2)).sqrt(),
            Analytic::Sphere { r, lat0, lat1 } => TAU * r * r * (lat1.sin() - lat0.sin()),
        }
    }
}

fn wrap_angle(phi: f64, a0: f64, a1: f64) -> f64 {
    // Bring phi into [a0, a0 + 2π), then clamp to [a0, a1] choosing the nearer end.
    let mut t = (phi - a0).rem_euclid(TAU) + a0;
    if t > a1 {
        let over = t - a1;
        let under = a0 + TAU - t;
        t = if over < under { a1 } else { a0 };
    }
    t
}

impl Surface for Analytic {
    fn closed_u(&self) -> bool {
        self.is_closed_u()
    }

    fn domain(&self) -> [[f64; 2]; 2] {
        match *self {
            Analytic::Plane { a, b } => [[0.0, a], [0.0, b]],
            Analytic::Cylinder { l, a0, a1, .. } | Analytic::Cone { l, a0, a1, .. } => [[a0, a1], [0.0, l]],
            Analytic::Sphere { lat0, lat1, .. } => [[0.0, TAU], [lat0, lat1]],
        }
    }

    fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.derivatives(u, v).0
    }

    fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        match *self {
            Analytic::Plane { .. } => (DVec3::new(u, v, 0.0), DVec3::X, DVec3::Y),
            Analytic::Cylinder { r, .. } => {
                let (s, c) = u.sin_cos();
                (DVec3::new(r * c, r * s, v), DVec3::new(-r * s, r * c, 0.0), DVec3::Z)
            }
            Analytic::Cone { r0, r1, l, .. } => {
                let (s, c) = u.sin_cos();
                let rho = r0 + (r1 - r0) * v / l;
                let dr = (r1 - r0) / l;
                (DVec3::new(rho * c, rho * s, v), DVec3::new(-rho * s, rho * c, 0.0), DVec3::new(dr * c, dr * s, 1.0))
            }
            Analytic::Sphere { r, .. } => {
                let (s, c) = u.sin_cos();
                let (sl, cl) = v.sin_cos();
                (
                    DVec3::new(r * cl * c, r * cl * s, r * sl),
                    DVec3::new(-r * cl * s, r * cl * c, 0.0),
                    DVec3::new(-r * sl * c, -r * sl * s, r * cl),
                )
            }
        }
    }

    fn normal(&self, u: f64, v: f64) -> DVec3 {
        match *self {
            Analytic::Plane { .. } => DVec3::Z,
            Analytic::Cylinder { .. } => DVec3::new(u.cos(), u.sin(), 0.0),
            Analytic::Cone { r0, r1, l, .. } => {
                // Outward normal of the generator line in the (rho, z) half-plane.
                let (s, c) = u.sin_cos();
                let n2 = glam::DVec2::new(l, -(r1 - r0)).normalize();
                DVec3::new(n2.x * c, n2.x * s, n2.y)
            }
            Analytic::Sphere { .. } => {
                let (s, c) = u.sin_cos();
                let (sl, cl) = v.sin_cos();
                DVec3::new(cl * c, cl * s, sl)
            }
        }
    }

    fn closest(&self, p: DVec3) -> ClosestPoint {
        let [_, [v0, v1]] = self.domain();
        match *self {
            Analytic::Plane { a, b } => {
                let (u, v) = (p.x.clamp(0.0, a), p.y.clamp(0.0, b));
                ClosestPoint { point: DVec3::new(u, v, 0.0), normal: DVec3::Z, uv: [u, v] }
            }
            Analytic::Cylinder { a0, a1, .. } | Analytic::Cone { a0, a1, .. } => {
                let u = wrap_angle(p.y.atan2(p.x), a0, a1);
                // Closest point of the generator segment in the half-plane of angle u.
                let rho_p = DVec3::new(u.cos(), u.sin(), 0.0).dot(p);
                let (ra, rb, l) = match *self {
                    Analytic::Cylinder { r, l, .. } => (r, r, l),
                    Analytic::Cone { r0, r1, l, .. } => (r0, r1, l),
                    _ => unreachable!("matched above"),
                };
                let (a, b) = (glam::DVec2::new(ra, 0.0), glam::DVec2::new(rb, l));
                let q = glam::DVec2::new(rho_p, p.z);
                let ab = b - a;
                let t = ((q - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                let v = (t * l).clamp(v0, v1);
                ClosestPoint { point: self.eval(u, v), normal: self.normal(u, v), uv: [u, v] }
            }
            Analytic::Sphere { .. } => {
                let u = p.y.atan2(p.x).rem_euclid(TAU);
                let rxy = (p.x * p.x + p.y * p.y).sqrt();
                let v = p.z.atan2(rxy).clamp(v0, v1);
                ClosestPoint { point: self.eval(u, v), normal: self.normal(u, v), uv: [u, v] }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_descriptions_and_names_problems() {
        assert_eq!(
            Analytic::parse("cylinder:r=300,l=1000").unwrap(),
            Analytic::Cylinder { r: 300.0, l: 1000.0, a0: 0.0, a1: TAU }
        );
        assert!(matches!(Analytic::parse("sphere:r=500").unwrap(), Analytic::Sphere { r, .. } if r == 500.0));
        let e = Analytic::parse("cylinder:r=300").unwrap_err();
        assert!(e.to_string().contains("missing l="), "{e}");
        let e = Analytic::parse("torus:r=1").unwrap_err();
        assert!(e.to_string().contains("unknown kind"), "{e}");
        let e = Analytic::parse("plane:a=1,b=x").unwrap_err();
        assert!(e.to_string().contains("not a number"), "{e}");
        assert!(Analytic::parse("cylinder:r=-1,l=2").is_err());
        assert!(Analytic::parse("cylinder:r=1,l=2,q=3").is_err());
        let e = Analytic::parse("plane:a=100,b=50,A=200").unwrap_err();
        assert!(e.to_string().contains("a is given twice"), "{e}");
    }

    #[test]
    fn derivatives_match_finite_differences_and_normals_are_unit() {
        let surfaces = [
            Analytic::parse("cylinder:r=300,l=1000").unwrap(),
            Analytic::parse("cone:r0=300,r1=150,l=600").unwrap(),
            Analytic::parse("sphere:r=500").unwrap(),
        ];
        for s in surfaces {
            let (u, v) = (0.7, 0.3);
            let (_, su, sv) = s.derivatives(u, v);
            let h = 1e-6;
            let fu = (s.eval(u + h, v) - s.eval(u - h, v)) / (2.0 * h);
            let fv = (s.eval(u, v + h) - s.eval(u, v - h)) / (2.0 * h);
            assert!((fu - su).length() < 1e-4 * su.length().max(1.0));
            assert!((fv - sv).length() < 1e-4 * sv.length().max(1.0));
            let n = s.normal(u, v);
            assert!((n.length() - 1.0).abs() < 1e-12);
            assert!((n - su.cross(sv).normalize()).length() < 1e-9);
        }
    }

    #[test]
    fn closest_point_is_a_foot_of_perpendicular() {
        let s = Analytic::parse("cone:r0=300,r1=150,l=600").unwrap();
        let p = DVec3::new(310.0, 40.0, 200.0);
        let c = s.closest(p);
        let (_, su, sv) = s.derivatives(c.uv[0], c.uv[1]);
        assert!((p - c.point).dot(su).abs() < 1e-9);
        assert!((p - c.point).dot(sv).abs() < 1e-9);
    }
}
