//! Course footprints: the on-part path swept by the course width, in a 2D frame of the part.
//!
//! The frame is the plan view (x, y of the part-frame tool point) for machines without a
//! mandrel, and the unrolled cylinder (axial position, arc length at a reference radius) for
//! machines with one; the unrolled frame is periodic in its second coordinate. Each laid move
//! becomes one or more rectangles ([`Quad`]) of the course width at that move: the tow width
//! times the tows on (dropped tows narrow it) or a fixed course width.
//!
//! Two footprints *overlap* when they share a region wider than [`OVERLAP_TOLERANCE`]: every
//! rectangle is shrunk by half that tolerance on each side, and shrunk rectangles must overlap
//! with positive area (bands that only touch do not overlap).

use glam::DVec3;
use towpath_machine::{Kinematics, Machine};

use crate::error::NcError;
use crate::program::Program;

/// Overlaps narrower than this (mm) do not count.
pub const OVERLAP_TOLERANCE: f64 = 0.01;

/// How wide a course is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Width {
    /// Tow width in mm: the course width is this times the number of tows on.
    Tow(f64),
    /// A fixed course width in mm.
    Course(f64),
}

/// The 2D frame footprints are drawn in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Frame {
    /// Plan view: x and y of the part-frame tool point.
    Plan,
    /// Unrolled cylinder around the mandrel axis: (axial, arc length at `radius`), periodic in
    /// the second coordinate with period 2π·radius.
    Cylinder {
        /// A point on the axis.
        origin: [f64; 3],
        /// Unit direction of the axis.
        dir: [f64; 3],
        /// First unit vector across the axis (angle 0).
        e1: [f64; 3],
        /// Second unit vector across the axis (angle 90°).
        e2: [f64; 3],
        /// Reference radius, mm.
        radius: f64,
    },
}

impl Frame {
    /// The period of the second coordinate, if the frame is periodic.
    pub fn period(&self) -> Option<f64> {
        match self {
            Frame::Plan => None,
            Frame::Cylinder { radius, .. } => Some(2.0 * std::f64::consts::PI * radius),
        }
    }

    /// Maps a part-frame point to the frame (unwrapped angle in (−π, π]).
    pub fn map(&self, p: [f64; 3]) -> [f64; 2] {
        match self {
            Frame::Plan => [p[0], p[1]],
            Frame::Cylinder { origin, dir, e1, e2, radius } => {
                let d = DVec3::from(p) - DVec3::from(*origin);
                let u = d.dot(DVec3::from(*dir));
                let phi = d.dot(DVec3::from(*e2)).atan2(d.dot(DVec3::from(*e1)));
                [u, radius * phi]
            }
        }
    }

    /// Moves `v` by whole periods to be as close as possible to `near`.
    #[inline]
    pub fn unwrap_near(&self, v: f64, near: f64) -> f64 {
        match self.period() {
            None => v,
            Some(p) => v - p * ((v - near) / p).round(),
        }
    }
}

/// An oriented rectangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// Centre.
    pub c: [f64; 2],
    /// Unit vector along the rectangle.
    pub u: [f64; 2],
    /// Half length along `u`.
    pub hl: f64,
    /// Half width across `u`.
    pub hw: f64,
}

impl Quad {
    /// The four corners, counter-clockwise.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let n = [-self.u[1], self.u[0]];
        let (a, b) = ([self.u[0] * self.hl, self.u[1] * self.hl], [n[0] * self.hw, n[1] * self.hw]);
        [
            [self.c[0] - a[0] - b[0], self.c[1] - a[1] - b[1]],
            [self.c[0] + a[0] - b[0], self.c[1] + a[1] - b[1]],
            [self.c[0] + a[0] + b[0], self.c[1] + a[1] + b[1]],
            [self.c[0] - a[0] + b[0], self.c[1] - a[1] + b[1]],
        ]
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let ex = self.hl * self.u[0].abs() + self.hw * self.u[1].abs();
        let ey = self.hl * self.u[1].abs() + self.hw * self.u[0].abs();
        ([self.c[0] - ex, self.c[1] - ey], [self.c[0] + ex, self.c[1] + ey])
    }

    /// The same rectangle moved along the second coordinate.
    pub fn shifted(&self, dv: f64) -> Quad {
        Quad { c: [self.c[0], self.c[1] + dv], ..*self }
    }

    /// True if the interiors of the two rectangles intersect (touching is not enough).
    pub fn overlaps(&self, o: &Quad) -> bool {
        let d = [o.c[0] - self.c[0], o.c[1] - self.c[1]];
        let axes = [self.u, [-self.u[1], self.u[0]], o.u, [-o.u[1], o.u[0]]];
        for l in axes {
            let dist = (d[0] * l[0] + d[1] * l[1]).abs();
            if dist >= self.radius(l) + o.radius(l) {
                return false;
            }
        }
        true
    }

    /// True if the point lies in the closed rectangle.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        let d = [p[0] - self.c[0], p[1] - self.c[1]];
        let along = (d[0] * self.u[0] + d[1] * self.u[1]).abs();
        let across = (-d[0] * self.u[1] + d[1] * self.u[0]).abs();
        along <= self.hl && across <= self.hw
    }

    #[inline]
    fn radius(&self, l: [f64; 2]) -> f64 {
        self.hl * (self.u[0] * l[0] + self.u[1] * l[1]).abs() + self.hw * (-self.u[1] * l[0] + self.u[0] * l[1]).abs()
    }
}

/// A course's footprint.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Footprint {
    /// The shrunk rectangles (see the module docs), unwrapped along the course: each laid move
    /// split into pieces no longer than four widths.
    pub quads: Vec<Quad>,
    /// The whole shrunk rectangle of each laid move (the union of its pieces).
    pub moves: Vec<Quad>,
    /// For each piece, its move.
    pub move_of: Vec<u32>,
    /// The laid centre line as polylines in the frame (unwrapped along the course).
    pub paths: Vec<Vec<[f64; 2]>>,
}

impl Footprint {
    /// True if the two footprints overlap (see the module docs).
    pub fn overlaps(&self, other: &Footprint, frame: &Frame) -> bool {
        for a in &self.quads {
            let (amin, amax) = a.bounds();
            for b in &other.quads {
                let b = match frame.period() {
                    Some(_) => b.shifted(frame.unwrap_near(b.c[1], a.c[1]) - b.c[1]),
                    None => *b,
                };
                let (bmin, bmax) = b.bounds();
                if bmin[0] >= amax[0] || bmax[0] <= amin[0] || bmin[1] >= amax[1] || bmax[1] <= amin[1] {
                    continue;
                }
                if a.overlaps(&b) {
                    return true;
                }
            }
        }
        false
    }
}

/// The footprints of every course of a program.
#[derive(Clone, Debug)]
pub struct Footprints {
    /// The frame.
    pub frame: Frame,
    /// One footprint per course.
    pub courses: Vec<Footprint>,
}

/// The narrowest course (one tow of a tow width, or a course width) towpath accepts, mm: twice
/// the overlap tolerance, since every footprint is shrunk by half of it on each side.
pub const MIN_WIDTH: f64 = 2.0 * OVERLAP_TOLERANCE;

/// A course width may be at most this many times the span of the whole laid part (the diagonal
/// of its laid centre lines in the footprint frame).
pub const MAX_WIDTH_PER_SPAN: f64 = 2.0;

/// At most this many footprint rectangles in a program: beyond it, laid moves are split into
/// longer pieces (the footprints stay exact; only spatial indexes get looser).
pub const MAX_PIECES: usize = 1_000_000;

/// Every laid move of the program: (course, segment index, course width there), in program
/// order. A course that restarts tows lays where tows are on; one that restarts none (a
/// dialect without tow codes in use) lays wherever the roller is in contact.
fn laid_moves(program: &Program, width: Option<Width>) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::new();
    for (c, course) in program.courses.iter().enumerate() {
        let segs = course.segments.clone();
        let has_tows = program.segments[segs.clone()].iter().any(|s| s.on_part && s.mask != 0);
        for i in segs {
            let s = &program.segments[i];
            if s.on_part && (!has_tows || s.mask != 0) {
                let w = match width {
                    Some(Width::Course(w)) => w,
                    Some(Width::Tow(t)) => t * s.mask.count_ones().max(1) as f64,
                    None => 0.0,
                };
                out.push((c, i, w));
            }
        }
    }
    out
}

/// The part-frame frame for a machine and program: plan, or an unrolled cylinder around the
/// mandrel at the median radius of the laid points. Refused when a laid point lies closer to
/// the mandrel axis than its course width / 2π (its course would wrap the whole mandrel there;
/// without a width: closer than 1 µm), naming the line: the footprints cannot be unrolled.
pub fn frame_for(
    program: &Program,
    machine: &Machine,
    kin: &Kinematics,
    width: Option<Width>,
) -> Result<Frame, NcError> {
    let Some((origin, dir)) = kin.mandrel_axis() else {
        return Ok(Frame::Plan);
    };
    let (o, k) = (DVec3::from(origin), DVec3::from(dir));
    // e1: any unit vector across the axis.
    let pick = if k.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let across = pick - k * pick.dot(k);
    let e1 = across / across.length();
    let e2 = k.cross(e1);
    let radius_of = |i: u32| {
        let d = DVec3::from(kin.part_point(program.point(i))) - o;
        (d - k * d.dot(k)).length()
    };
    let mut radii: Vec<f64> = Vec::new();
    for (_, i, w) in laid_moves(program, width) {
        let s = &program.segments[i];
        for p in [s.from, s.to] {
            let r = radius_of(p);
            let min = (w / std::f64::consts::TAU).max(1e-3);
            if r.is_nan() || r < min {
                return Err(NcError::MandrelAxis {
                    line: s.line as usize + 1,
                    radius: r,
                    width: w,
                    axis: machine.mandrel_axis().unwrap_or(0),
                    label: machine.mandrel_axis().map_or_else(String::new, |i| machine.axes[i].label.clone()),
                    origin,
                    direction: dir,
                });
            }
        }
        radii.push(radius_of(s.to));
    }
    radii.sort_by(f64::total_cmp);
    // Nothing laid: no footprint depends on the radius.
    let radius = radii.get(radii.len() / 2).copied().unwrap_or(1.0);
    Ok(Frame::Cylinder { origin, dir, e1: e1.to_array(), e2: e2.to_array(), radius })
}

/// Builds the footprints of every course. Needs the machine's kinematics and a width; refuses a
/// width narrower than [`MIN_WIDTH`] or wider than [`MAX_WIDTH_PER_SPAN`] times the laid part,
/// and laid points on or near a mandrel's axis (closer than the course width / 2π, where the unrolled course would wrap the whole mandrel).
pub fn footprints(program: &Program, machine: &Machine, width: Width) -> Result<Footprints, NcError> {
    footprints_within(program, machine, width, MAX_PIECES)
}

/// [`footprints`] with at most about `max_pieces` rectangles (one more per laid move at most).
pub(crate) fn footprints_within(
    program: &Program,
    machine: &Machine,
    width: Width,
    max_pieces: usize,
) -> Result<Footprints, NcError> {
    let narrowest = match width {
        Width::Tow(t) | Width::Course(t) => t,
    };
    if !(narrowest.is_finite() && narrowest >= MIN_WIDTH) {
        return Err(NcError::ImplausibleWidth {
            width: narrowest,
            problem: format!(
                "is narrower than {MIN_WIDTH} mm (twice the {OVERLAP_TOLERANCE} mm overlap tolerance): its footprints would vanish"
            ),
        });
    }
    let kin = machine.kinematics().ok_or(NcError::NoToolPoint)?;
    for course in &program.courses {
        let segs = &program.segments[course.segments.clone()];
        let has_tows = segs.iter().any(|s| s.on_part && s.mask != 0);
        if !has_tows && matches!(width, Width::Tow(_)) && segs.iter().any(|s| s.on_part) {
            return Err(NcError::TowWidthWithoutTows { line: course.on_part.start + 1 });
        }
    }
    let frame = frame_for(program, machine, &kin, Some(width))?;
    // Every laid move in the frame (unwrapped along its course), and the part's span.
    let laid = laid_moves(program, Some(width));
    let mut mapped: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(laid.len());
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    // The course and the end of its last laid move (unwrapped), to unwrap the next one near it.
    let mut last: Option<(usize, f64)> = None;
    for &(c, i, _) in &laid {
        let s = &program.segments[i];
        let mut a = frame.map(kin.part_point(program.point(s.from)));
        let mut b = frame.map(kin.part_point(program.point(s.to)));
        if let Some((_, v)) = last.filter(|l| l.0 == c) {
            a[1] = frame.unwrap_near(a[1], v);
        }
        b[1] = frame.unwrap_near(b[1], a[1]);
        last = Some((c, b[1]));
        for p in [a, b] {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        mapped.push((a, b));
    }
    let widest = laid.iter().map(|l| l.2).fold(0.0, f64::max);
    if lo[0].is_finite() {
        let span = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
        if span > OVERLAP_TOLERANCE && widest > MAX_WIDTH_PER_SPAN * span {
            return Err(NcError::ImplausibleWidth {
                width: widest,
                problem: format!(
                    "is more than {MAX_WIDTH_PER_SPAN} times the whole laid part, whose laid paths span {span:.3} mm{}: \
                     a width in other units?",
                    if frame.period().is_some() { " on the unrolled mandrel" } else { " in plan" }
                ),
            });
        }
    }
    // Pieces no longer than four widths (at most 100,000 per move), unless that makes more than
    // `max_pieces` in all: then each move gets its share of them.
    let length = |(a, b): &([f64; 2], [f64; 2])| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let natural: Vec<usize> = laid
        .iter()
        .zip(&mapped)
        .map(|(l, m)| {
            let inner = length(m) - OVERLAP_TOLERANCE;
            if inner > 0.0 {
                ((inner / (4.0 * l.2.max(1e-3))).ceil() as usize).clamp(1, 100_000)
            } else {
                0
            }
        })
        .collect();
    let total = natural.iter().fold(0usize, |a, &b| a.saturating_add(b));
    let share = |n: usize| {
        if total > max_pieces {
            ((n as f64 * max_pieces as f64 / total as f64) as usize).max(1)
        } else {
            n
        }
    };

    let mut courses: Vec<Footprint> = vec![Footprint::default(); program.courses.len()];
    let mut path: Vec<[f64; 2]> = Vec::new();
    let mut prev: Option<(usize, usize)> = None;
    for ((&(c, i, w), &(a, b)), &n) in laid.iter().zip(&mapped).zip(&natural) {
        // A new polyline where the course changes or a laid move does not follow the last one.
        let joined = prev.is_some_and(|(pc, pi)| pc == c && pi + 1 == i);
        if !joined {
            if let Some((pc, _)) = prev {
                if path.len() > 1 {
                    courses[pc].paths.push(std::mem::take(&mut path));
                }
            }
            path.clear();
        }
        if path.is_empty() {
            path.push(a);
        }
        path.push(b);
        add_pieces(&mut courses[c], a, b, w, share(n));
        prev = Some((c, i));
    }
    if let Some((pc, _)) = prev {
        if path.len() > 1 {
            courses[pc].paths.push(path);
        }
    }
    Ok(Footprints { frame, courses })
}

/// Adds the shrunk rectangles of one laid move from `a` to `b` of width `w`, split into pieces
/// no longer than four widths (so spatial indexes stay tight).
#[cfg(test)]
fn add_quads(fp: &mut Footprint, a: [f64; 2], b: [f64; 2], w: f64) {
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let pieces = (((len - OVERLAP_TOLERANCE) / (4.0 * w.max(1e-3))).ceil() as usize).clamp(1, 100_000);
    add_pieces(fp, a, b, w, pieces)
}

/// Adds the shrunk rectangles of one laid move from `a` to `b` of width `w`, in `pieces`
/// pieces of equal length (the whole move's rectangle goes to `moves`).
fn add_pieces(fp: &mut Footprint, a: [f64; 2], b: [f64; 2], w: f64, pieces: usize) {
    let shrink = OVERLAP_TOLERANCE / 2.0;
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let hw = w / 2.0 - shrink;
    if !(len > OVERLAP_TOLERANCE && hw > 0.0 && len.is_finite()) {
        return;
    }
    let u = [d[0] / len, d[1] / len];
    let inner = len - OVERLAP_TOLERANCE;
    let pieces = pieces.max(1);
    let piece = inner / pieces as f64;
    let m = fp.moves.len() as u32;
    fp.moves.push(Quad { c: [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], u, hl: inner / 2.0, hw });
    for k in 0..pieces {
        let t = shrink + piece * (k as f64 + 0.5);
        fp.quads.push(Quad { c: [a[0] + u[0] * t, a[1] + u[1] * t], u, hl: piece / 2.0, hw });
        fp.move_of.push(m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band(x0: f64, y: f64, x1: f64, w: f64) -> Footprint {
        let mut fp = Footprint::default();
        add_quads(&mut fp, [x0, y], [x1, y], w);
        fp
    }

    #[test]
    fn bands_that_touch_do_not_overlap_and_wider_overlaps_do() {
        let f = Frame::Plan;
        let a = band(0.0, 0.0, 100.0, 10.0);
        // Side by side, edges touching: y = 10 apart with width 10.
        assert!(!a.overlaps(&band(0.0, 10.0, 100.0, 10.0), &f));
        // Overlapping by 0.005 mm: below the tolerance.
        assert!(!a.overlaps(&band(0.0, 9.995, 100.0, 10.0), &f));
        // Overlapping by 0.02 mm: counts.
        assert!(a.overlaps(&band(0.0, 9.98, 100.0, 10.0), &f));
        // End to end, touching.
        assert!(!a.overlaps(&band(100.0, 0.0, 200.0, 10.0), &f));
        // Crossing at right angles.
        let mut cross = Footprint::default();
        add_quads(&mut cross, [50.0, -50.0], [50.0, 50.0], 10.0);
        assert!(a.overlaps(&cross, &f));
        // Long moves are split into short pieces.
        assert_eq!(a.quads.len(), 3);
        assert_eq!(a.moves.len(), 1);
        assert_eq!(a.move_of, vec![0, 0, 0]);
    }

    fn xyz() -> Machine {
        use towpath_machine::{Axis, AxisKind};
        Machine::new("m", ["X", "Y", "Z"].iter().map(|l| Axis::new(l, AxisKind::Linear)).collect()).unwrap()
    }

    /// One tow laid in a straight line from `a` to `b` (plan coordinates).
    fn course(a: [f64; 2], b: [f64; 2]) -> String {
        format!(
            "G0 X{} Y{} Z10\nG1 Z0 F1000\nM20\nM60 P1\nG1 X{} Y{} F3000\nM61 P1\nM21\nG1 Z10\n",
            a[0], a[1], b[0], b[1]
        )
    }

    /// Capped at a few pieces, long moves are split into longer pieces that still make up
    /// exactly each move, and precedence comes out the same.
    #[test]
    fn capped_pieces_still_make_up_each_move() {
        let mut text = String::from("G90\n(PLY 1)\n");
        for k in 0..4 {
            text.push_str(&course([0.0, 10.0 * k as f64], [5000.0, 10.0 * k as f64]));
        }
        text.push_str("(PLY 2)\n");
        for k in 0..4 {
            text.push_str(&course([1000.0 * k as f64, -5.0], [1000.0 * k as f64 + 300.0, 40.0]));
        }
        let m = xyz();
        let p = crate::parse::parse(&text, &m, &crate::Dialect::default()).unwrap();
        let free = footprints(&p, &m, Width::Course(2.0)).unwrap();
        let capped = footprints_within(&p, &m, Width::Course(2.0), 40).unwrap();
        let count = |f: &Footprints| f.courses.iter().map(|c| c.quads.len()).sum::<usize>();
        assert!(count(&free) > 2000, "{}", count(&free));
        assert!(count(&capped) <= 40 + 8, "{}", count(&capped));
        for (a, b) in free.courses.iter().zip(&capped.courses) {
            assert_eq!(a.moves, b.moves);
            for (mi, mv) in b.moves.iter().enumerate() {
                let pieces: Vec<&Quad> =
                    b.quads.iter().zip(&b.move_of).filter(|(_, &m)| m as usize == mi).map(|(q, _)| q).collect();
                let total: f64 = pieces.iter().map(|q| 2.0 * q.hl).sum();
                assert!((total - 2.0 * mv.hl).abs() < 1e-6, "{total} {}", 2.0 * mv.hl);
                assert!(pieces.iter().all(|q| q.hw == mv.hw && q.u == mv.u));
            }
        }
        let plies: Vec<Vec<usize>> = p.plies.iter().map(|p| p.courses.clone()).collect();
        let mut e1 = crate::precedence::course_precedence(&free, &plies).unwrap();
        let mut e2 = crate::precedence::course_precedence(&capped, &plies).unwrap();
        e1.sort_unstable();
        e2.sort_unstable();
        assert_eq!(e1, e2);
        assert!(!e1.is_empty());
    }

    /// Widths narrower than twice the overlap tolerance, or far wider than the part, are refused;
    /// the bounds themselves are accepted.
    #[test]
    fn widths_are_checked_against_the_tolerance_and_the_part() {
        let mut text = String::from("G90\n(PLY 1)\n");
        text.push_str(&course([0.0, 0.0], [300.0, 0.0]));
        text.push_str(&course([0.0, 40.0], [300.0, 40.0]));
        let m = xyz();
        let p = crate::parse::parse(&text, &m, &crate::Dialect::default()).unwrap();
        // The laid paths span the diagonal of (0, 0)–(300, 40).
        let span = (300.0f64 * 300.0 + 40.0 * 40.0).sqrt();
        assert!(footprints(&p, &m, Width::Course(MAX_WIDTH_PER_SPAN * span * 0.999)).is_ok());
        let e = footprints(&p, &m, Width::Course(MAX_WIDTH_PER_SPAN * span * 1.001)).unwrap_err();
        assert!(matches!(e, NcError::ImplausibleWidth { .. }) && e.to_string().contains("302.655 mm in plan"), "{e}");
        let e = footprints(&p, &m, Width::Course(1e20)).unwrap_err();
        assert!(e.to_string().starts_with("a course width of 1e20 mm is more than 2 times"), "{e}");
        assert!(footprints(&p, &m, Width::Tow(MIN_WIDTH)).is_ok());
        let e = footprints(&p, &m, Width::Tow(MIN_WIDTH * 0.9)).unwrap_err();
        assert!(e.to_string().contains("is narrower than 0.02 mm"), "{e}");
    }

    #[test]
    fn periodic_frame_wraps() {
        let f = Frame::Cylinder {
            origin: [0.0; 3],
            dir: [1.0, 0.0, 0.0],
            e1: [0.0, 1.0, 0.0],
            e2: [0.0, 0.0, 1.0],
            radius: 100.0,
        };
        let p = f.period().unwrap();
        // Two hoop bands at the same axial place, one written one turn further.
        let a = band(0.0, 5.0, 50.0, 10.0);
        let mut b = band(0.0, 5.0 + p, 50.0, 10.0);
        assert!(a.overlaps(&b, &f));
        b = band(0.0, 20.0 + p, 50.0, 10.0);
        assert!(!a.overlaps(&b, &f));
        assert!((f.map([3.0, 0.0, 100.0])[1] - p / 4.0).abs() < 1e-9);
    }
}
