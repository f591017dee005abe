//! Transits: how the gun gets from the end of one pass to the start of the next with the spray
//! off, keeping away from the part.
//!
//! A transit is the straight move when that keeps at least the clearance ([`CLEARANCE`] times
//! the standoff) from the part; otherwise the gun lifts: it backs off along the surface normal
//! at both ends by the least of ¼, ½, 1, 2, 4, … standoffs that makes the three moves clear; if
//! no lift up to the part's size does, it goes round by a sphere enclosing the part one standoff
//! out (back off, out radially, along a great circle, in, approach). Clearance is checked by
//! sphere tracing against the mesh: from each point the move advances by the distance to the
//! part minus the clearance (at least a fiftieth of the standoff), so the whole move is checked
//! to within that step. Near an end that is already closer than the clearance (a pass in a
//! concave corner), the move must only keep that end's distance.

use glam::DVec3;
use towpath_geom::Mesh;

/// Transits keep this fraction of the standoff from the part.
pub const CLEARANCE: f64 = 0.9;

/// A transit: the moves from one pose to the next with the spray off.
#[derive(Debug, Clone, PartialEq)]
pub struct Transit {
    /// The intermediate points (not including the two ends); empty for a straight move.
    pub via: Vec<DVec3>,
    /// Total length (mm).
    pub length: f64,
    /// Whether every move was checked clear (false only when even the way round was not).
    pub clear: bool,
}

/// Clearance checks against a mesh.
pub struct Clearance<'m> {
    mesh: &'m Mesh,
    standoff: f64,
    centre: DVec3,
    sphere: f64,
    size: f64,
}

impl<'m> Clearance<'m> {
    /// Checks against `mesh` for a gun at `standoff`.
    pub fn new(mesh: &'m Mesh, standoff: f64) -> Clearance<'m> {
        mesh.prepare_index();
        let (lo, hi) = mesh.bounds();
        let centre = (lo + hi) * 0.5;
        let far = mesh.positions().iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
        Clearance { mesh, standoff, centre, sphere: far + standoff, size: (hi - lo).length() }
    }

    /// The required clearance.
    pub fn required(&self) -> f64 {
        CLEARANCE * self.standoff
    }

    /// Distance from a point to the part.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.mesh.closest_point(p).map_or(f64::INFINITY, |sp| self.mesh.point(sp).distance(p))
    }

    /// Whether the move a → b keeps the clearance (or, near an end already closer, that end's
    /// distance). `da`, `db`: distances of the ends to the part.
    pub fn clear(&self, a: DVec3, da: f64, b: DVec3, db: f64) -> bool {
        let need = self.required().min(0.99 * da).min(0.99 * db);
        let len = a.distance(b);
        if len == 0.0 {
            return true;
        }
        // Both ends certify balls around them (the distance is 1-Lipschitz).
        if da + db - 2.0 * need >= len {
            return true;
        }
        let dir = (b - a) / len;
        let min_step = self.standoff / 50.0;
        let mut s = 0.0;
        let mut d = da;
        loop {
            if d < need {
                return false;
            }
            // Everything within d - need of the point is clear; so is the rest to b if b's ball
            // reaches.
            if len - s <= (d - need) + (db - need) {
                return true;
            }
            s += (d - need).max(min_step);
            if s >= len {
                return db >= need;
            }
            d = self.distance(a + dir * s);
        }
    }

    /// The transit from `a` (surface normal `na` there, pointing away from the part) to `b`.
    pub fn transit(&self, a: DVec3, na: DVec3, b: DVec3, nb: DVec3) -> Transit {
        let (da, db) = (self.distance(a), self.distance(b));
        if self.clear(a, da, b, db) {
            return Transit { via: Vec::new(), length: a.distance(b), clear: true };
        }
        let mut lift = 0.25 * self.standoff;
        while lift <= 2.0 * self.size + self.standoff {
            let (a2, b2) = (a + na * lift, b + nb * lift);
            let (da2, db2) = (self.distance(a2), self.distance(b2));
            if self.clear(a, da, a2, da2) && self.clear(a2, da2, b2, db2) && self.clear(b2, db2, b, db) {
                return Transit { via: vec![a2, b2], length: lift * 2.0 + a2.distance(b2), clear: true };
            }
            lift *= 2.0;
        }
        self.round_sphere(a, na, da, b, nb, db)
    }

    /// The way round by the enclosing sphere.
    fn round_sphere(&self, a: DVec3, na: DVec3, da: f64, b: DVec3, nb: DVec3, db: f64) -> Transit {
        let mut clear = true;
        let mut backoff = |p: DVec3, n: DVec3, dp: f64| -> DVec3 {
            let mut lift = 0.25 * self.standoff;
            while lift <= self.sphere {
                let q = p + n * lift;
                if self.clear(p, dp, q, self.distance(q)) {
                    return q;
                }
                lift *= 2.0;
            }
            clear = false;
            p + n * self.standoff
        };
        let a2 = backoff(a, na, da);
        let b2 = backoff(b, nb, db);
        let out = |p: DVec3| self.centre + (p - self.centre).try_normalize().unwrap_or(DVec3::Z) * self.sphere;
        let (a3, b3) = (out(a2), out(b2));
        for (p, q) in [(a2, a3), (b3, b2)] {
            let (dp, dq) = (self.distance(p), self.distance(q));
            if !self.clear(p, dp, q, dq) {
                clear = false;
            }
        }
        let mut via = vec![a2, a3];
        // Great circle from a3 to b3: chords short enough to sag at most 5 % of the standoff.
        let (ua, ub) = ((a3 - self.centre) / self.sphere, (b3 - self.centre) / self.sphere);
        let ang = ua.dot(ub).clamp(-1.0, 1.0).acos();
        let max_step = 2.0 * (1.0 - 0.05 * self.standoff / self.sphere).clamp(-1.0, 1.0).acos();
        let n = ((ang / max_step.max(1e-6)).ceil() as usize).max(1);
        let axis = ua.cross(ub).try_normalize().unwrap_or_else(|| crate::frame::plane_axes(ua).0);
        for k in 1..n {
            let t = ang * k as f64 / n as f64;
            let u = ua * t.cos() + axis.cross(ua) * t.sin() + axis * axis.dot(ua) * (1.0 - t.cos());
            via.push(self.centre + u * self.sphere);
        }
        via.push(b3);
        via.push(b2);
        let mut length = 0.0;
        let mut prev = a;
        for &p in via.iter().chain(std::iter::once(&b)) {
            length += prev.distance(p);
            prev = p;
        }
        Transit { via, length, clear }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_geom::{BuildOptions, Soup};

    /// A closed unit cube scaled to `s`.
    pub(crate) fn cube(s: f64) -> Mesh {
        let p: Vec<DVec3> =
            (0..8).map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) * s).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut t = Vec::new();
        for q in quads {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        Mesh::build(&Soup { positions: p, triangles: t }, &BuildOptions::default()).unwrap().0
    }

    fn min_distance(c: &Clearance, pts: &[DVec3]) -> f64 {
        let mut m = f64::INFINITY;
        for w in pts.windows(2) {
            for k in 0..=400 {
                m = m.min(c.distance(w[0].lerp(w[1], k as f64 / 400.0)));
            }
        }
        m
    }

    #[test]
    fn transits_keep_clear_of_a_cube() {
        let m = cube(100.0);
        let c = Clearance::new(&m, 20.0);
        // Over the top: straight.
        let a = DVec3::new(10.0, 50.0, 120.0);
        let b = DVec3::new(90.0, 50.0, 120.0);
        let t = c.transit(a, DVec3::Z, b, DVec3::Z);
        assert!(t.via.is_empty() && (t.length - 80.0).abs() < 1e-9);
        // Top to side (+x face): would cut the edge; lifted.
        let b = DVec3::new(120.0, 50.0, 10.0);
        let t = c.transit(a, DVec3::Z, b, DVec3::X);
        assert!(!t.via.is_empty() && t.clear);
        let pts: Vec<DVec3> = std::iter::once(a).chain(t.via.iter().copied()).chain(std::iter::once(b)).collect();
        assert!(min_distance(&c, &pts) >= c.required() - 20.0 / 50.0, "{}", min_distance(&c, &pts));
        // Top to bottom: through the cube is impossible, the lift or the way round is taken.
        let b = DVec3::new(50.0, 50.0, -20.0);
        let t = c.transit(a, DVec3::Z, b, -DVec3::Z);
        let pts: Vec<DVec3> = std::iter::once(a).chain(t.via.iter().copied()).chain(std::iter::once(b)).collect();
        assert!(t.clear);
        assert!(min_distance(&c, &pts) >= c.required() - 20.0 / 50.0);
        let len: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!((len - t.length).abs() < 1e-9);
    }
}
