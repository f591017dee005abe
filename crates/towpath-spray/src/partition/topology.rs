//! Topology partition (Tewolde & Sheng 2008 §III-A, after Sheng et al. 2004): a piece seen in
//! projection on the plane of its mean normal is split into hole-free, regular, nearly convex
//! cells, and the split is mapped back onto the surface (cells are sets of triangles).
//!
//! For a candidate sweep direction t (passes along t, the sweep coordinate x across them), the
//! *critical points* are the border's reflex extrema of x: points where the border turns back
//! in x with the piece on the outer side of the turn (the near side of a hole, the bottom of a
//! notch). Cutting along t through every critical point, from border to border, leaves cells
//! that are hole-free and monotone in x (every pass line crosses a cell once: Huang's
//! boustrophedon decomposition). Every other reflex corner (the inner corner of an L) is cut
//! along t as far as the piece lies on both sides of the line, which removes the corner.
//! Neighbouring cells are then merged, greedily, while the union stays hole-free and monotone
//! and the weighted cost goes down:
//!
//! - **turns**: the cell's width across its best sweep direction in spray radii (≈ passes,
//!   each ending in a turn; the paper's minimum altitude), weight 1;
//! - **common border** (where thickness is hard to keep even) in spray radii, weight ½;
//! - **reflex corners** (interior angle above 200°, the convexity criterion), weight 2 each;
//! - **sharp corners** (interior angle below 60°, the regularity criterion), weight 1 each.
//!
//! The candidate directions are the piece's principal axes and its long border directions; the
//! cheapest partition wins (the unsplit piece competes when it has no hole). The paper solves
//! the weighted set partition exactly with commercial software over candidate sub-polygons; here
//! the candidates are the boustrophedon cells and their greedy unions, per direction.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3};
use towpath_geom::{Mesh, NO_FACE};

use super::{components, mean_normal};
use crate::frame::{plane_axes, Frame};
use crate::passes::simplify_closed;

/// Weight of one spray radius of common border.
const W_BORDER: f64 = 0.5;
/// Weight of a reflex corner.
const W_REFLEX: f64 = 2.0;
/// Weight of a sharp corner.
const W_SHARP: f64 = 1.0;
/// A turn sharper than this (degrees) makes a reflex corner (interior angle > 180° + this).
const REFLEX_DEG: f64 = 20.0;
/// An interior angle below this (degrees) is a sharp corner.
const SHARP_DEG: f64 = 60.0;

/// The plane of a piece: axes and projection.
struct Plane {
    origin: DVec3,
    eu: DVec3,
    ev: DVec3,
}

impl Plane {
    fn to2(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.origin).dot(self.eu), (p - self.origin).dot(self.ev))
    }
}

/// Shape figures of a cell.
#[derive(Debug, Clone)]
struct Shape {
    loops: usize,
    reflex: usize,
    sharp: usize,
    /// Smallest width over the directions across its simplified edges (mm).
    width: f64,
    /// The simplified outer loop.
    outer: Vec<DVec2>,
}

/// The border loops of a face set, projected (oriented with the set on the left).
fn outline(mesh: &Mesh, faces: &[u32], set: &HashSet<u32>, plane: &Plane) -> Vec<Vec<DVec2>> {
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut count = 0;
    for &f in faces {
        let t = mesh.triangles()[f as usize];
        for k in 0..3 {
            let g = mesh.neighbor(f, k);
            if g == NO_FACE || !set.contains(&g) {
                next.entry(t[k]).or_default().push(t[(k + 1) % 3]);
                count += 1;
            }
        }
    }
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    let mut used = 0;
    for s in starts {
        while next.get(&s).is_some_and(|v| !v.is_empty()) {
            let mut lp = vec![plane.to2(mesh.positions()[s as usize])];
            let mut cur = s;
            while let Some(n) = next.get_mut(&cur).and_then(Vec::pop) {
                used += 1;
                if n == s || used > count {
                    break;
                }
                lp.push(plane.to2(mesh.positions()[n as usize]));
                cur = n;
            }
            loops.push(lp);
        }
    }
    loops
}

/// Signed area of a closed polygon (positive counter-clockwise).
fn signed_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() * 0.5
}

fn shape(mesh: &Mesh, faces: &[u32], plane: &Plane, tol: f64) -> Shape {
    let set: HashSet<u32> = faces.iter().copied().collect();
    let loops = outline(mesh, faces, &set, plane);
    let simp: Vec<Vec<DVec2>> = loops.iter().map(|l| simplify_closed(l, tol)).collect();
    let outer =
        simp.iter().max_by(|a, b| signed_area(a).abs().total_cmp(&signed_area(b).abs())).cloned().unwrap_or_default();
    let (mut reflex, mut sharp) = (0, 0);
    for l in &simp {
        let n = l.len();
        if n < 3 {
            continue;
        }
        for i in 0..n {
            let (a, b, c) = (l[(i + n - 1) % n], l[i], l[(i + 1) % n]);
            let (u, v) = (b - a, c - b);
            if u.length() == 0.0 || v.length() == 0.0 {
                continue;
            }
            // Turn angle: positive left (convex for the set on the left).
            let turn = u.perp_dot(v).atan2(u.dot(v)).to_degrees();
            if turn < -REFLEX_DEG {
                reflex += 1;
            } else if 180.0 - turn < SHARP_DEG {
                sharp += 1;
            }
        }
    }
    let mut width = f64::INFINITY;
    let n = outer.len();
    for i in 0..n {
        let e = outer[(i + 1) % n] - outer[i];
        if e.length() == 0.0 {
            continue;
        }
        let m = e.perp().normalize();
        let (lo, hi) =
            outer.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p.dot(m)), h.max(p.dot(m))));
        width = width.min(hi - lo);
    }
    if !width.is_finite() {
        width = 0.0;
    }
    Shape { loops: loops.len(), reflex, sharp, width, outer }
}

fn cost(s: &Shape, scale: f64) -> f64 {
    s.width / scale + W_REFLEX * s.reflex as f64 + W_SHARP * s.sharp as f64
}

/// Number of local maxima of x = p·m along a closed polygon, runs of equal x (within `tol`)
/// counted once. A simple polygon is monotone in x when it has one.
fn maxima(p: &[DVec2], m: DVec2, tol: f64) -> usize {
    let groups = groups(p, m, tol);
    let g = groups.len();
    if g < 3 {
        return 1;
    }
    (0..g).filter(|&i| groups[i].2 > groups[(i + g - 1) % g].2 && groups[i].2 > groups[(i + 1) % g].2).count()
}

/// Runs of consecutive vertices with equal x (within `tol`): (first, last, x), cyclic.
fn groups(p: &[DVec2], m: DVec2, tol: f64) -> Vec<(usize, usize, f64)> {
    let n = p.len();
    if n == 0 {
        return Vec::new();
    }
    let x: Vec<f64> = p.iter().map(|q| q.dot(m)).collect();
    // Start at a vertex that begins a run.
    let start = (0..n).find(|&i| (x[i] - x[(i + n - 1) % n]).abs() > tol).unwrap_or(0);
    let mut out: Vec<(usize, usize, f64)> = Vec::new();
    let mut k = 0;
    while k < n {
        let i = (start + k) % n;
        let mut j = k;
        while j + 1 < n && (x[(start + j + 1) % n] - x[i]).abs() <= tol {
            j += 1;
        }
        let last = (start + j) % n;
        let xm = (k..=j).map(|q| x[(start + q) % n]).sum::<f64>() / (j - k + 1) as f64;
        out.push((i, last, xm));
        k = j + 1;
    }
    out
}

/// A cut: a segment of the plane.
#[derive(Debug, Clone, Copy)]
struct Cut {
    a: DVec2,
    b: DVec2,
}

fn segments_cross(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> bool {
    let d1 = (q - p).perp_dot(a - p);
    let d2 = (q - p).perp_dot(b - p);
    let d3 = (b - a).perp_dot(p - a);
    let d4 = (b - a).perp_dot(q - a);
    (d1 > 0.0) != (d2 > 0.0) && (d3 > 0.0) != (d4 > 0.0)
}

/// The interval (of those given) nearest to parameter `s`.
fn nearest_interval(ivs: &[(f64, f64)], s: f64) -> Option<(f64, f64)> {
    let gap = |iv: &(f64, f64)| {
        if s < iv.0 {
            iv.0 - s
        } else if s > iv.1 {
            s - iv.1
        } else {
            0.0
        }
    };
    ivs.iter().copied().min_by(|a, b| gap(a).total_cmp(&gap(b)))
}

/// Cuts along `t`: through the reflex extrema of x of the simplified loops, from border to
/// border on the side the piece wraps round (boustrophedon critical points), and through every
/// other reflex corner, as far as the piece lies on both sides of the line (so that the cut
/// removes the corner).
fn cuts(frame: &Frame, loops: &[Vec<DVec2>], t: DVec2, tol: f64) -> Vec<Cut> {
    let m = t.perp();
    let eps = (1e-6 * frame.area2.abs().sqrt()).max(1e-9);
    let mut out = Vec::new();
    for lp in loops {
        let gs = groups(lp, m, tol);
        let g = gs.len();
        let n = lp.len();
        if g < 2 {
            continue;
        }
        let mut in_critical = vec![false; n];
        for i in 0..g {
            let (p, c, q) = (gs[(i + g - 1) % g], gs[i], gs[(i + 1) % g]);
            let is_min = p.2 > c.2 && q.2 > c.2;
            let is_max = p.2 < c.2 && q.2 < c.2;
            if !(is_min || is_max) {
                continue;
            }
            // Direction of travel along t at the extremum: from the vertex before the run to
            // the vertex after it.
            let s = (lp[(c.1 + 1) % n] - lp[(c.0 + n - 1) % n]).dot(t);
            let critical = (is_min && s < 0.0) || (is_max && s > 0.0);
            if !critical {
                continue;
            }
            let mut run = Vec::new();
            let mut k = c.0;
            loop {
                run.push(k);
                in_critical[k] = true;
                if k == c.1 {
                    break;
                }
                k = (k + 1) % n;
            }
            let xs = run.iter().map(|&k| lp[k].dot(m));
            let xc = if is_min {
                xs.fold(f64::INFINITY, f64::min) - eps
            } else {
                xs.fold(f64::NEG_INFINITY, f64::max) + eps
            };
            let mid = run.iter().map(|&k| lp[k].dot(t)).sum::<f64>() / run.len() as f64;
            if let Some((s0, s1)) = nearest_interval(&frame.line_intervals(t, xc), mid) {
                out.push(Cut { a: m * xc + t * s0, b: m * xc + t * s1 });
            }
        }
        for k in 0..n {
            if in_critical[k] {
                continue;
            }
            let (a, b, c) = (lp[(k + n - 1) % n], lp[k], lp[(k + 1) % n]);
            let (u, v) = (b - a, c - b);
            if u.length() == 0.0 || v.length() == 0.0 {
                continue;
            }
            if u.perp_dot(v).atan2(u.dot(v)).to_degrees() >= -REFLEX_DEG {
                continue;
            }
            let (x, s) = (b.dot(m), b.dot(t));
            let lo = nearest_interval(&frame.line_intervals(t, x - eps), s);
            let hi = nearest_interval(&frame.line_intervals(t, x + eps), s);
            if let (Some(l), Some(h)) = (lo, hi) {
                let (s0, s1) = (l.0.max(h.0), l.1.min(h.1));
                if s1 - s0 > tol {
                    out.push(Cut { a: m * x + t * s0, b: m * x + t * s1 });
                }
            }
        }
    }
    out
}

/// Splits a projectable piece into hole-free, nearly convex cells (see the module docs).
/// `scale` is the spray radius.
pub fn split(mesh: &Mesh, faces: &[u32], scale: f64) -> Vec<Vec<u32>> {
    if faces.len() < 2 || !(scale > 0.0) {
        return vec![faces.to_vec()];
    }
    let (normal, _) = mean_normal(mesh, faces);
    let set: HashSet<u32> = faces.iter().copied().collect();
    let frame = Frame::of_faces(mesh, faces, normal, &|g| set.contains(&g), &|_| u32::MAX, 0.0);
    let (eu, ev) = plane_axes(normal);
    let plane = Plane { origin: frame.origin, eu, ev };
    debug_assert!((plane.eu - frame.eu).length() < 1e-12);
    let tol = (scale / 4.0).max(0.005 * frame.area2.abs().sqrt());
    let whole = shape(mesh, faces, &plane, tol);
    if whole.loops == 1 && whole.reflex == 0 {
        return vec![faces.to_vec()];
    }
    let loops: Vec<Vec<DVec2>> = frame
        .loops
        .iter()
        .map(|lp| simplify_closed(&lp.iter().map(|&i| frame.border[i].a).collect::<Vec<_>>(), tol))
        .collect();
    let centroid: HashMap<u32, DVec2> = faces
        .iter()
        .map(|&f| {
            let c = mesh.corners(f);
            (f, plane.to2((c[0] + c[1] + c[2]) / 3.0))
        })
        .collect();
    let mut best: Option<(f64, Vec<Vec<u32>>)> =
        (whole.loops == 1).then(|| (cost(&whole, scale), vec![faces.to_vec()]));
    for t in directions(&frame, &loops, scale) {
        let cs = cuts(&frame, &loops, t, tol);
        if cs.is_empty() {
            continue;
        }
        let joined = |f: u32, g: u32| {
            let (p, q) = (centroid[&f], centroid[&g]);
            !cs.iter().any(|c| segments_cross(p, q, c.a, c.b))
        };
        let cells = components(mesh, faces, &joined);
        let (cells, total) = merge(mesh, cells, &plane, t.perp(), tol, scale);
        let shapes_ok = cells.iter().all(|c| shape(mesh, c, &plane, tol).loops == 1);
        if shapes_ok && best.as_ref().is_none_or(|b| total < b.0 - 1e-9) {
            best = Some((total, cells));
        }
    }
    best.map_or_else(|| vec![faces.to_vec()], |b| b.1)
}

/// Candidate directions of the passes: principal axes and long border segments.
fn directions(frame: &Frame, loops: &[Vec<DVec2>], scale: f64) -> Vec<DVec2> {
    let [xx, xy, yy] = frame.moments;
    let ang = 0.5 * (2.0 * xy).atan2(xx - yy);
    let major = DVec2::new(ang.cos(), ang.sin());
    let mut dirs = vec![major, major.perp()];
    let mut segs: Vec<(f64, DVec2)> = Vec::new();
    for l in loops {
        for i in 0..l.len() {
            let e = l[(i + 1) % l.len()] - l[i];
            if e.length() >= scale {
                segs.push((e.length(), e.normalize()));
            }
        }
    }
    segs.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, d) in segs.into_iter().take(8) {
        if dirs.iter().all(|e| e.dot(d).abs() < 2f64.to_radians().cos()) {
            dirs.push(d);
        }
    }
    dirs
}

/// Greedy merging of neighbouring cells while the union is hole-free, monotone across `m` and
/// cheaper; returns the cells and the total cost.
fn merge(mesh: &Mesh, mut cells: Vec<Vec<u32>>, plane: &Plane, m: DVec2, tol: f64, scale: f64) -> (Vec<Vec<u32>>, f64) {
    let mut shapes: Vec<Shape> = cells.iter().map(|c| shape(mesh, c, plane, tol)).collect();
    loop {
        let mut owner: HashMap<u32, usize> = HashMap::new();
        for (i, c) in cells.iter().enumerate() {
            for &f in c {
                owner.insert(f, i);
            }
        }
        // Shared border lengths between cells.
        let mut shared: HashMap<(usize, usize), f64> = HashMap::new();
        for (i, c) in cells.iter().enumerate() {
            for &f in c {
                let k3 = mesh.corners(f);
                for k in 0..3 {
                    let g = mesh.neighbor(f, k);
                    if g == NO_FACE {
                        continue;
                    }
                    if let Some(&j) = owner.get(&g) {
                        if j > i {
                            *shared.entry((i, j)).or_insert(0.0) += k3[k].distance(k3[(k + 1) % 3]);
                        }
                    }
                }
            }
        }
        let mut pairs: Vec<((usize, usize), f64)> = shared.into_iter().collect();
        pairs.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut best: Option<(f64, usize, usize, Shape)> = None;
        for ((i, j), len) in pairs {
            let union: Vec<u32> = cells[i].iter().chain(&cells[j]).copied().collect();
            let s = shape(mesh, &union, plane, tol);
            if s.loops != 1 || maxima(&s.outer, m, tol) != 1 {
                continue;
            }
            let delta = cost(&s, scale) - cost(&shapes[i], scale) - cost(&shapes[j], scale) - W_BORDER * len / scale;
            if delta < -1e-9 && best.as_ref().is_none_or(|b| delta < b.0) {
                best = Some((delta, i, j, s));
            }
        }
        let Some((_, i, j, s)) = best else { break };
        let moved = std::mem::take(&mut cells[j]);
        cells[i].extend(moved);
        cells[i].sort_unstable();
        shapes[i] = s;
        cells.remove(j);
        shapes.remove(j);
    }
    // Total: cells plus half a weight per radius of remaining common border.
    let mut owner: HashMap<u32, usize> = HashMap::new();
    for (i, c) in cells.iter().enumerate() {
        for &f in c {
            owner.insert(f, i);
        }
    }
    let mut border = 0.0;
    for (i, c) in cells.iter().enumerate() {
        for &f in c {
            let k3 = mesh.corners(f);
            for k in 0..3 {
                let g = mesh.neighbor(f, k);
                if g != NO_FACE && owner.get(&g).is_some_and(|&j| j > i) {
                    border += k3[k].distance(k3[(k + 1) % 3]);
                }
            }
        }
    }
    let total = shapes.iter().map(|s| cost(s, scale)).sum::<f64>() + W_BORDER * border / scale;
    (cells, total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monotone_polygons_have_one_maximum() {
        let square = [DVec2::new(0.0, 0.0), DVec2::new(4.0, 0.0), DVec2::new(4.0, 4.0), DVec2::new(0.0, 4.0)];
        assert_eq!(maxima(&square, DVec2::Y, 1e-9), 1);
        // A U shape opening upwards is not monotone in y (two tops), is in x.
        let u = [
            DVec2::new(0.0, 0.0),
            DVec2::new(6.0, 0.0),
            DVec2::new(6.0, 4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 2.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(2.0, 4.0),
            DVec2::new(0.0, 4.0),
        ];
        assert_eq!(maxima(&u, DVec2::Y, 1e-9), 2);
        assert_eq!(maxima(&u, DVec2::X, 1e-9), 1);
    }
}
