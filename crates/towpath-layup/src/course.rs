//! A course: the centreline of a band of tows with, per tow, the arc-length intervals where the
//! tow is laid.

use glam::DVec3;
use serde::Serialize;

use towpath_geom::{Mesh, SurfacePoint, NO_FACE};

use crate::trace::{Located, PathPoint};

/// One course of a ply.
#[derive(Debug, Clone, Serialize)]
pub struct Course {
    /// Position in the ply, from the rightmost course (looking along the fiber with the normal up)
    /// to the leftmost.
    pub id: usize,
    /// −1: right of the reference course, 0: the reference course, +1: left of it.
    pub side: i8,
    /// 0 for the reference course, k for the k-th course on its side.
    pub offset_index: usize,
    /// Centreline points, arc length from the first.
    pub points: Vec<PathPoint>,
    /// Whether each point lies on the mesh (false for run-outs beyond a mesh edge).
    pub on_surface: Vec<bool>,
    /// For every tow (tow 0 is the rightmost), the arc-length intervals where it is laid.
    pub tows: Vec<Vec<[f64; 2]>>,
}

impl Course {
    /// Centreline length.
    pub fn length(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.s)
    }

    /// Interpolated centreline frame at arc length `s` (clamped): position, normal, direction.
    pub fn frame_at(&self, s: f64) -> (DVec3, DVec3, DVec3) {
        frame_at(&self.points, s)
    }

    /// Tow restart (add) and cut positions in order: (arc length, restarted mask, cut mask).
    /// Tow k is bit k of the mask.
    pub fn events(&self) -> Vec<TowEvent> {
        let mut ev: Vec<(f64, usize, bool)> = Vec::new();
        for (k, ivs) in self.tows.iter().enumerate() {
            for iv in ivs {
                ev.push((iv[0], k, true));
                ev.push((iv[1], k, false));
            }
        }
        ev.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.2.cmp(&a.2)));
        let mut out: Vec<TowEvent> = Vec::new();
        for (s, k, on) in ev {
            let same = out.last_mut().filter(|e| (e.s - s).abs() <= 1e-6);
            let e = match same {
                Some(e) => e,
                None => {
                    out.push(TowEvent { s, restart: 0, cut: 0 });
                    out.last_mut().expect("just pushed")
                }
            };
            let bit = 1u64 << k.min(63);
            if on {
                e.restart |= bit;
            } else {
                e.cut |= bit;
            }
        }
        out
    }

    /// Whether the centreline at arc length `s` lies on the mesh (not on a run-out).
    pub fn on_surface_at(&self, s: f64) -> bool {
        let i = self.points.partition_point(|q| q.s < s);
        let a = self.on_surface.get(i.saturating_sub(1)).copied().unwrap_or(true);
        let b = self.on_surface.get(i.min(self.points.len().saturating_sub(1))).copied().unwrap_or(true);
        a && b
    }

    /// Whether tow `k` is laid at arc length `s`.
    pub fn laid(&self, k: usize, s: f64) -> bool {
        self.tows.get(k).is_some_and(|ivs| ivs.iter().any(|iv| iv[0] <= s && s <= iv[1]))
    }

    /// Arc-length range over which any tow is laid.
    pub fn laid_range(&self) -> Option<[f64; 2]> {
        let lo = self.tows.iter().flatten().map(|iv| iv[0]).fold(f64::INFINITY, f64::min);
        let hi = self.tows.iter().flatten().map(|iv| iv[1]).fold(f64::NEG_INFINITY, f64::max);
        (lo <= hi).then_some([lo, hi])
    }
}

/// A tow restart/cut event along a course.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TowEvent {
    /// Arc length along the course.
    pub s: f64,
    /// Tows restarted here (bit k = tow k).
    pub restart: u64,
    /// Tows cut here.
    pub cut: u64,
}

/// The face hint of the segment containing arc length `s` ([`NO_FACE`] if unknown).
pub fn face_hint(points: &[PathPoint], s: f64) -> u32 {
    let i = points.partition_point(|q| q.s < s).clamp(1, points.len().max(1));
    points.get(i.min(points.len().saturating_sub(1))).map_or(NO_FACE, |q| q.face)
}

/// Locates `p` on the mesh: in face `hint` when `p` projects inside it, else by the closest point.
pub fn locate(mesh: &Mesh, p: DVec3, hint: u32) -> Option<Located> {
    if (hint as usize) < mesh.num_faces() {
        let b = mesh.barycentric(hint, p);
        if b.min_element() >= -1e-9 {
            let b = b.max(DVec3::ZERO);
            let b = b / (b.x + b.y + b.z);
            return Some(Located::new(mesh, SurfacePoint { face: hint, bary: b }));
        }
    }
    mesh.closest_point(p).map(|sp| Located::new(mesh, sp))
}

/// Interpolated frame on a polyline of path points at arc length `s` (clamped).
pub fn frame_at(points: &[PathPoint], s: f64) -> (DVec3, DVec3, DVec3) {
    let Some(first) = points.first() else { return (DVec3::ZERO, DVec3::Z, DVec3::X) };
    if points.len() == 1 || s <= first.s {
        return (first.p, first.n, first.d);
    }
    let i = points.partition_point(|q| q.s < s);
    if i >= points.len() {
        let l = &points[points.len() - 1];
        return (l.p, l.n, l.d);
    }
    let (a, b) = (&points[i - 1], &points[i]);
    let t = if b.s > a.s { (s - a.s) / (b.s - a.s) } else { 0.0 };
    let n = a.n.lerp(b.n, t).normalize_or_zero();
    let d = a.d.lerp(b.d, t);
    let d = (d - n * d.dot(n)).normalize_or_zero();
    (a.p.lerp(b.p, t), n, d)
}
