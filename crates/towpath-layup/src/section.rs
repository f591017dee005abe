//! Cross sections of a course and per-tow trimming at the ply boundary under a coverage rule.
//!
//! At a station (arc length s) the course's cross section is walked along the surface, as a
//! geodesic perpendicular to the fiber, to the lateral positions of every tow edge and tow centre.
//! A line position is *inside* when the walk reaches it without leaving the mesh and it lies
//! inside the ply boundary curve (if any). Stations far from every boundary are classified from
//! the centre alone. The coverage rule decides from the three positions of a tow (its two edges
//! and its centre) whether it is laid there; transitions between stations are refined by
//! bisection, so restart and cut positions are accurate to a small fraction of a millimetre.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use towpath_geom::Mesh;

use crate::boundary::Region;
use crate::course::{face_hint, frame_at, locate};
use crate::trace::{walk, PathPoint, Steering, Stop, WalkOptions};

/// Where a tow is cut (and restarted) at the ply boundary: the 0 % / 50 % / 100 % coverage
/// conventions of AFP programming tools.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Coverage {
    /// 0 %: a tow is laid only where all of its width is inside (cut at first touch of the
    /// boundary, restarted once fully inside): no material outside, small gaps along the boundary.
    Zero,
    /// 50 %: a tow is laid where its centre is inside (cut at the centre crossing).
    Half,
    /// 100 %: a tow is laid wherever any of its width is inside (cut at full exit): the ply is
    /// fully covered, material overhangs the boundary.
    Full,
}

impl Coverage {
    /// From a percentage 0, 50 or 100.
    pub fn from_percent(p: u32) -> Option<Coverage> {
        match p {
            0 => Some(Coverage::Zero),
            50 => Some(Coverage::Half),
            100 => Some(Coverage::Full),
            _ => None,
        }
    }
    /// As a percentage.
    pub fn percent(self) -> u32 {
        match self {
            Coverage::Zero => 0,
            Coverage::Half => 50,
            Coverage::Full => 100,
        }
    }
}

/// Geometry of the band of tows.
#[derive(Debug, Clone, Copy)]
pub struct Band {
    /// Tow width.
    pub tow_width: f64,
    /// Number of tows.
    pub tows: usize,
}

impl Band {
    /// Course width: tows × tow width.
    pub fn width(&self) -> f64 {
        self.tow_width * self.tows as f64
    }
    /// Lateral offset (along n × d, to the left) of tow edge j (0..=tows); edge 0 is the right
    /// edge of tow 0.
    pub fn edge(&self, j: usize) -> f64 {
        j as f64 * self.tow_width - 0.5 * self.width()
    }
    /// Lateral offset of tow k's centre.
    pub fn centre(&self, k: usize) -> f64 {
        (k as f64 + 0.5) * self.tow_width - 0.5 * self.width()
    }
}

/// Inside flags of all line positions of a cross section.
#[derive(Debug, Clone)]
pub struct Section {
    /// Tow edges 0..=tows.
    pub edges: Vec<bool>,
    /// Tow centres 0..tows.
    pub centres: Vec<bool>,
}

impl Section {
    /// Whether tow k is laid under the rule.
    pub fn laid(&self, k: usize, rule: Coverage) -> bool {
        let (l, c, r) = (self.edges[k], self.centres[k], self.edges[k + 1]);
        match rule {
            Coverage::Zero => l && c && r,
            Coverage::Half => c,
            Coverage::Full => l || c || r,
        }
    }
}

/// Evaluates cross sections of one course polyline.
pub struct Sectioner<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The ply region.
    pub region: &'a Region,
    /// The band.
    pub band: Band,
    /// Surface already covered (by other courses): lines there count as outside the ply, so a
    /// closing course is trimmed against the courses laid before it under the same rule.
    pub occupied: Option<&'a (dyn Fn(DVec3) -> bool + Sync)>,
}

impl Sectioner<'_> {
    /// Inside test of a point known to be on the mesh, with the surface normal near it.
    fn inside_curve(&self, q: DVec3, n: DVec3) -> bool {
        (!self.region.has_curve() || self.region.curve_distance(q, n) >= 0.0) && !self.occupied.is_some_and(|f| f(q))
    }

    /// Whether a point near the mesh edge (possibly off the surface) lies over the mesh rather than
    /// beyond its boundary: the side of the nearest mesh boundary edge (interior on the left).
    fn on_mesh(&self, q: DVec3) -> bool {
        self.region.mesh_edges.signed_distance(q) >= 0.0
    }

    /// The cross section at arc length `s` of `points`.
    pub fn section(&self, points: &[PathPoint], s: f64) -> Section {
        let nt = self.band.tows;
        let offsets: Vec<f64> =
            (0..=nt).map(|j| self.band.edge(j)).chain((0..nt).map(|k| self.band.centre(k))).collect();
        let inside = self.lines(points, s, &offsets);
        Section { edges: inside[..=nt].to_vec(), centres: inside[nt + 1..].to_vec() }
    }

    /// Whether tow `k` is laid at `s` under `rule` (its two edges and centre only).
    pub fn tow_laid(&self, points: &[PathPoint], s: f64, k: usize, rule: Coverage) -> bool {
        let offsets = [self.band.edge(k), self.band.centre(k), self.band.edge(k + 1)];
        let v = self.lines(points, s, &offsets);
        match rule {
            Coverage::Zero => v[0] && v[1] && v[2],
            Coverage::Half => v[1],
            Coverage::Full => v[0] || v[1] || v[2],
        }
    }

    /// Inside flags of the lines at lateral `offsets` (left positive) at arc length `s`.
    pub fn lines(&self, points: &[PathPoint], s: f64, offsets: &[f64]) -> Vec<bool> {
        let (p, n, d) = frame_at(points, s);
        let half = 0.5 * self.band.width();
        let margin = half + self.band.tow_width;
        let sd = self.region.curve_distance(p, n);
        if sd < -margin {
            return vec![false; offsets.len()];
        }
        let hint = face_hint(points, s);
        // A run-out point (no face) beyond the mesh edge needs no projection.
        let located = if hint == towpath_geom::NO_FACE && !self.on_mesh(p) { None } else { locate(self.mesh, p, hint) };
        let centre_on_mesh = located.is_some_and(|l| {
            let v = p - l.p;
            let nf = self.mesh.face_normal(l.sp.face);
            (v - nf * v.dot(nf)).length() <= 1e-3 * self.band.tow_width
        });
        if centre_on_mesh && sd > margin && self.region.mesh_edges.distance(p) > margin && self.occupied.is_none() {
            return vec![true; offsets.len()];
        }
        let b = n.cross(d).normalize_or_zero();
        let mut inside = vec![false; offsets.len()];
        match located {
            Some(start) if centre_on_mesh => {
                // Geodesic walks to each side that has lines, just past the outermost one.
                let reach_l = offsets.iter().fold(0.0f64, |m, &o| m.max(o));
                let reach_r = offsets.iter().fold(0.0f64, |m, &o| m.max(-o));
                let side = |dir: DVec3, reach: f64| {
                    if reach <= 0.0 {
                        return (Vec::new(), Stop::Length);
                    }
                    let opts = WalkOptions::up_to(reach + 1e-9);
                    walk(self.mesh, start, dir, Steering::Geodesic, &opts, |_| false)
                };
                let (left, stop_l) = side(b, reach_l);
                let (right, stop_r) = side(-b, reach_r);
                for (i, &o) in offsets.iter().enumerate() {
                    let (w, stop) = if o >= 0.0 { (&left, stop_l) } else { (&right, stop_r) };
                    let a = o.abs();
                    if a <= 1e-12 {
                        inside[i] = self.inside_curve(start.p, start.n);
                        continue;
                    }
                    let reach = w.last().map_or(0.0, |q| q.s);
                    if reach + 1e-9 < a && stop != Stop::Length {
                        continue; // the mesh ends before this line
                    }
                    inside[i] = self.inside_curve(point_at(start.p, w, a), start.n);
                }
            }
            _ => {
                // The centre is beyond the mesh (a run-out): offsets in the tangent plane.
                for (i, &o) in offsets.iter().enumerate() {
                    let q = p + b * o;
                    inside[i] = self.on_mesh(q) && self.inside_curve(q, n);
                }
            }
        }
        inside
    }

    /// Laid intervals per tow along `points` (stations every `step`, transitions refined by
    /// bisection to `tol`).
    pub fn trim(&self, points: &[PathPoint], rule: Coverage, step: f64, tol: f64) -> Vec<Vec<[f64; 2]>> {
        let nt = self.band.tows;
        let mut out = vec![Vec::new(); nt];
        let (Some(first), Some(last)) = (points.first(), points.last()) else { return out };
        let (s0, s1) = (first.s, last.s);
        if !(s1 > s0) {
            return out;
        }
        let count = ((s1 - s0) / step).ceil().max(1.0) as usize;
        let stations: Vec<f64> = (0..=count).map(|i| s0 + (s1 - s0) * i as f64 / count as f64).collect();
        let sections: Vec<Section> = stations.iter().map(|&s| self.section(points, s)).collect();
        for k in 0..nt {
            let mut start: Option<f64> = None;
            for i in 0..stations.len() {
                let on = sections[i].laid(k, rule);
                match (start, on) {
                    (None, true) => {
                        start = Some(if i == 0 {
                            stations[0]
                        } else {
                            self.refine(points, k, rule, stations[i - 1], stations[i], false, tol)
                        });
                    }
                    (Some(a), false) => {
                        let e = self.refine(points, k, rule, stations[i - 1], stations[i], true, tol);
                        if e > a {
                            out[k].push([a, e]);
                        }
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(a) = start {
                out[k].push([a, s1]);
            }
            // Merge laid intervals separated by less than a quarter tow width: a cut and restart
            // that close is noise of the boundary test, not a gap worth a cut cycle.
            let mut merged: Vec<[f64; 2]> = Vec::with_capacity(out[k].len());
            for iv in out[k].drain(..) {
                match merged.last_mut() {
                    Some(last) if iv[0] - last[1] < 0.25 * self.band.tow_width => last[1] = iv[1],
                    _ => merged.push(iv),
                }
            }
            out[k] = merged;
        }
        out
    }

    /// Bisection between a station where tow k is (not) laid and the next where it changes.
    #[allow(clippy::too_many_arguments)]
    fn refine(
        &self,
        points: &[PathPoint],
        k: usize,
        rule: Coverage,
        mut a: f64,
        mut b: f64,
        laid_at_a: bool,
        tol: f64,
    ) -> f64 {
        while b - a > tol {
            let m = 0.5 * (a + b);
            if self.tow_laid(points, m, k, rule) == laid_at_a {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }
}

/// Position at arc length `a` along a walk starting at `p0`.
fn point_at(p0: DVec3, w: &[PathPoint], a: f64) -> DVec3 {
    let mut prev = (p0, 0.0);
    for q in w {
        if q.s >= a {
            let t = if q.s > prev.1 { (a - prev.1) / (q.s - prev.1) } else { 1.0 };
            return prev.0.lerp(q.p, t.clamp(0.0, 1.0));
        }
        prev = (q.p, q.s);
    }
    prev.0
}
