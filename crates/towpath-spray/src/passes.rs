//! Passes per patch (Tewolde & Sheng 2008 §III-B): zigzag passes along a sweep direction, or a
//! spiral of rings, at the spacing that minimises the thickness error, with gun poses at the
//! standoff along the surface normal.
//!
//! **Zigzag.** Candidate sweep directions are the patch's principal axes (of its projected
//! area) and the directions of its long border segments (the border simplified by
//! Douglas–Peucker); the one giving the fewest passes wins (fewest turns), then the shortest
//! spray length. Passes lie on the lines `p·m = x_min + (k + ½) d` of the projection plane (m
//! across the sweep), i.e. on the plane slices through the patch along the mean normal, the first
//! and last half a spacing inside the patch's extent, so that a patch continuing across a seam
//! continues the same lattice. On a line, a pass runs where the line is over the patch (split
//! where a hole or a notch interrupts it) and where it is within the run-out band of a free or
//! crease edge: passes run past such edges, and extra passes run outside them, so that the
//! edge gets the full thickness; at a seam they stop at the border, where the neighbour's
//! passes take over. With an optimised spacing, d is fitted so that a whole number of passes
//! fills the patch's width ([`spacing::fit`]).
//!
//! **Spiral.** Rings are the level lines `φ = (k + ½) d` of the distance φ to the patch border
//! (computed on a grid of d/6 in the projection plane; marching squares), plus level lines
//! `φ = −(k + ½) d` outside free and crease edges within their run-out band. Each ring is one
//! closed pass, started on the ray from the patch's centroid along the first plane axis so that
//! consecutive rings start close together.
//!
//! **Auto** plans both and keeps the spiral only when its estimated time (spray time plus
//! [`TURN_SECONDS`] for every pass end and every turn sharper than 45° inside a pass) is at least
//! 10 % below the zigzag's.

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::deposition::Gun;
use crate::frame::Frame;
use crate::spacing::{self, Side, SpacingChoice};

/// Time a pass end (stop, turn, restart) costs in the pattern choice of `auto` (s).
pub const TURN_SECONDS: f64 = 0.3;

/// Pass patterns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Pattern {
    /// Parallel straight passes (plane slices), sprayed back and forth.
    Zigzag,
    /// Concentric rings at constant distance from the border.
    Spiral,
    /// Plane slices through the whole part, no partition (the plain plane-slicer baseline).
    Slicer,
    /// No passes of its own: a sliver sprayed by its neighbours' run-outs.
    Absorbed,
}

impl std::fmt::Display for Pattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Pattern::Zigzag => "zigzag",
            Pattern::Spiral => "spiral",
            Pattern::Slicer => "slicer",
            Pattern::Absorbed => "absorbed",
        })
    }
}

/// Which pattern to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PatternChoice {
    /// Zigzag on every patch.
    Zigzag,
    /// Spiral on every patch.
    Spiral,
    /// Per patch, whichever is estimated faster (see the module docs).
    #[default]
    Auto,
    /// No partition: the whole part sliced by parallel planes (baseline for comparison).
    Slicer,
}

/// One pass: a polyline of gun poses sprayed at constant speed, in either direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pass {
    /// Index in the plan's pass list.
    pub id: u32,
    /// The patch it sprays.
    pub patch: u32,
    /// True for a closed ring (it ends where it starts).
    pub closed: bool,
    /// Gun positions.
    #[serde(skip)]
    pub positions: Vec<DVec3>,
    /// Gun axes (unit, towards the surface).
    #[serde(skip)]
    pub axes: Vec<DVec3>,
    /// The points aimed at: where the axis meets the surface (or its extension past an edge),
    /// one standoff from the gun.
    #[serde(skip)]
    pub targets: Vec<DVec3>,
    /// Length of the gun's path (mm).
    pub length: f64,
    /// Length of the aimed path on the surface (mm).
    pub target_length: f64,
    /// Speed of the aimed point along the surface (mm/s); the gun moves faster over convex
    /// surfaces, slower over concave ones.
    pub speed: f64,
    /// Direction changes sharper than 45° inside the pass.
    pub turns: usize,
}

/// How one patch is sprayed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatchPlan {
    /// The patch.
    pub patch: u32,
    /// The pattern used.
    pub pattern: Pattern,
    /// Sweep direction of a zigzag (unit, along the passes).
    pub direction: Option<DVec3>,
    /// Pass spacing (mm).
    pub spacing: f64,
    /// Gun speed on the passes (mm/s).
    pub speed: f64,
    /// Ripple of an endless raster at this spacing (relative RMS).
    pub ripple: f64,
    /// The passes.
    pub passes: Vec<u32>,
    /// Estimated spray time plus turns of the pattern used, and of the other one when `auto`
    /// compared them (s).
    pub estimate_s: f64,
    /// The other pattern's estimate, when both were planned.
    pub other_estimate_s: Option<f64>,
}

/// What pass planning needs to know.
#[derive(Debug, Clone, Copy)]
pub struct PassParams {
    /// The gun.
    pub gun: Gun,
    /// Target mean thickness (µm).
    pub target: f64,
    /// Fixed spacing, or `None` to optimise.
    pub spacing: Option<f64>,
    /// Fixed speed, or `None` to derive it from the target.
    pub speed: Option<f64>,
    /// Optimal spacing of the profile.
    pub optimum: SpacingChoice,
}

impl PassParams {
    fn step(&self) -> f64 {
        self.gun.radius / 4.0
    }
    fn speed_at(&self, spacing: f64) -> f64 {
        self.speed.unwrap_or_else(|| self.gun.speed_for(self.target, spacing))
    }
}

/// A pass before it gets its id and patch.
#[derive(Debug, Clone)]
pub(crate) struct Geom {
    pub positions: Vec<DVec3>,
    pub axes: Vec<DVec3>,
    pub targets: Vec<DVec3>,
    pub closed: bool,
}

impl Geom {
    fn length(&self) -> f64 {
        self.positions.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
    fn target_length(&self) -> f64 {
        self.targets.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
    fn turns(&self) -> usize {
        let p = &self.positions;
        let mut n = 0;
        for i in 1..p.len().saturating_sub(1) {
            let (a, b) = (p[i] - p[i - 1], p[i + 1] - p[i]);
            if a.length() > 0.0
                && b.length() > 0.0
                && a.normalize().dot(b.normalize()) < std::f64::consts::FRAC_1_SQRT_2
            {
                n += 1;
            }
        }
        n
    }
}

/// A planned pattern for a patch.
pub(crate) struct Planned {
    pub pattern: Pattern,
    pub direction: Option<DVec3>,
    pub spacing: f64,
    pub speed: f64,
    pub geoms: Vec<Geom>,
}

impl Planned {
    /// A plan with no passes.
    pub fn empty() -> Planned {
        Planned { pattern: Pattern::Zigzag, direction: None, spacing: 0.0, speed: 0.0, geoms: Vec::new() }
    }

    /// Spray time plus [`TURN_SECONDS`] per pass end and inner turn.
    pub fn estimate(&self) -> f64 {
        let len: f64 = self.geoms.iter().map(Geom::target_length).sum();
        let turns: usize = self.geoms.iter().map(|g| 1 + g.turns()).sum();
        if self.geoms.is_empty() {
            return 0.0;
        }
        len / self.speed + turns as f64 * TURN_SECONDS
    }
}

/// Gun poses over plane points: at the standoff along the surface normal.
fn poses(frame: &Frame, pts: &[DVec2], h: f64, closed: bool) -> Geom {
    let mut positions = Vec::with_capacity(pts.len());
    let mut axes = Vec::with_capacity(pts.len());
    let mut targets = Vec::with_capacity(pts.len());
    for &q in pts {
        let (p, n, _) = frame.lift(q);
        positions.push(p + n * h);
        axes.push(-n);
        targets.push(p);
    }
    Geom { positions, axes, targets, closed }
}

/// Points every `step` or less from a to b, both included.
fn sample_segment(a: DVec2, b: DVec2, step: f64) -> Vec<DVec2> {
    let n = ((a.distance(b) / step).ceil() as usize).max(1);
    (0..=n).map(|i| a.lerp(b, i as f64 / n as f64)).collect()
}

/// Zigzag lines of a direction: (offset, intervals) per line with anything on it.
struct Lines {
    dir: DVec2,
    spacing: f64,
    lines: Vec<(f64, Vec<(f64, f64)>)>,
}

impl Lines {
    fn count(&self) -> usize {
        self.lines.iter().map(|l| l.1.len()).sum()
    }
    fn length(&self) -> f64 {
        self.lines.iter().flat_map(|l| l.1.iter()).map(|iv| iv.1 - iv.0).sum()
    }
}

/// The zigzag lines of a direction. With `optimise`, an unset spacing is searched for this
/// patch ([`spacing::zigzag_layout`]); without, the profile's optimum is used (fitted to a whole
/// number of passes between two seams), which is enough to compare directions.
fn lines_for(frame: &Frame, dir: DVec2, params: &PassParams, optimise: bool) -> Lines {
    let m = dir.perp();
    let (lo, hi) = frame.extent(m);
    let g = &params.gun;
    let d0 = params.optimum.spacing;
    let e = frame.max_ext();
    // Spacing is measured on the surface: along the line across the passes through the
    // centroid, offsets map to arc length.
    let arc = ArcMap::new(frame, m, dir.dot(frame.centroid) * dir, lo - e - 2.0 * d0, hi + e + 2.0 * d0);
    let (slo, shi) = (arc.s(lo), arc.s(hi));
    let width = shi - slo;
    let side = |seam: bool| if seam { Side::Seam } else { Side::Free };
    let sides = (side(seam_side(frame, m, lo, d0)), side(seam_side(frame, m, hi, d0)));
    let fixed = match (params.spacing, optimise) {
        (Some(d), _) => Some(d),
        (None, true) => None,
        (None, false) if sides == (Side::Seam, Side::Seam) => Some(spacing::fit(&g.profile, g.radius, width, d0).1),
        (None, false) => Some(d0),
    };
    let layout = spacing::zigzag_layout(&g.profile, g.radius, width, sides, e, d0, fixed);
    let min_len = 1e-3 * g.radius;
    let mut lines = Vec::new();
    for &x in &layout.passes {
        let c = arc.x(slo + x);
        let ivs: Vec<(f64, f64)> =
            frame.line_intervals(dir, c).into_iter().filter(|iv| iv.1 - iv.0 > min_len).collect();
        if !ivs.is_empty() {
            lines.push((c, ivs));
        }
    }
    Lines { dir, spacing: layout.spacing, lines }
}

/// Arc length on the surface along a line of the projection plane, as a function of the
/// plane coordinate: piecewise linear through lifted samples.
struct ArcMap {
    xs: Vec<f64>,
    ss: Vec<f64>,
}

impl ArcMap {
    /// Samples the line `base + x·m` for x from `x0` to `x1`.
    fn new(frame: &Frame, m: DVec2, base: DVec2, x0: f64, x1: f64) -> ArcMap {
        let n = 256;
        let xs: Vec<f64> = (0..=n).map(|i| x0 + (x1 - x0) * i as f64 / n as f64).collect();
        let pts: Vec<DVec3> = xs.iter().map(|&x| frame.lift(base + m * x).0).collect();
        let mut ss = vec![x0];
        for i in 1..pts.len() {
            // Never shorter than the projection (keeps the map strictly increasing).
            let step = pts[i].distance(pts[i - 1]).max(xs[i] - xs[i - 1]);
            ss.push(ss[i - 1] + step);
        }
        ArcMap { xs, ss }
    }
    fn interp(from: &[f64], to: &[f64], v: f64) -> f64 {
        let n = from.len();
        if v <= from[0] {
            return to[0] + (v - from[0]);
        }
        if v >= from[n - 1] {
            return to[n - 1] + (v - from[n - 1]);
        }
        let k = from.partition_point(|&a| a <= v).clamp(1, n - 1);
        let (a, b) = (from[k - 1], from[k]);
        to[k - 1] + (to[k] - to[k - 1]) * (v - a) / (b - a)
    }
    /// Arc length at plane coordinate x.
    fn s(&self, x: f64) -> f64 {
        Self::interp(&self.xs, &self.ss, x)
    }
    /// Plane coordinate at arc length s.
    fn x(&self, s: f64) -> f64 {
        Self::interp(&self.ss, &self.xs, s)
    }
}

/// Whether the border near the extreme `x` (along plane direction `m`, within one spacing) is
/// mostly seam, by length.
fn seam_side(frame: &Frame, m: DVec2, x: f64, d: f64) -> bool {
    let (mut seam, mut other) = (0.0, 0.0);
    for e in &frame.border {
        let (xa, xb) = (e.a.dot(m), e.b.dot(m));
        if (xa - x).abs() <= d && (xb - x).abs() <= d {
            let l = e.a.distance(e.b);
            if e.kind == crate::frame::EdgeKind::Seam {
                seam += l;
            } else {
                other += l;
            }
        }
    }
    seam > other
}

/// Candidate sweep directions: principal axes, then long border directions.
fn directions(frame: &Frame, scale: f64) -> Vec<DVec2> {
    let [xx, xy, yy] = frame.moments;
    let ang = 0.5 * (2.0 * xy).atan2(xx - yy);
    let major = DVec2::new(ang.cos(), ang.sin());
    let mut dirs = vec![major, major.perp()];
    let tol = (0.02 * frame.area2.abs().sqrt()).max(scale / 8.0);
    let mut segs: Vec<(f64, DVec2)> = Vec::new();
    for lp in &frame.loops {
        let pts: Vec<DVec2> = lp.iter().map(|&i| frame.border[i].a).collect();
        let simp = simplify_closed(&pts, tol);
        for i in 0..simp.len() {
            let (a, b) = (simp[i], simp[(i + 1) % simp.len()]);
            let l = a.distance(b);
            if l >= scale {
                segs.push((l, (b - a) / l));
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

/// Douglas–Peucker simplification of a closed polyline (kept vertices in order).
pub(crate) fn simplify_closed(pts: &[DVec2], tol: f64) -> Vec<DVec2> {
    let n = pts.len();
    if n < 4 {
        return pts.to_vec();
    }
    // Split at the vertex farthest from vertex 0.
    let far = (1..n).max_by(|&a, &b| pts[a].distance(pts[0]).total_cmp(&pts[b].distance(pts[0]))).unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    fn dp(pts: &[DVec2], idx: &[usize], tol: f64, keep: &mut [bool]) {
        if idx.len() < 3 {
            return;
        }
        let (a, b) = (pts[idx[0]], pts[idx[idx.len() - 1]]);
        let ab = b - a;
        let mut best = (0.0, 0);
        for (k, &i) in idx.iter().enumerate().take(idx.len() - 1).skip(1) {
            let d = if ab.length() > 0.0 { (pts[i] - a).perp_dot(ab).abs() / ab.length() } else { pts[i].distance(a) };
            if d > best.0 {
                best = (d, k);
            }
        }
        if best.0 > tol {
            keep[idx[best.1]] = true;
            dp(pts, &idx[..=best.1], tol, keep);
            dp(pts, &idx[best.1..], tol, keep);
        }
    }
    let first: Vec<usize> = (0..=far).collect();
    let second: Vec<usize> = (far..n).chain(std::iter::once(0)).collect();
    dp(pts, &first, tol, &mut keep);
    dp(pts, &second, tol, &mut keep);
    (0..n).filter(|&i| keep[i]).map(|i| pts[i]).collect()
}

/// Zigzag passes of a patch.
pub(crate) fn zigzag(frame: &Frame, params: &PassParams) -> Option<Planned> {
    let mut best: Option<Lines> = None;
    for dir in directions(frame, params.gun.radius) {
        let l = lines_for(frame, dir, params, false);
        let better = match &best {
            None => true,
            Some(b) => l.count() < b.count() || (l.count() == b.count() && l.length() < b.length() - 1e-9),
        };
        if better && l.count() > 0 {
            best = Some(l);
        }
    }
    let mut lines = best?;
    if params.spacing.is_none() {
        let tuned = lines_for(frame, lines.dir, params, true);
        if tuned.count() > 0 {
            lines = tuned;
        }
    }
    let h = params.gun.standoff;
    let step = params.step();
    let m = lines.dir.perp();
    let mut geoms = Vec::new();
    for (c, ivs) in &lines.lines {
        for &(s0, s1) in ivs {
            let a = m * *c + lines.dir * s0;
            let b = m * *c + lines.dir * s1;
            geoms.push(poses(frame, &sample_segment(a, b, step), h, false));
        }
    }
    Some(Planned {
        pattern: Pattern::Zigzag,
        direction: Some(frame.dir3(lines.dir)),
        spacing: lines.spacing,
        speed: params.speed_at(lines.spacing),
        geoms,
    })
}

/// Most grid nodes of a spiral's distance field.
const SPIRAL_NODES: f64 = 250_000.0;
/// Value of the distance field where no ring may pass.
const NO_RING: f64 = -1e300;

/// Spiral rings of a patch.
pub(crate) fn spiral(frame: &Frame, params: &PassParams) -> Option<Planned> {
    let e = frame.max_ext();
    let (ulo, uhi) = frame.extent(DVec2::X);
    let (vlo, vhi) = frame.extent(DVec2::Y);
    let (ulo, uhi, vlo, vhi) = (ulo - e, uhi + e, vlo - e, vhi + e);
    let d0 = params.spacing.unwrap_or(params.optimum.spacing);
    let mut g = d0 / 6.0;
    while ((uhi - ulo) / g + 2.0) * ((vhi - vlo) / g + 2.0) > SPIRAL_NODES {
        g *= 1.2;
    }
    let nx = ((uhi - ulo) / g).ceil() as usize + 1;
    let ny = ((vhi - vlo) / g).ceil() as usize + 1;
    let node = |i: usize, j: usize| DVec2::new(ulo + i as f64 * g, vlo + j as f64 * g);
    let mut phi = vec![NO_RING; nx * ny];
    let mut inner_max = 0.0f64;
    for j in 0..ny {
        for i in 0..nx {
            let q = node(i, j);
            let Some((dist, edge)) = frame.border_distance(q) else { continue };
            phi[j * nx + i] = if frame.covers(q) {
                inner_max = inner_max.max(dist);
                dist
            } else if frame.border[edge].ext > 0.0 && dist <= frame.border[edge].ext {
                -dist
            } else {
                NO_RING
            };
        }
    }
    if !(inner_max > 0.0) {
        return None;
    }
    let d = match params.spacing {
        Some(d) => d,
        None => spacing::spiral_spacing(&params.gun.profile, params.gun.radius, inner_max, e, d0).0,
    };
    let mut levels = Vec::new();
    let mut k = 0;
    while (k as f64 + 0.5) * d < inner_max {
        levels.push((k as f64 + 0.5) * d);
        k += 1;
    }
    let mut k = 0;
    while (k as f64 + 0.5) * d < e {
        levels.push(-(k as f64 + 0.5) * d);
        k += 1;
    }
    let h = params.gun.standoff;
    let step = params.step();
    let mut geoms = Vec::new();
    for lev in levels {
        for (mut line, closed) in contour(&phi, nx, ny, lev) {
            for q in &mut line {
                *q = DVec2::new(ulo + q.x * g, vlo + q.y * g);
            }
            if closed {
                // Start on the ray from the centroid along +u.
                let start = (0..line.len())
                    .min_by(|&a, &b| ray_key(line[a], frame.centroid).total_cmp(&ray_key(line[b], frame.centroid)))
                    .unwrap_or(0);
                line.rotate_left(start);
                line.push(line[0]);
            }
            let pts = resample(&line, step);
            if pts.len() >= 2 {
                geoms.push(poses(frame, &pts, h, closed));
            }
        }
    }
    if geoms.is_empty() {
        return None;
    }
    Some(Planned { pattern: Pattern::Spiral, direction: None, spacing: d, speed: params.speed_at(d), geoms })
}

/// Sort key that is smallest for points on the ray from `c` along +u.
fn ray_key(p: DVec2, c: DVec2) -> f64 {
    let v = p - c;
    let a = v.y.atan2(v.x).abs();
    a + if v.x > 0.0 { 0.0 } else { 10.0 }
}

/// A polyline resampled so that no step exceeds `step` (original vertices kept).
fn resample(pts: &[DVec2], step: f64) -> Vec<DVec2> {
    let mut out = Vec::new();
    for w in pts.windows(2) {
        let s = sample_segment(w[0], w[1], step);
        if out.is_empty() {
            out.extend(s);
        } else {
            out.extend(s.into_iter().skip(1));
        }
    }
    out
}

/// Marching squares: the level lines `f = level` of a grid (node (i, j) at `f[j*nx + i]`), in
/// grid units, as polylines with a flag for closed ones. Cells touching a [`NO_RING`] node
/// have no line.
fn contour(f: &[f64], nx: usize, ny: usize, level: f64) -> Vec<(Vec<DVec2>, bool)> {
    // Edge keys: horizontal edge from (i, j) to (i+1, j) is 2(j nx + i); vertical from (i, j) to
    // (i, j+1) is 2(j nx + i) + 1.
    let val = |i: usize, j: usize| f[j * nx + i];
    let point = |key: usize| -> DVec2 {
        let base = key / 2;
        let (i, j) = (base % nx, base / nx);
        let (a, b, pa, pb) = if key % 2 == 0 {
            (val(i, j), val(i + 1, j), DVec2::new(i as f64, j as f64), DVec2::new(i as f64 + 1.0, j as f64))
        } else {
            (val(i, j), val(i, j + 1), DVec2::new(i as f64, j as f64), DVec2::new(i as f64, j as f64 + 1.0))
        };
        let t = ((level - a) / (b - a)).clamp(0.0, 1.0);
        pa.lerp(pb, t)
    };
    let mut segs: Vec<[usize; 2]> = Vec::new();
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx.saturating_sub(1) {
            let v = [val(i, j), val(i + 1, j), val(i + 1, j + 1), val(i, j + 1)];
            if v.iter().any(|&x| x <= NO_RING) {
                continue;
            }
            let code = (v[0] >= level) as u8
                | ((v[1] >= level) as u8) << 1
                | ((v[2] >= level) as u8) << 2
                | ((v[3] >= level) as u8) << 3;
            let bottom = 2 * (j * nx + i);
            let right = 2 * (j * nx + i + 1) + 1;
            let top = 2 * ((j + 1) * nx + i);
            let left = 2 * (j * nx + i) + 1;
            let centre_in = (v.iter().sum::<f64>() / 4.0) >= level;
            match code {
                0 | 15 => {}
                1 | 14 => segs.push([left, bottom]),
                2 | 13 => segs.push([bottom, right]),
                3 | 12 => segs.push([left, right]),
                4 | 11 => segs.push([right, top]),
                6 | 9 => segs.push([bottom, top]),
                7 | 8 => segs.push([left, top]),
                5 => {
                    if centre_in {
                        segs.push([left, top]);
                        segs.push([bottom, right]);
                    } else {
                        segs.push([left, bottom]);
                        segs.push([right, top]);
                    }
                }
                10 => {
                    if centre_in {
                        segs.push([left, bottom]);
                        segs.push([right, top]);
                    } else {
                        segs.push([left, top]);
                        segs.push([bottom, right]);
                    }
                }
                _ => {}
            }
        }
    }
    // Chain segments through shared edge keys.
    let mut at: HashMap<usize, Vec<usize>> = HashMap::new();
    for (s, k) in segs.iter().enumerate() {
        at.entry(k[0]).or_default().push(s);
        at.entry(k[1]).or_default().push(s);
    }
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    let other = |s: usize, k: usize| if segs[s][0] == k { segs[s][1] } else { segs[s][0] };
    // Open chains first (start at keys with one segment), then closed loops.
    let mut starts: Vec<usize> = at.iter().filter(|(_, v)| v.len() == 1).map(|(&k, _)| k).collect();
    starts.sort_unstable();
    let mut all_keys: Vec<usize> = at.keys().copied().collect();
    all_keys.sort_unstable();
    for pass in 0..2 {
        let keys = if pass == 0 { &starts } else { &all_keys };
        for &k0 in keys {
            let Some(&s0) = at[&k0].iter().find(|&&s| !used[s]) else { continue };
            let mut keys_chain = vec![k0];
            let mut s = s0;
            let mut k = k0;
            loop {
                used[s] = true;
                let k2 = other(s, k);
                keys_chain.push(k2);
                k = k2;
                match at[&k].iter().find(|&&t| !used[t]) {
                    Some(&t) => s = t,
                    None => break,
                }
            }
            let closed = pass == 1 && keys_chain.first() == keys_chain.last();
            if closed {
                keys_chain.pop();
            }
            out.push((keys_chain.into_iter().map(point).collect(), closed));
        }
    }
    out
}

/// Ids, patches and lengths for a patch's planned passes.
pub(crate) fn finish(planned: &Planned, patch: u32, first_id: u32) -> Vec<Pass> {
    planned
        .geoms
        .iter()
        .enumerate()
        .map(|(i, g)| Pass {
            id: first_id + i as u32,
            patch,
            closed: g.closed,
            length: g.length(),
            target_length: g.target_length(),
            speed: planned.speed,
            turns: g.turns(),
            positions: g.positions.clone(),
            axes: g.axes.clone(),
            targets: g.targets.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marching_squares_rings_a_cone() {
        // f = 10 - distance from the centre of a 21 × 21 grid: the level 4 line is a circle of
        // radius 6 grid units around (10, 10).
        let n = 21;
        let f: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64, (k / n) as f64);
                10.0 - ((i - 10.0).powi(2) + (j - 10.0).powi(2)).sqrt()
            })
            .collect();
        let lines = contour(&f, n, n, 4.0);
        assert_eq!(lines.len(), 1);
        assert!(lines[0].1, "closed");
        for p in &lines[0].0 {
            let r = p.distance(DVec2::new(10.0, 10.0));
            assert!((r - 6.0).abs() < 0.1, "{r}");
        }
    }

    #[test]
    fn simplify_keeps_the_corners_of_a_noisy_square() {
        let mut pts = Vec::new();
        for i in 0..40 {
            let t = i as f64 / 10.0;
            let p = match i / 10 {
                0 => DVec2::new(t * 10.0, 0.0),
                1 => DVec2::new(10.0, (t - 1.0) * 10.0),
                2 => DVec2::new(10.0 - (t - 2.0) * 10.0, 10.0),
                _ => DVec2::new(0.0, 10.0 - (t - 3.0) * 10.0),
            };
            pts.push(p + DVec2::new(0.01 * ((i * 7) % 3) as f64, 0.0));
        }
        let s = simplify_closed(&pts, 0.1);
        assert_eq!(s.len(), 4, "{s:?}");
    }
}
