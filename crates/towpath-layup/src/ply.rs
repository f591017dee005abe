//! Covering a ply with courses (seed 002 §3–4): a reference course through the start point, then
//! parallel courses offset by one course width measured on the surface, on both sides, until the
//! ply is covered; every course trimmed per tow at the ply boundary.

use std::time::Instant;

use rayon::prelude::*;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use towpath_geom::Mesh;

use crate::boundary::Region;
use crate::course::Course;
use crate::field::DirectionField;
use crate::laid::LaidMap;
use crate::quality::{self, PlyQuality};
use crate::section::{Band, Coverage, Sectioner};
use crate::trace::{reverse_walk, tangent, transport, walk, Located, PathPoint, Steering, Stop, WalkOptions};
use towpath_geom::NO_FACE;

/// How courses follow the design.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Every course follows the design direction (fixed angle, guide curves or orientation
    /// samples): the fiber angle is exact, the spacing between courses varies (gaps/overlaps).
    Field,
    /// The reference course is a geodesic from the start point in the design direction; every
    /// other course is its geodesic parallel one course width away (seed 002's equidistant
    /// method): no gaps or overlaps, the fiber angle drifts and courses may need steering.
    Parallel,
    /// Every course is a geodesic (a natural path: no steering at all), started on the seed curve
    /// in the design direction there: the angle holds at the seeds, gaps/overlaps elsewhere.
    Natural,
}

/// What to generate.
#[derive(Debug, Clone)]
pub struct PlySpec {
    /// Tow width (mm).
    pub tow_width: f64,
    /// Tows per course.
    pub tows: usize,
    /// Course method.
    pub method: Method,
    /// Coverage rule at the boundary.
    pub coverage: Coverage,
    /// Minimum steering radius for quality flags (mm).
    pub min_steering_radius: f64,
    /// Start point of the reference course (projected onto the mesh); `None`: the point of the ply
    /// nearest its centroid.
    pub start: Option<DVec3>,
    /// Most courses to lay: a ply that needs more is refused ([`PlyError::TooManyCourses`]).
    pub max_courses: usize,
    /// Spacing of trimming stations along a course (mm).
    pub station_step: f64,
    /// Stop with [`PlyError::TimeLimit`] after this instant.
    pub deadline: Option<Instant>,
}

impl PlySpec {
    /// Defaults for a band of `tows` tows of width `tow_width`: field method, 50 % coverage,
    /// minimum steering radius 100 tow widths (635 mm for 6.35 mm tows).
    pub fn new(tow_width: f64, tows: usize) -> PlySpec {
        PlySpec {
            tow_width,
            tows,
            method: Method::Field,
            coverage: Coverage::Half,
            min_steering_radius: 100.0 * tow_width,
            start: None,
            max_courses: 10_000,
            station_step: tow_width.min(5.0),
            deadline: None,
        }
    }
    fn band(&self) -> Band {
        Band { tow_width: self.tow_width, tows: self.tows }
    }
}

/// A planned ply.
#[derive(Debug, Clone, Serialize)]
pub struct Ply {
    /// Courses from right to left (looking along the fiber, normal up).
    pub courses: Vec<Course>,
    /// Courses generated to the left (+) of the reference course (seed 002's N₁).
    pub n1: usize,
    /// Courses generated to the right (−) of the reference course (N₂).
    pub n2: usize,
    /// Seed 002 eq. 9 estimate ⌈max section length / course width⌉ on each side (left, right),
    /// from sections across the reference course.
    pub n_estimate: [usize; 2],
    /// The ply's width across the fibers at the reference course (mm): the longest section on
    /// the left plus the longest on the right.
    pub section_width: f64,
    /// Whether the surface closed on itself across the fibers (a ply round a tube): the
    /// sections on both sides then run round the same surface.
    pub wraps: bool,
    /// Quality figures.
    pub quality: PlyQuality,
    /// Time spent planning (s).
    pub seconds: f64,
    /// Where the time went (s): centreline tracing, trimming, quality.
    pub timings: Timings,
}

/// Time per phase of [`plan`], seconds.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Timings {
    /// Tracing and offsetting centrelines.
    pub courses: f64,
    /// Per-tow trimming.
    pub trim: f64,
    /// Quality figures.
    pub quality: f64,
}

/// Errors of ply planning.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlyError {
    /// Tow width or count not positive.
    #[error("tow width must be positive and the tow count between 1 and 64 (got {0} mm × {1})")]
    BadBand(f64, usize),
    /// The design direction is undefined at the start.
    #[error("the design direction is undefined at the start point {0:?} (reference axis along the surface normal?)")]
    NoDirection([f64; 3]),
    /// The start point is outside the ply.
    #[error("the start point {0:?} lies outside the ply boundary")]
    StartOutside([f64; 3]),
    /// Nothing to start from.
    #[error("the mesh is empty")]
    Empty,
    /// Covering the ply would take more courses than the limit.
    #[error("the ply needs more than {0} courses; use wider tows or more tows per course, or a smaller ply")]
    TooManyCourses(usize),
    /// The deadline passed before the ply was planned.
    #[error("the time limit was reached while planning the ply ({courses} courses traced); nothing was written")]
    TimeLimit {
        /// Courses traced (or trimmed) by then.
        courses: usize,
    },
}

/// The outcome of looking for the next course on one side.
enum Next {
    /// A new centreline.
    Course(Vec<PathPoint>),
    /// No room: every candidate lands on courses already laid (the surface closes on itself).
    Blocked,
    /// No more ply on this side.
    End,
}

/// Progress report: courses generated so far.
pub type Progress<'a> = &'a mut dyn FnMut(usize);

struct Planner<'a> {
    mesh: &'a Mesh,
    field: &'a dyn DirectionField,
    region: &'a Region,
    spec: &'a PlySpec,
    /// Course centreline points laid so far (for wrap-around detection): a coarse grid.
    /// Each point with the lateral index of its course (0 the reference, +k / −k the k-th course
    /// to the left / right).
    grid: std::collections::HashMap<[i64; 3], Vec<(DVec3, i32)>>,
    max_len: f64,
}

/// Plans a ply: reference course, offsets on both sides, trimming, quality.
///
/// Refused when the band is not a band, the mesh is empty, the start is outside the ply or has
/// no design direction; stopped with [`PlyError::TooManyCourses`] when covering the ply would
/// take more than `spec.max_courses` courses and with [`PlyError::TimeLimit`] at
/// `spec.deadline` (never a partial ply presented as a whole one).
pub fn plan(
    mesh: &Mesh,
    field: &dyn DirectionField,
    region: &Region,
    spec: &PlySpec,
    progress: Progress<'_>,
) -> Result<Ply, PlyError> {
    let t0 = Instant::now();
    if !(spec.tow_width > 0.0 && spec.tow_width.is_finite()) || spec.tows == 0 || spec.tows > 64 {
        return Err(PlyError::BadBand(spec.tow_width, spec.tows));
    }
    if mesh.num_faces() == 0 {
        return Err(PlyError::Empty);
    }
    let mut timings = Timings::default();
    let tp = Instant::now();
    let (lo, hi) = mesh.bounds();
    let diag = (hi - lo).length();
    let mut pl = Planner { mesh, field, region, spec, grid: Default::default(), max_len: 3.0 * diag };
    let traced = pl.centrelines(progress)?;
    timings.courses = tp.elapsed().as_secs_f64();
    let tp = Instant::now();
    let (courses, n1, n2) = pl.trim_all(traced.lines, traced.closing, traced.n1, traced.n2)?;
    timings.trim = tp.elapsed().as_secs_f64();
    let tp = Instant::now();
    let quality = quality::assess(mesh, field, region, spec, &courses);
    check_time(spec, courses.len())?;
    timings.quality = tp.elapsed().as_secs_f64();
    Ok(Ply {
        courses,
        n1,
        n2,
        n_estimate: traced.n_estimate,
        section_width: traced.section_width,
        wraps: traced.wraps,
        quality,
        seconds: t0.elapsed().as_secs_f64(),
        timings,
    })
}

/// Fails with [`PlyError::TimeLimit`] once the spec's deadline has passed.
fn check_time(spec: &PlySpec, courses: usize) -> Result<(), PlyError> {
    match spec.deadline {
        Some(d) if Instant::now() >= d => Err(PlyError::TimeLimit { courses }),
        _ => Ok(()),
    }
}

/// Centrelines of a ply before trimming, in lateral order (rightmost first): (side, rank on the
/// side, points); the closing course of a closed surface apart.
struct Traced {
    lines: Vec<(i8, usize, Vec<PathPoint>)>,
    closing: Option<(i8, Vec<PathPoint>)>,
    n1: usize,
    n2: usize,
    n_estimate: [usize; 2],
    section_width: f64,
    wraps: bool,
}

/// A centreline before trimming: (side, rank on the side, points, whether each is on the mesh).
type Line = (i8, usize, Vec<PathPoint>, Vec<bool>);

/// The mesh (or ply) point nearest the area centroid.
fn default_start(mesh: &Mesh, region: &Region) -> DVec3 {
    if region.has_curve() {
        let c = region.curve_points.iter().copied().sum::<DVec3>() / region.curve_points.len().max(1) as f64;
        return c;
    }
    let mut acc = DVec3::ZERO;
    let mut area = 0.0;
    for f in 0..mesh.num_faces() as u32 {
        let c = mesh.corners(f);
        let a = mesh.face_area(f);
        acc += (c[0] + c[1] + c[2]) / 3.0 * a;
        area += a;
    }
    acc / area.max(1e-300)
}

impl Planner<'_> {
    /// The reference course through the start, then offsets on both sides until the ply is
    /// covered (or the surface closes on itself: then the closing course).
    fn centrelines(&mut self, progress: Progress<'_>) -> Result<Traced, PlyError> {
        let (mesh, region, spec, field) = (self.mesh, self.region, self.spec, self.field);
        let start_pt = spec.start.unwrap_or_else(|| default_start(mesh, region));
        let sp = mesh.closest_point(start_pt).ok_or(PlyError::Empty)?;
        let start = Located::new(mesh, sp);
        if region.has_curve() && region.curve_distance(start.p, start.n) < 0.0 {
            return Err(PlyError::StartOutside(start.p.to_array()));
        }
        let d0 = field.direction(start.p, start.n).ok_or(PlyError::NoDirection(start.p.to_array()))?;
        let steer = match spec.method {
            Method::Field => Steering::Field(field),
            Method::Parallel | Method::Natural => Steering::Geodesic,
        };
        let reference = self.trace(start, d0, steer);
        self.remember(&reference, 0);
        let mut done = 1usize;
        progress(done);
        let (n_estimate, section_width) = self.estimate(&reference);
        let mut sides: [Vec<Vec<PathPoint>>; 2] = [Vec::new(), Vec::new()];
        // Whether a side stopped because its next course would land on a course laid more than
        // two courses away from it: the surface closes on itself across the fibers (a helical
        // ply on a tube).
        let mut blocked = false;
        for (si, sign) in [(0usize, 1.0f64), (1, -1.0)] {
            let mut prev = reference.clone();
            let mut prev_index = 0i32;
            loop {
                check_time(spec, done)?;
                let next = match self.next_course(&prev, prev_index, sign, steer, false) {
                    Next::Course(c) => c,
                    Next::Blocked => {
                        blocked = true;
                        break;
                    }
                    Next::End => break,
                };
                if done >= spec.max_courses {
                    return Err(PlyError::TooManyCourses(spec.max_courses));
                }
                prev_index += sign as i32;
                self.remember(&next, prev_index);
                done += 1;
                progress(done);
                sides[si].push(next.clone());
                prev = next;
            }
        }
        // On a closed surface the courses leave a strip narrower than a course where the last
        // course meets the first. One closing course is laid over it, right of the rightmost
        // course (else left of the leftmost), with its tows trimmed against the courses already
        // laid under the coverage rule, as at the ply boundary.
        let mut closing: Option<(i8, Vec<PathPoint>)> = None;
        if blocked {
            if done >= spec.max_courses {
                return Err(PlyError::TooManyCourses(spec.max_courses));
            }
            for (si, sign) in [(1usize, -1.0f64), (0, 1.0)] {
                let prev = sides[si].last().unwrap_or(&reference);
                let prev_index = sign as i32 * sides[si].len() as i32;
                if let Next::Course(c) = self.next_course(prev, prev_index, sign, steer, true) {
                    closing = Some((sign as i8, c));
                    break;
                }
            }
        }
        let [left, right] = sides;
        let (n1, n2) = (left.len(), right.len());
        // Lateral order: rightmost first.
        let mut lines: Vec<(i8, usize, Vec<PathPoint>)> = Vec::new();
        for (i, c) in right.into_iter().enumerate().rev() {
            lines.push((-1, i + 1, c));
        }
        lines.push((0, 0, reference));
        for (i, c) in left.into_iter().enumerate() {
            lines.push((1, i + 1, c));
        }
        Ok(Traced { lines, closing, n1, n2, n_estimate, section_width, wraps: blocked })
    }

    /// Run-outs, per-tow trimming and cropping of every centreline (independently, in
    /// parallel; the result does not depend on threads), then the closing course trimmed
    /// against the courses laid. Returns the courses with laid tows and the updated N₁, N₂.
    fn trim_all(
        &self,
        lines: Vec<(i8, usize, Vec<PathPoint>)>,
        closing: Option<(i8, Vec<PathPoint>)>,
        mut n1: usize,
        mut n2: usize,
    ) -> Result<(Vec<Course>, usize, usize), PlyError> {
        let (mesh, region, spec) = (self.mesh, self.region, self.spec);
        let sectioner = Sectioner { mesh, region, band: spec.band(), occupied: None };
        let prepared: Vec<Line> = lines
            .into_iter()
            .map(|(side, offset_index, pts)| {
                let (pts, on) = self.run_out(pts);
                (side, offset_index, pts, on)
            })
            .collect();
        let late = std::sync::atomic::AtomicBool::new(false);
        let mut courses: Vec<Course> = prepared
            .into_par_iter()
            .map(|x| {
                // Past the deadline the remaining courses are skipped (the run fails below).
                if late.load(std::sync::atomic::Ordering::Relaxed) || check_time(spec, 0).is_err() {
                    late.store(true, std::sync::atomic::Ordering::Relaxed);
                    return Course {
                        id: 0,
                        side: x.0,
                        offset_index: x.1,
                        points: Vec::new(),
                        on_surface: Vec::new(),
                        tows: Vec::new(),
                    };
                }
                trim_line(&sectioner, spec, x, 0.0)
            })
            .collect();
        check_time(spec, courses.len())?;
        if let Some((side, pts)) = closing {
            // Lines over laid tows (by more than a twentieth of a tow, 0.32 mm for 6.35 mm tows,
            // so that abutting edges are free despite the tangent-plane offsets of [`LaidMap`])
            // count as outside the ply for the closing course.
            let laid = LaidMap::new(&courses, spec.band());
            let inset = 0.05 * spec.tow_width;
            let occupied = |q: DVec3| laid.covers(q, inset);
            let closing_sectioner = Sectioner { mesh, region, band: spec.band(), occupied: Some(&occupied) };
            let offset_index = if side < 0 { n2 + 1 } else { n1 + 1 };
            let (pts, on) = self.run_out(pts);
            // The closing course fills the strip along its length; the slivers of free surface
            // it also finds where other courses end at the boundary are not worth a tow restart:
            // pieces shorter than one course width are dropped.
            let c = trim_line(&closing_sectioner, spec, (side, offset_index, pts, on), self.width());
            if c.laid_range().is_some() {
                if side < 0 {
                    n2 += 1;
                    courses.insert(0, c);
                } else {
                    n1 += 1;
                    courses.push(c);
                }
            }
        }
        courses.retain(|c| c.laid_range().is_some());
        for (i, c) in courses.iter_mut().enumerate() {
            c.id = i;
        }
        Ok((courses, n1, n2))
    }

    fn width(&self) -> f64 {
        self.spec.tow_width * self.spec.tows as f64
    }

    /// Walk options of centreline traces: up to the longest course, in steps of at most half a
    /// course width (triangles larger than that are crossed in several steps).
    fn course_walk(&self) -> WalkOptions {
        WalkOptions { max_step: 0.5 * self.width(), ..WalkOptions::up_to(self.max_len) }
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        let f = p / self.width();
        [f.x.floor() as i64, f.y.floor() as i64, f.z.floor() as i64]
    }

    /// Remembers a course's centreline at points at most a tenth of a course width apart (long
    /// segments, from large triangles, are filled in).
    fn remember(&mut self, pts: &[PathPoint], lateral: i32) {
        let gap = 0.1 * self.width();
        let mut last: Option<DVec3> = None;
        for q in pts {
            if let Some(l) = last {
                let d = l.distance(q.p);
                if d < gap {
                    continue;
                }
                let k = (d / gap).floor() as usize;
                for j in 1..k {
                    let x = l.lerp(q.p, j as f64 / k as f64);
                    let key = self.key(x);
                    self.grid.entry(key).or_default().push((x, lateral));
                }
            }
            last = Some(q.p);
            let k = self.key(q.p);
            self.grid.entry(k).or_default().push((q.p, lateral));
        }
    }

    /// Distance to the nearest remembered course point (within one course width; else ∞) and the
    /// lateral index of its course.
    fn near_existing(&self, p: DVec3) -> (f64, i32) {
        let c = self.key(p);
        let mut best = (f64::INFINITY, 0);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(v) = self.grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &(q, lateral) in v {
                            let d = q.distance(p);
                            if d < best.0 {
                                best = (d, lateral);
                            }
                        }
                    }
                }
            }
        }
        best
    }

    /// Whether a course centre at p would still put material in the ply.
    fn useful(&self, p: DVec3, n: DVec3) -> bool {
        !self.region.has_curve() || self.region.curve_distance(p, n) > -0.5 * self.width()
    }

    /// The stop test of centreline traces: far outside the ply boundary.
    fn outside_far(&self, p: DVec3, n: DVec3) -> bool {
        self.region.has_curve() && self.region.curve_distance(p, n) < -1.5 * self.width()
    }

    /// Traces a centreline in both directions from `start`. A closed loop (a hoop on a tube) is
    /// closed once instead of wrapping again.
    fn trace(&self, start: Located, d0: DVec3, steer: Steering<'_>) -> Vec<PathPoint> {
        let w = self.width();
        let opts = self.course_walk();
        let d_start = match steer {
            Steering::Field(f) => f.direction(start.p, start.n).map(|v| if v.dot(d0) < 0.0 { -v } else { v }),
            Steering::Geodesic => tangent(d0, start.n),
        };
        let Some(d_start) = d_start else { return Vec::new() };
        let mut closed = false;
        let (mut last, mut last_s) = (start.p, 0.0);
        let (mut fwd, _) = walk(self.mesh, start, d_start, steer, &opts, |q| {
            if self.outside_far(q.p, q.n) {
                return true;
            }
            // Back at the start (a hoop): a step from more than a course width along the path
            // passes the start. (The first step, which leaves the start, does not count, however
            // long it is: on a coarse mesh it may cross the whole ply.)
            let seg = q.p - last;
            let t = if seg.length_squared() > 0.0 {
                ((start.p - last).dot(seg) / seg.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let near = (last + seg * t).distance(start.p);
            let from = last_s;
            (last, last_s) = (q.p, q.s);
            if from > w && q.s > 2.0 * w && near < 0.02 * w {
                closed = true;
                return true;
            }
            false
        });
        if closed {
            // End the loop exactly at the start.
            if let Some(l) = fwd.last_mut() {
                *l = PathPoint { p: start.p, n: start.n, ..*l };
            }
        }
        let bwd = if closed {
            Vec::new()
        } else {
            walk(self.mesh, start, -d_start, steer, &opts, |q| self.outside_far(q.p, q.n)).0
        };
        let total_b = bwd.last().map_or(0.0, |q| q.s);
        let mut pts = Vec::with_capacity(fwd.len() + bwd.len() + 1);
        pts.extend(reverse_walk(&bwd, start.sp.face).into_iter().map(|q| PathPoint { s: total_b - q.s, ..q }));
        let start_face = bwd.first().map_or(start.sp.face, |q| q.face);
        pts.push(PathPoint { p: start.p, n: start.n, d: d_start, s: total_b, face: start_face });
        for q in &fwd {
            pts.push(PathPoint { s: total_b + q.s, ..*q });
        }
        pts
    }

    /// Walks `dist` along the surface from a course point, perpendicular to the fiber, towards
    /// `sign` (+1 left). Returns the end located point and the transported fiber direction. When
    /// the mesh ends first but more than half a tow of surface is left beyond the previous
    /// course's edge, the point a quarter tow inside the mesh edge is returned instead (the last
    /// course is shifted onto the surface; the overlap this makes is reported by the quality
    /// figures).
    fn across(&self, at: &PathPoint, sign: f64, dist: f64, allow_shift: bool) -> Option<(Located, DVec3)> {
        let start = crate::course::locate(self.mesh, at.p, at.face)?;
        let b = start.n.cross(at.d) * sign;
        let opts = WalkOptions::up_to(dist);
        let (mut w, stop) = walk(self.mesh, start, b, Steering::Geodesic, &opts, |_| false);
        if stop != Stop::Length {
            let reach = w.last().map_or(0.0, |q| q.s);
            let tw = self.spec.tow_width;
            if !allow_shift || stop != Stop::Boundary || reach < 0.5 * dist + 0.5 * tw {
                return None;
            }
            let opts = WalkOptions::up_to(reach - 0.25 * tw);
            let (w2, stop2) = walk(self.mesh, start, b, Steering::Geodesic, &opts, |_| false);
            if stop2 != Stop::Length {
                return None;
            }
            w = w2;
        }
        let end = w.last()?;
        let loc = crate::course::locate(self.mesh, end.p, end.face)?;
        let d = tangent(transport(at.d, start.n, loc.n), loc.n)?;
        Some((loc, d))
    }

    /// The next course one width across from `prev` towards `sign` for the ply's method;
    /// `on_existing` allows it to land on courses already laid (the closing course).
    /// `prev_index` is the lateral index of `prev`.
    fn next_course(
        &self,
        prev: &[PathPoint],
        prev_index: i32,
        sign: f64,
        steer: Steering<'_>,
        on_existing: bool,
    ) -> Next {
        match self.spec.method {
            Method::Parallel => self.parallel(prev, prev_index, sign, on_existing),
            Method::Field | Method::Natural => self.seeded(prev, prev_index, sign, steer, on_existing),
        }
    }

    /// Whether a course of lateral index `owner` met by the next course after `prev_index` lies
    /// round a closed surface rather than beside it.
    fn wraps(owner: i32, prev_index: i32) -> bool {
        (owner - prev_index).abs() > 2
    }

    /// Next course for the field and natural methods: seeded one course width across from the
    /// previous course (at the point nearest the previous seed that lands in the ply and, unless
    /// `on_existing`, not on an existing course), then traced.
    fn seeded(&self, prev: &[PathPoint], prev_index: i32, sign: f64, steer: Steering<'_>, on_existing: bool) -> Next {
        let w = self.width();
        let Some(len) = prev.last().map(|q| q.s) else { return Next::End };
        let mut blocked = false;
        // Candidate stations every w/2, nearest the middle first.
        let mid = 0.5 * len;
        let count = (len / (0.5 * w)).ceil() as usize + 1;
        let mut cands: Vec<f64> = (0..count).map(|i| (i as f64 * 0.5 * w).min(len)).collect();
        cands.sort_by(|a, b| (a - mid).abs().total_cmp(&(b - mid).abs()));
        for s in cands {
            let (p, n, d) = crate::course::frame_at(prev, s);
            if !self.useful(p, n) {
                continue;
            }
            let at = PathPoint { p, n, d, s, face: crate::course::face_hint(prev, s) };
            let Some((loc, dt)) = self.across(&at, sign, w, true) else { continue };
            if !self.useful(loc.p, loc.n) {
                continue;
            }
            let (dist, owner) = self.near_existing(loc.p);
            if !on_existing && dist < 0.5 * w {
                blocked |= Self::wraps(owner, prev_index);
                continue;
            }
            let d0 = match steer {
                Steering::Field(f) => f.direction(loc.p, loc.n).map(|v| if v.dot(dt) < 0.0 { -v } else { v }),
                Steering::Geodesic => {
                    // Natural path: start in the design direction at the seed.
                    self.field.direction(loc.p, loc.n).map(|v| if v.dot(dt) < 0.0 { -v } else { v })
                }
            };
            let Some(d0) = d0 else { continue };
            let pts = self.trace(loc, d0, steer);
            if pts.len() >= 2 {
                return Next::Course(pts);
            }
        }
        if blocked {
            Next::Blocked
        } else {
            Next::End
        }
    }

    /// Next course for the parallel method: the geodesic offset of every station of the previous
    /// course, extended at both ends along geodesics to the ply (seed 002 §4).
    fn parallel(&self, prev: &[PathPoint], prev_index: i32, sign: f64, on_existing: bool) -> Next {
        // Whole-width offsets first; only where none fits (the last strip before a mesh edge) is
        // the course shifted onto the surface.
        match self.parallel_with(prev, prev_index, sign, false, on_existing) {
            Next::Course(c) => Next::Course(c),
            first => match self.parallel_with(prev, prev_index, sign, true, on_existing) {
                Next::Course(c) => Next::Course(c),
                Next::Blocked => Next::Blocked,
                Next::End => first,
            },
        }
    }

    fn parallel_with(
        &self,
        prev: &[PathPoint],
        prev_index: i32,
        sign: f64,
        allow_shift: bool,
        on_existing: bool,
    ) -> Next {
        let w = self.width();
        let Some(len) = prev.last().map(|q| q.s) else { return Next::End };
        let step = (0.1 * w).clamp(1.0, 10.0);
        let count = (len / step).ceil() as usize;
        let mut pts: Vec<PathPoint> = Vec::new();
        for i in 0..=count {
            let s = (i as f64 * step).min(len);
            let (p, n, d) = crate::course::frame_at(prev, s);
            let at = PathPoint { p, n, d, s, face: crate::course::face_hint(prev, s) };
            let Some((loc, dt)) = self.across(&at, sign, w, allow_shift) else { continue };
            // Drop points where the offset folds back (prev curves tighter than w on this side).
            if let Some(last) = pts.last() {
                if (loc.p - last.p).dot(last.d) <= 1e-9 {
                    continue;
                }
            }
            pts.push(PathPoint { p: loc.p, n: loc.n, d: dt, s: 0.0, face: NO_FACE });
        }
        let useful = pts.iter().filter(|q| self.useful(q.p, q.n)).count();
        if useful == 0 {
            return Next::End;
        }
        let near: Vec<(f64, i32)> = pts.iter().map(|q| self.near_existing(q.p)).collect();
        let covered = near.iter().filter(|x| x.0 < 0.5 * w).count();
        if !on_existing && covered * 2 > pts.len() {
            let wrapped = near.iter().filter(|x| x.0 < 0.5 * w && Self::wraps(x.1, prev_index)).count();
            // Wrapped onto courses round a closed surface, or folded onto its neighbours.
            return if wrapped * 2 > pts.len() { Next::Blocked } else { Next::End };
        }
        let closed = prev.len() > 2 && prev[0].p.distance(prev[prev.len() - 1].p) < 0.02 * w;
        if closed {
            // The offset of a closed course (a hoop) is closed too: no extension.
            let mut all = pts;
            if let Some(&first) = all.first() {
                all.push(first);
            }
            let mut s = 0.0;
            for i in 0..all.len() {
                if i > 0 {
                    s += all[i].p.distance(all[i - 1].p);
                }
                all[i].s = s;
            }
            return Next::Course(all);
        }
        // Extend both ends geodesically until leaving the ply or the mesh.
        let opts = self.course_walk();
        let ext = |q: &PathPoint, dir: DVec3| -> Vec<PathPoint> {
            let Some(loc) = crate::course::locate(self.mesh, q.p, q.face) else { return Vec::new() };
            walk(self.mesh, loc, dir, Steering::Geodesic, &opts, |x| self.outside_far(x.p, x.n)).0
        };
        let (Some(&first), Some(&last)) = (pts.first(), pts.last()) else { return Next::End };
        let head = ext(&first, -first.d);
        let tail = ext(&last, last.d);
        let mut all: Vec<PathPoint> = reverse_walk(&head, NO_FACE);
        if let Some(first) = pts.first_mut() {
            first.face = head.first().map_or(NO_FACE, |q| q.face);
        }
        all.extend(pts);
        all.extend(tail);
        let mut s = 0.0;
        for i in 0..all.len() {
            if i > 0 {
                s += all[i].p.distance(all[i - 1].p);
            }
            all[i].s = s;
        }
        Next::Course(all)
    }

    /// Adds straight run-outs beyond the mesh edge at ends where the centreline stopped on the
    /// mesh boundary, so tows on the trailing side can be laid to the edge under the 50 % and 100 %
    /// rules. Run-outs are at most one course width long and marked off the surface.
    fn run_out(&self, mut pts: Vec<PathPoint>) -> (Vec<PathPoint>, Vec<bool>) {
        let w = self.width();
        let mut on = vec![true; pts.len()];
        if pts.len() < 2 || self.spec.coverage == Coverage::Zero {
            return (pts, on);
        }
        let near_edge = |p: DVec3| self.region.mesh_edges.distance(p) < 1e-6 * (1.0 + p.length());
        let k = 4;
        if let Some(&l) = pts.last() {
            if near_edge(l.p) {
                for i in 1..=k {
                    let t = w * i as f64 / k as f64;
                    pts.push(PathPoint { p: l.p + l.d * t, s: l.s + t, face: NO_FACE, ..l });
                    on.push(false);
                }
            }
        }
        if let Some(&f) = pts.first() {
            if near_edge(f.p) {
                let mut head = Vec::new();
                for i in (1..=k).rev() {
                    let t = w * i as f64 / k as f64;
                    head.push(PathPoint { p: f.p - f.d * t, s: f.s - t, face: NO_FACE, ..f });
                }
                let n = head.len();
                if let Some(first) = pts.first_mut() {
                    first.face = NO_FACE;
                }
                head.extend(pts);
                pts = head;
                let mut on2 = vec![false; n];
                on2.extend(on);
                on = on2;
                let s0 = pts[0].s;
                for q in &mut pts {
                    q.s -= s0;
                }
            }
        }
        (pts, on)
    }

    /// Seed 002 eq. 9: the longest section across the reference course on each side, walked as a
    /// geodesic perpendicular to the fiber until it leaves the ply, divided by the course width;
    /// and the two longest sections added (the ply's width across the fibers).
    fn estimate(&self, reference: &[PathPoint]) -> ([usize; 2], f64) {
        let w = self.width();
        let Some(len) = reference.last().map(|q| q.s) else { return ([0, 0], 0.0) };
        let mut best = [0.0f64; 2];
        let count = (len / w).ceil().max(1.0) as usize;
        for i in 0..=count {
            let s = len * i as f64 / count as f64;
            let (p, n, d) = crate::course::frame_at(reference, s);
            if self.region.has_curve() && self.region.curve_distance(p, n) < 0.0 {
                continue;
            }
            let Some(start) = crate::course::locate(self.mesh, p, crate::course::face_hint(reference, s)) else {
                continue;
            };
            for (k, sign) in [(0usize, 1.0f64), (1, -1.0)] {
                let b = n.cross(d) * sign;
                let opts = WalkOptions::up_to(self.max_len);
                let (wk, _) = walk(self.mesh, start, b, Steering::Geodesic, &opts, |q| {
                    (self.region.has_curve() && self.region.curve_distance(q.p, q.n) < 0.0)
                        || (q.s > w && q.p.distance(start.p) < 0.02 * w)
                });
                let l = wk.last().map_or(0.0, |q| q.s);
                best[k] = best[k].max(l);
            }
        }
        // The reference course covers half a width on each side.
        let count = |l: f64| ((l - 0.5 * w).max(0.0) / w - 1e-6).ceil().max(0.0) as usize;
        ([count(best[0]), count(best[1])], best[0] + best[1])
    }
}

/// Trims one centreline per tow under the spec's coverage rule (laid pieces shorter than
/// `shortest` dropped) and crops it to where tows are laid.
fn trim_line(sectioner: &Sectioner<'_>, spec: &PlySpec, line: Line, shortest: f64) -> Course {
    let (side, offset_index, pts, on_surface) = line;
    let mut tows = sectioner.trim(&pts, spec.coverage, spec.station_step, 1e-3);
    for ivs in &mut tows {
        ivs.retain(|iv| iv[1] - iv[0] >= shortest);
    }
    let mut c = Course { id: 0, side, offset_index, points: pts, on_surface, tows };
    crop(&mut c);
    c
}

/// Crops a course's centreline to the range where tows are laid (with exact end points).
fn crop(c: &mut Course) {
    let Some([a, b]) = c.laid_range() else { return };
    let (pa, na, da) = c.frame_at(a);
    let (pb, nb, db) = c.frame_at(b);
    let face_at = |s: f64| {
        let i = c.points.partition_point(|q| q.s < s).min(c.points.len().saturating_sub(1));
        c.points.get(i).map_or(NO_FACE, |q| q.face)
    };
    // A new end point is on the surface only if the segment it lies in is (both its ends are): an
    // end cut inside a run-out is off the mesh even when the next point is on it.
    let flag_at = |s: f64| {
        let i = c.points.partition_point(|q| q.s < s);
        match (c.points.get(i), c.on_surface.get(i)) {
            (Some(q), Some(&o)) if (q.s - s).abs() <= 1e-9 => o,
            _ => c.on_surface_at(s),
        }
    };
    let (on_a, on_b) = (flag_at(a), flag_at(b));
    let mut pts = vec![PathPoint { p: pa, n: na, d: da, s: a, face: NO_FACE }];
    let mut on = vec![on_a];
    for (q, &o) in c.points.iter().zip(&c.on_surface) {
        if q.s > a + 1e-9 && q.s < b - 1e-9 {
            pts.push(*q);
            on.push(o);
        }
    }
    pts.push(PathPoint { p: pb, n: nb, d: db, s: b, face: face_at(b) });
    on.push(on_b);
    // Re-base arc length to start at zero.
    for q in &mut pts {
        q.s -= a;
    }
    for ivs in &mut c.tows {
        for iv in ivs.iter_mut() {
            iv[0] -= a;
            iv[1] -= a;
        }
    }
    c.points = pts;
    c.on_surface = on;
}
