//! The verifier: checks an optimized program against its original, independently of the
//! optimizer (it shares only the parser and the footprint geometry).
//!
//! It checks that the optimized program lays the same multiset of courses, each either with
//! the same motion (points, tows on, motion codes and feeds, approach and retract included; its
//! span byte-identical, or, if written anew, keeping its comments and unknown lines), or as a
//! legal reversal (the same points in reverse order, the heading axis turned by 180°, the same
//! tows on along every move, the same feeds on-part, the reversed approach at the original
//! approach's motion code and feed and the reversed retract at the original retract's); that
//! every line the original keeps (header, footer, comments and unknown lines) is still there;
//! and that no course is laid before a course of an earlier ply it overlaps. It measures the
//! off-part and on-part motion of both programs under every cost model the machine supports.

use std::collections::HashMap;

use serde::Serialize;
use towpath_machine::{CostKind, Machine, MachineCost, StateTable};

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::footprint::{footprints, Footprints, Width};
use crate::program::{Program, Region};
use crate::rewrite::Placement;
use crate::width::WidthUsed;

/// What the verifier checks beyond the course rule.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VerifyOptions {
    /// Course width, for the footprints of the precedence check (else the dialect's).
    pub width: Option<Width>,
    /// Also require every ply to be laid after the one before.
    pub strict_plies: bool,
    /// Also require the courses of each ply in their original order.
    pub keep_ply_order: bool,
    /// Also require Doherty et al.'s precedence sets in order: every course of a set laid before any
    /// course of the next (the verifier finds the sets on its own, from the footprints).
    pub doherty_sets: bool,
}

/// Why an optimized program does not verify.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// The original program could not be read.
    #[error("original program: {0}")]
    Original(NcError),
    /// The optimized program could not be read.
    #[error("optimized program: {0}")]
    Optimized(NcError),
    /// The verification needs something it was not given.
    #[error("{0}")]
    Setup(NcError),
    /// The numbers of courses differ.
    #[error("the optimized program has {got} courses, the original {expected}")]
    CourseCount {
        /// Courses in the optimized program.
        got: usize,
        /// Courses in the original.
        expected: usize,
    },
    /// A course of the optimized program is no course of the original.
    #[error("optimized program line {line}: this course is not a course of the original, forward or legally reversed{detail}")]
    Unmatched {
        /// 1-based line of the course's roller contact in the optimized program.
        line: usize,
        /// What differs from the closest candidate, if there was one.
        detail: String,
    },
    /// A course of the original is not laid.
    #[error("{0} of the original is not laid by the optimized program")]
    Missing(String),
    /// A line of the optimized program is none of the original's lines, nor part of a legal
    /// reversal, nor a transit towpath writes.
    #[error(
        "optimized program line {line} ({text:?}) {place} is not a line of the original, of a legal reversal, or of \
         a transit towpath writes"
    )]
    ExtraLine {
        /// 1-based line in the optimized program.
        line: usize,
        /// Its text.
        text: String,
        /// Where it is.
        place: String,
    },
    /// A line the original keeps is gone.
    #[error("original line {line} ({text:?}) is missing from the optimized program")]
    LostLine {
        /// 1-based line in the original.
        line: usize,
        /// Its text.
        text: String,
    },
    /// A course is laid before a course it must follow.
    #[error("precedence broken: {after} is laid before {before}, which it overlaps and must follow")]
    Precedence {
        /// The course that must come first.
        before: String,
        /// The course that came too early.
        after: String,
    },
    /// A ply or within-ply order rule is broken.
    #[error("order broken: {0}")]
    Order(String),
}

/// Off-part and on-part motion of one program under one cost model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Motion {
    /// The cost model.
    pub kind: CostKind,
    /// Off-part motion attributed to each course (its transit in, approach and retract),
    /// indexed by the original course.
    pub off_course: Vec<f64>,
    /// Off-part motion of the header and footer.
    pub off_other: f64,
    /// On-part motion.
    pub on_part: f64,
}

impl Motion {
    /// Total off-part motion.
    pub fn off_part(&self) -> f64 {
        self.off_course.iter().sum::<f64>() + self.off_other
    }
    /// Off-part plus on-part motion.
    pub fn total(&self) -> f64 {
        self.off_part() + self.on_part
    }
}

/// A successful verification.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verification {
    /// Courses checked.
    pub courses: usize,
    /// Courses laid in reverse.
    pub reversed: usize,
    /// The optimized program's courses, as original courses.
    pub order: Vec<Placement>,
    /// True if precedence between plies was checked on footprints.
    pub precedence_checked: bool,
    /// True if every ply was checked to be finished before the next starts (which implies
    /// precedence between plies without footprints).
    pub ply_order_checked: bool,
    /// The course width of the footprints and where it came from.
    pub width: WidthUsed,
    /// Motion of the original, per cost model.
    pub before: Vec<Motion>,
    /// Motion of the optimized program, per cost model (courses indexed as in the original).
    pub after: Vec<Motion>,
}

impl Verification {
    /// The motion before and after under one cost model, if the machine supports it.
    pub fn motion(&self, kind: CostKind) -> Option<(&Motion, &Motion)> {
        let b = self.before.iter().find(|m| m.kind == kind)?;
        let a = self.after.iter().find(|m| m.kind == kind)?;
        Some((b, a))
    }
}

/// Verifies program text `optimized` against `original`.
pub fn verify(
    original: &str,
    optimized: &str,
    machine: &Machine,
    dialect: &Dialect,
    opts: &VerifyOptions,
) -> Result<Verification, VerifyError> {
    let orig = crate::parse::parse(original, machine, dialect).map_err(VerifyError::Original)?;
    let opt = crate::parse::parse(optimized, machine, dialect).map_err(VerifyError::Optimized)?;
    verify_parsed(&orig, &opt, machine, dialect, opts, None)
}

/// Verifies parsed programs; `fps` may pass the original's footprints if already built.
pub fn verify_parsed(
    orig: &Program,
    opt: &Program,
    machine: &Machine,
    dialect: &Dialect,
    opts: &VerifyOptions,
    fps: Option<&Footprints>,
) -> Result<Verification, VerifyError> {
    let k = orig.courses.len();
    if opt.courses.len() != k {
        return Err(VerifyError::CourseCount { got: opt.courses.len(), expected: k });
    }
    let tol = (0.5 * 10f64.powi(-(dialect.decimals as i32))).max(1e-6);
    crate::verify_lines::check_header_footer(orig, opt)?;
    let order = match_courses(orig, opt, machine, dialect, tol)?;
    // The moves of each course (reversed, the original's retract leads), for its lines.
    let windows: Vec<Option<std::ops::Range<usize>>> = order
        .iter()
        .enumerate()
        .map(|(kc, p)| {
            let a = span_motion(orig, p.course);
            if p.reversed {
                window_range(opt, kc, a.trail, a.lead)
            } else {
                window_range(opt, kc, a.lead, a.trail)
            }
        })
        .collect();
    crate::verify_lines::account(orig, opt, &order, &windows, dialect, machine)?;

    // Precedence.
    let plies_with_courses = orig.plies.iter().filter(|p| !p.courses.is_empty()).count();
    let mut precedence_checked = false;
    let width_used = WidthUsed::choose(opts.width, dialect, orig);
    // Ply after ply implies the course rule; without a width that is all there is to check.
    let by_ply_order_alone = opts.strict_plies && fps.is_none() && width_used.width.is_none();
    if plies_with_courses > 1 && !by_ply_order_alone {
        let width = width_used.width;
        let owned;
        let fps = match (fps, width) {
            (Some(f), _) => f,
            (None, Some(w)) => {
                owned = footprints(orig, machine, w).map_err(VerifyError::Setup)?;
                &owned
            }
            (None, None) => {
                let plies = orig.plies.iter().filter(|p| !p.courses.is_empty()).count();
                return Err(VerifyError::Setup(NcError::NeedsWidth { plies, checking: true }));
            }
        };
        check_precedence(orig, fps, &order)?;
        if opts.doherty_sets {
            check_sets(orig, fps, &order)?;
        }
        precedence_checked = true;
    }
    check_ply_order(orig, &order, opts)?;

    let mut inverse = vec![0usize; k];
    for (i, p) in order.iter().enumerate() {
        inverse[i] = p.course;
    }
    let identity: Vec<usize> = (0..k).collect();
    let before = measure(orig, machine, dialect, &identity, orig.header_end, orig.footer_start);
    // The optimized program starts with the original's header and ends with its footer.
    let footer_len = orig.lines.len() - orig.footer_start;
    let after = measure(opt, machine, dialect, &inverse, orig.header_end, opt.lines.len() - footer_len);
    Ok(Verification {
        courses: k,
        reversed: order.iter().filter(|p| p.reversed).count(),
        order,
        precedence_checked,
        ply_order_checked: opts.strict_plies,
        width: width_used,
        before,
        after,
    })
}

/// The order rules of the options: every ply laid after the one before (`strict_plies`), the
/// courses of each ply in their original order (`keep_ply_order`).
fn check_ply_order(orig: &Program, order: &[Placement], opts: &VerifyOptions) -> Result<(), VerifyError> {
    let mut pos = vec![0usize; orig.courses.len()];
    for (i, p) in order.iter().enumerate() {
        pos[p.course] = i;
    }
    if opts.strict_plies {
        for w in orig.plies.iter().filter(|p| !p.courses.is_empty()).collect::<Vec<_>>().windows(2) {
            let last_a = w[0].courses.iter().map(|&c| pos[c]).max().unwrap_or(0);
            let first_b = w[1].courses.iter().map(|&c| pos[c]).min().unwrap_or(0);
            if first_b < last_a {
                return Err(VerifyError::Order(format!(
                    "ply {:?} starts before ply {:?} is finished",
                    w[1].label, w[0].label
                )));
            }
        }
    }
    if opts.keep_ply_order {
        for p in &orig.plies {
            for w in p.courses.windows(2) {
                if pos[w[1]] < pos[w[0]] {
                    return Err(VerifyError::Order(format!(
                        "{} comes before {} within the ply",
                        orig.course_name(w[1]),
                        orig.course_name(w[0])
                    )));
                }
            }
        }
    }
    Ok(())
}

/// How a move is driven: a rapid at the axes' limits, or a feed move at its programmed feed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pace {
    /// A rapid move: it has no feed, whatever the modal feed.
    Rapid,
    /// A feed move at this feed (always a number: a feed move without a feed is refused by
    /// the interpreter, and feeds are > 0).
    Feed(f64),
}

impl Pace {
    /// The pace of a segment.
    fn of(s: &crate::program::Segment) -> Self {
        if s.rapid {
            Pace::Rapid
        } else {
            Pace::Feed(s.feed)
        }
    }

    /// The feed as a number for messages (NaN for a rapid).
    fn value(self) -> f64 {
        match self {
            Pace::Rapid => f64::NAN,
            Pace::Feed(f) => f,
        }
    }
}

impl std::fmt::Display for Pace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pace::Rapid => write!(f, "a rapid"),
            Pace::Feed(v) => write!(f, "feed {v}"),
        }
    }
}

/// One move of a span, as the verifier compares it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Move {
    /// The move lays material.
    on_part: bool,
    /// Tows on during the move.
    mask: u64,
    /// Rapid, or the feed.
    pace: Pace,
}

/// Consecutive moves of a program as points (physical values), with each move's contact,
/// tows and pace.
struct SpanMotion {
    points: Vec<Vec<f64>>,
    moves: Vec<Move>,
    /// Off-part moves before the first laid one (the approach).
    lead: usize,
    /// Off-part moves after the last laid one (the retract).
    trail: usize,
}

/// The position of program `p` just before its move `i` (after its last move if `i` is past
/// the end), as a point index.
fn point_before(p: &Program, i: usize) -> u32 {
    match p.segments.get(i) {
        Some(s) => s.from,
        None => (p.points.len() / p.dim.max(1)).saturating_sub(1) as u32,
    }
}

/// The moves `segs` of `p`, `lead` of them before the laying and `trail` after.
fn motion_of(p: &Program, segs: std::ops::Range<usize>, lead: usize, trail: usize) -> SpanMotion {
    let mut points = vec![p.point(point_before(p, segs.start)).to_vec()];
    let mut moves = Vec::with_capacity(segs.len());
    for s in &p.segments[segs] {
        points.push(p.point(s.to).to_vec());
        moves.push(Move { on_part: s.on_part, mask: s.mask, pace: Pace::of(s) });
    }
    SpanMotion { points, moves, lead, trail }
}

/// The moves of course `c` that lay material, as a range of `p.segments`: from its first laid
/// move to its last; for a course that lays nothing, an empty range where the roller comes
/// into contact.
fn laying(p: &Program, c: usize) -> std::ops::Range<usize> {
    let course = &p.courses[c];
    let segs = course.segments.clone();
    let first = segs.clone().find(|&i| p.segments[i].on_part);
    let last = segs.clone().rev().find(|&i| p.segments[i].on_part);
    if let (Some(f), Some(l)) = (first, last) {
        return f..l + 1;
    }
    // Nothing laid: the place where the roller comes into contact (after a move written on that
    // line, which comes before the contact when it is not laid). Reversed, the contact comes
    // where the original lifted, so the moves on either side swap as the blocks do.
    let at = segs.clone().find(|&i| p.segments[i].line as usize > course.on_part.start).unwrap_or(segs.end);
    at..at
}

/// The moves of course `c`'s span.
fn span_motion(p: &Program, c: usize) -> SpanMotion {
    let course = &p.courses[c];
    let (segs, laid) = (course.segments.clone(), laying(p, c));
    motion_of(p, segs.clone(), laid.start - segs.start, segs.end - laid.end)
}

/// The moves of optimized course `kc` to compare with an original course: its laying (see
/// [`laying`]) with the `lead` moves before it and the `trail` moves after, wherever reading
/// the optimized program put those. (Where an original approach or retract block is short,
/// because nothing moved before the course or one move joined two courses, the regenerated
/// transit, or the next course's approach, reads as part of it; such moves are off-part all the
/// same.) `None` if the program has not that many moves there.
fn window(p: &Program, kc: usize, lead: usize, trail: usize) -> Option<SpanMotion> {
    let range = window_range(p, kc, lead, trail)?;
    Some(motion_of(p, range, lead, trail))
}

/// The segment indices of [`window`].
fn window_range(p: &Program, kc: usize, lead: usize, trail: usize) -> Option<std::ops::Range<usize>> {
    let laid = laying(p, kc);
    let (lo, hi) = (laid.start.checked_sub(lead)?, laid.end + trail);
    (hi <= p.segments.len()).then_some(lo..hi)
}

/// The point where a course starts laying (forward) or ends laying, for finding candidates
/// (for a course that lays nothing, where its on-part block sits).
fn laying_point(p: &Program, c: usize, end: bool) -> &[f64] {
    let laid = laying(p, c);
    let at = match (laid.is_empty(), end) {
        (false, true) => p.segments[laid.end - 1].to,
        _ => point_before(p, laid.start),
    };
    p.point(at)
}

/// Checks that optimized course `kc` is original course `oc` laid forward.
fn is_forward(orig: &Program, oc: usize, opt: &Program, kc: usize, machine: &Machine, tol: f64) -> Result<(), String> {
    let a = span_motion(orig, oc);
    let Some(b) = window(opt, kc, a.lead, a.trail) else {
        return Err(format!("fewer than {} moves around its laid moves", a.lead + a.trail));
    };
    if a.moves.len() != b.moves.len() {
        return Err(format!("{} moves instead of {}", b.moves.len(), a.moves.len()));
    }
    for (i, (pa, pb)) in a.points.iter().zip(&b.points).enumerate() {
        for ax in 0..machine.dim() {
            if !same_value(machine, ax, pa[ax], pb[ax], 0.0, tol) {
                return Err(format!("point {i}: axis {} is {} instead of {}", machine.axes[ax].label, pb[ax], pa[ax]));
            }
        }
    }
    for (i, (ma, mb)) in a.moves.iter().zip(&b.moves).enumerate() {
        if ma.on_part != mb.on_part || ma.mask != mb.mask || (ma.on_part && ma.pace != mb.pace) {
            return Err(format!("move {i}: contact, tows or feed differ"));
        }
        // Approach and retract moves keep their motion code and feed too: a roller brought
        // down at a rapid is not the qualified program.
        if !ma.on_part && ma.pace != mb.pace {
            return Err(format!("move {i} (off-part): {} instead of {}", mb.pace, ma.pace));
        }
    }
    Ok(())
}

/// The motion code and feed each move of original course `c`'s span must have
/// when the course is laid reversed: the original retract, run backwards as the approach,
/// takes those of the original approach's last move, and the original approach, run
/// backwards as the retract, those of the original retract's first move; moves of the on-part
/// block keep their own.
fn reversed_paces(p: &Program, c: usize) -> Vec<Pace> {
    let course = &p.courses[c];
    let (start, end) = (course.on_part.start as u32, course.on_part.end as u32);
    let segs = &p.segments[course.segments.clone()];
    let last_approach = segs.iter().rev().find(|s| s.line < start).map(Pace::of);
    let first_retract = segs.iter().find(|s| s.line >= end).map(Pace::of);
    segs.iter()
        .map(|s| match (s.line < start, s.line >= end) {
            (true, _) => first_retract.unwrap_or(Pace::of(s)),
            (_, true) => last_approach.unwrap_or(Pace::of(s)),
            _ => Pace::of(s),
        })
        .collect()
}

/// Checks that optimized course `kc` is original course `oc` legally reversed.
fn is_reversal(
    orig: &Program,
    oc: usize,
    opt: &Program,
    kc: usize,
    machine: &Machine,
    dialect: &Dialect,
    tol: f64,
) -> Result<(), String> {
    let a = span_motion(orig, oc);
    // Reversed, the original's retract leads and its approach trails.
    let Some(b) = window(opt, kc, a.trail, a.lead) else {
        return Err(format!("fewer than {} moves around its laid moves", a.lead + a.trail));
    };
    let n = a.moves.len();
    if n != b.moves.len() {
        return Err(format!("{} moves instead of {}", b.moves.len(), n));
    }
    let expected = reversed_paces(orig, oc);
    let heading = machine.heading_axis();
    for i in 0..=n {
        let (pa, pb) = (&a.points[n - i], &b.points[i]);
        for ax in 0..machine.dim() {
            let turn = if Some(ax) == heading { 180.0 } else { 0.0 };
            if !same_value(machine, ax, pa[ax], pb[ax], turn, tol) {
                return Err(format!(
                    "reversed point {i}: axis {} is {} where the original's point {} has {}{}",
                    machine.axes[ax].label,
                    pb[ax],
                    n - i,
                    pa[ax],
                    if turn != 0.0 { " (±180)" } else { "" }
                ));
            }
        }
    }
    for i in 0..n {
        let (ma, mb) = (&a.moves[n - 1 - i], &b.moves[i]);
        if ma.on_part != mb.on_part {
            return Err(format!("reversed move {i}: roller contact differs from the original's move {}", n - 1 - i));
        }
        if ma.mask != mb.mask {
            return Err(format!(
                "reversed move {i}: tows on {} where the original's move {} has {} (restart and cut must swap at the same points)",
                mb.mask,
                n - 1 - i,
                ma.mask
            ));
        }
        if ma.on_part && ma.pace != mb.pace {
            return Err(format!("reversed move {i}: feed {} instead of {}", mb.pace.value(), ma.pace.value()));
        }
        if !ma.on_part && expected[n - 1 - i] != mb.pace {
            return Err(format!("reversed move {i} (off-part): {} instead of {}", mb.pace, expected[n - 1 - i]));
        }
    }
    let range = window_range(opt, kc, a.trail, a.lead).unwrap_or(0..0);
    crate::verify_lines::rewritten_lines(orig, oc, opt, kc, range, true, dialect, machine)
}

fn same_value(machine: &Machine, i: usize, a: f64, b: f64, turn: f64, tol: f64) -> bool {
    let d = b - a - turn;
    if machine.axes[i].kind.wraps() || turn != 0.0 {
        let r = d - 360.0 * (d / 360.0).round();
        r.abs() <= tol
    } else {
        d.abs() <= tol
    }
}

fn span_text(p: &Program, c: usize) -> String {
    let mut s = String::new();
    for l in &p.lines[p.courses[c].span.clone()] {
        s.push_str(l.trim_end_matches('\r'));
        s.push('\n');
    }
    s
}

/// Grid cell (0.5 mm or 0.5°) of the first two non-heading axes of a point, for finding
/// reversal candidates; angles modulo a turn.
fn point_cell(machine: &Machine, p: &[f64]) -> Vec<(i64, Option<i64>)> {
    let heading = machine.heading_axis();
    (0..machine.dim())
        .filter(|&i| Some(i) != heading)
        .take(2)
        .map(|i| {
            let v = (p[i] / 0.5).floor() as i64;
            if machine.axes[i].kind.wraps() {
                (v.rem_euclid(720), Some(720))
            } else {
                (v, None)
            }
        })
        .collect()
}

/// The cell and its neighbours.
fn neighbour_cells(cell: &[(i64, Option<i64>)]) -> Vec<Vec<i64>> {
    let mut out: Vec<Vec<i64>> = vec![Vec::new()];
    for &(v, period) in cell {
        let mut next = Vec::with_capacity(out.len() * 3);
        for base in &out {
            for d in -1..=1 {
                let x = match period {
                    Some(p) => (v + d).rem_euclid(p),
                    None => v + d,
                };
                let mut b = base.clone();
                b.push(x);
                next.push(b);
            }
        }
        out = next;
    }
    out.sort();
    out.dedup();
    out
}

/// A candidate for an optimized course: the original course and its direction, and whether
/// the span's lines are the same.
type Candidate = (Placement, bool);

/// Matches every course of `opt` to a course of `orig`: by identical span text and motion, else
/// by identical motion (written differently), else as a legal reversal. Returns the placements
/// and, per placement, whether its lines were written anew (reversed, or rewritten forward).
fn match_courses(
    orig: &Program,
    opt: &Program,
    machine: &Machine,
    dialect: &Dialect,
    tol: f64,
) -> Result<Vec<Placement>, VerifyError> {
    let m = Matcher { orig, opt, machine, dialect, tol, index: CourseIndex::new(orig, machine) };
    let k = orig.courses.len();
    // Greedy in program order; where a course finds every candidate taken (courses alike but
    // for their approach or retract), an augmenting path re-assigns earlier ones.
    let mut unused = vec![true; k];
    let mut a = Assignment { owner: vec![None; k], chosen: vec![None; k], all: HashMap::new() };
    for kc in 0..k {
        let (first, detail) = m.candidates(kc, Some(&unused));
        if let Some(&(p, text)) = first.first() {
            unused[p.course] = false;
            a.owner[p.course] = Some(kc);
            a.chosen[kc] = Some((p, text));
            continue;
        }
        let (list, _) = m.candidates(kc, None);
        if list.is_empty() {
            return Err(VerifyError::Unmatched { line: opt.courses[kc].on_part.start + 1, detail });
        }
        a.all.insert(kc, list);
        let mut seen = vec![false; k];
        if !a.augment(kc, &mut seen, &m) {
            return Err(VerifyError::Unmatched {
                line: opt.courses[kc].on_part.start + 1,
                detail: ": every course of the original it could be is laid elsewhere".into(),
            });
        }
        for (u, o) in unused.iter_mut().zip(&a.owner) {
            *u = o.is_none();
        }
    }
    let mut order = Vec::with_capacity(k);
    for c in a.chosen {
        let Some((p, _)) = c else {
            return Err(VerifyError::Missing(String::from("a course")));
        };
        order.push(p);
    }
    if let Some(c) = a.owner.iter().position(Option::is_none) {
        return Err(VerifyError::Missing(orig.course_name(c)));
    }
    Ok(order)
}

/// The original's courses indexed for matching: by span text, and by the grid cell where
/// their laying starts and ends.
struct CourseIndex {
    by_text: HashMap<String, Vec<usize>>,
    by_start: HashMap<Vec<i64>, Vec<usize>>,
    by_end: HashMap<Vec<i64>, Vec<usize>>,
    /// Moves each original course has around its laying (approach and retract).
    around: Vec<usize>,
}

impl CourseIndex {
    fn new(orig: &Program, machine: &Machine) -> Self {
        let k = orig.courses.len();
        let mut by_text: HashMap<String, Vec<usize>> = HashMap::new();
        for c in (0..k).rev() {
            by_text.entry(span_text(orig, c)).or_default().push(c);
        }
        let mut by_end: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
        let mut by_start: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
        for c in (0..k).rev() {
            // Keyed by where laying starts and ends: the approach and retract around it may have
            // taken in transit moves in the optimized program (see `window`).
            let key: Vec<i64> = point_cell(machine, laying_point(orig, c, true)).iter().map(|x| x.0).collect();
            by_end.entry(key).or_default().push(c);
            let key: Vec<i64> = point_cell(machine, laying_point(orig, c, false)).iter().map(|x| x.0).collect();
            by_start.entry(key).or_default().push(c);
        }
        let around = (0..k).map(|c| orig.courses[c].segments.len() - laying(orig, c).len()).collect();
        CourseIndex { by_text, by_start, by_end, around }
    }

    /// Candidates near a point, those with the most moves around their laying first: of two
    /// courses that lay the same, the one that also needs a retract (say) must take the
    /// optimized course that has it, leaving the other for one that may not.
    fn near(&self, map: &HashMap<Vec<i64>, Vec<usize>>, machine: &Machine, p: &[f64]) -> Vec<usize> {
        let mut v: Vec<usize> = neighbour_cells(&point_cell(machine, p))
            .iter()
            .filter_map(|key| map.get(key))
            .flat_map(|v| v.iter().copied())
            .collect();
        v.sort_unstable_by_key(|&c| (std::cmp::Reverse(self.around[c]), c));
        v.dedup();
        v
    }
}

/// What matching compares: the two programs and the index of the original's courses.
struct Matcher<'a> {
    orig: &'a Program,
    opt: &'a Program,
    machine: &'a Machine,
    dialect: &'a Dialect,
    tol: f64,
    index: CourseIndex,
}

/// Candidates found so far for one optimized course, and why the closest others failed.
struct Found<'u> {
    out: Vec<Candidate>,
    detail: String,
    /// With a mask of the original courses not yet taken, stops at the first such candidate.
    unused: Option<&'u [bool]>,
}

impl Found<'_> {
    fn takes(&self, oc: usize) -> bool {
        self.unused.is_none_or(|u| u[oc]) && !self.out.iter().any(|x| x.0.course == oc)
    }

    /// Adds a candidate; true when the search may stop.
    fn push(&mut self, c: Candidate) -> bool {
        self.out.push(c);
        self.unused.is_some()
    }
}

impl Matcher<'_> {
    /// Every original course that optimized course `kc` may be, in order of preference: same
    /// lines, then same motion forward, then a legal reversal. With `unused`, stops at the first
    /// candidate not yet taken. Each comes with "same lines" and, if there is none, why.
    fn candidates(&self, kc: usize, unused: Option<&[bool]>) -> (Vec<Candidate>, String) {
        let mut f = Found { out: Vec::new(), detail: String::new(), unused };
        if self.same_lines(kc, &mut f) || self.forward_near(kc, &mut f) {
            return (f.out, f.detail);
        }
        self.reversed_near(kc, &mut f);
        (f.out, f.detail)
    }

    /// Original courses with the same span text, laid forward.
    fn same_lines(&self, kc: usize, f: &mut Found) -> bool {
        let Some(cands) = self.index.by_text.get(&span_text(self.opt, kc)) else { return false };
        for &oc in cands.iter().rev() {
            if !f.takes(oc) {
                continue;
            }
            match is_forward(self.orig, oc, self.opt, kc, self.machine, self.tol) {
                Ok(()) => {
                    if f.push((Placement { course: oc, reversed: false }, true)) {
                        return true;
                    }
                }
                Err(e) => f.detail = format!(": same lines as {} but {e}", self.orig.course_name(oc)),
            }
        }
        false
    }

    /// Original courses that start laying where `kc` does, with the same motion forward.
    fn forward_near(&self, kc: usize, f: &mut Found) -> bool {
        let start = laying_point(self.opt, kc, false);
        for oc in self.index.near(&self.index.by_start, self.machine, start) {
            if !f.takes(oc) {
                continue;
            }
            match is_forward(self.orig, oc, self.opt, kc, self.machine, self.tol) {
                Ok(()) => {
                    if f.push((Placement { course: oc, reversed: false }, false)) {
                        return true;
                    }
                }
                // The first reason kept: the closest candidate, laid forward.
                Err(e) if f.detail.is_empty() => {
                    f.detail = format!(": not {} laid forward: {e}", self.orig.course_name(oc))
                }
                Err(_) => {}
            }
        }
        false
    }

    /// Original courses that stop laying where `kc` starts, legally reversed.
    fn reversed_near(&self, kc: usize, f: &mut Found) -> bool {
        let start = laying_point(self.opt, kc, false);
        let cands = self.index.near(&self.index.by_end, self.machine, start);
        if cands.is_empty() && f.detail.is_empty() && f.out.is_empty() {
            f.detail = ": no course of the original stops laying where it starts".into();
        }
        for oc in cands {
            if !f.takes(oc) {
                continue;
            }
            match is_reversal(self.orig, oc, self.opt, kc, self.machine, self.dialect, self.tol) {
                Ok(()) => {
                    if f.push((Placement { course: oc, reversed: true }, false)) {
                        return true;
                    }
                }
                Err(e) => f.detail = format!(": not a legal reversal of {}: {e}", self.orig.course_name(oc)),
            }
        }
        false
    }
}

/// The matching so far: which optimized course holds each original course, the candidate
/// each optimized course holds, and every candidate of the courses that needed more than the
/// first.
struct Assignment {
    owner: Vec<Option<usize>>,
    chosen: Vec<Option<Candidate>>,
    all: HashMap<usize, Vec<Candidate>>,
}

impl Assignment {
    /// Kuhn's augmenting path: gives optimized course `kc` one of its candidates, moving the
    /// courses that hold them to other candidates of theirs if need be.
    fn augment(&mut self, kc: usize, seen: &mut [bool], m: &Matcher) -> bool {
        let list = self.all.entry(kc).or_insert_with(|| m.candidates(kc, None).0).clone();
        for (p, text) in list {
            if std::mem::replace(&mut seen[p.course], true) {
                continue;
            }
            let free = match self.owner[p.course] {
                None => true,
                Some(other) => self.augment(other, seen, m),
            };
            if free {
                self.owner[p.course] = Some(kc);
                self.chosen[kc] = Some((p, text));
                return true;
            }
        }
        false
    }
}

/// Most (rectangle, cell) incidences the verifier's grids hold; their cells grow until the
/// footprints touch no more.
const MAX_GRID_HITS: u64 = 8_000_000;

/// Most grid entries the verifier's precedence checks compare before giving up.
const MAX_GRID_VISITS: u64 = 1_000_000_000;

/// The verifier's grid over the footprint frame: square cells of about eight median half
/// widths (larger if the footprints would touch too many), periodic rows on a mandrel.
struct CellGrid {
    cell: f64,
    hcell: f64,
    rows: Option<i64>,
}

impl CellGrid {
    fn new(fps: &Footprints) -> Self {
        let mut widths: Vec<f64> = fps.courses.iter().flat_map(|f| f.quads.iter().map(|q| q.hw)).collect();
        widths.sort_by(f64::total_cmp);
        let mut cell = widths.get(widths.len() / 2).map_or(10.0, |w| (8.0 * w).max(1e-2));
        loop {
            let g = CellGrid::sized(fps, cell);
            let mut hits = 0u64;
            for q in fps.courses.iter().flat_map(|f| f.quads.iter()) {
                let (i, j) = g.ranges(q);
                let n = (i.1 - i.0 + 1).max(1) as f64 * (j.1 - j.0 + 1).max(1) as f64;
                hits = hits.saturating_add(n.min(1e18) as u64);
                if hits > MAX_GRID_HITS {
                    break;
                }
            }
            if hits <= MAX_GRID_HITS || !cell.is_finite() {
                return g;
            }
            cell *= 2.0;
        }
    }

    fn sized(fps: &Footprints, cell: f64) -> Self {
        let period = fps.frame.period();
        let rows = period.map(|p| ((p / cell).ceil().max(1.0)) as i64);
        let hcell = match (period, rows) {
            (Some(p), Some(r)) => p / r as f64,
            _ => cell,
        };
        CellGrid { cell, hcell, rows }
    }

    /// The column and row ranges a rectangle's bounds cover.
    fn ranges(&self, q: &crate::footprint::Quad) -> ((i64, i64), (i64, i64)) {
        let (lo, hi) = q.bounds();
        (
            ((lo[0] / self.cell).floor() as i64, (hi[0] / self.cell).floor() as i64),
            ((lo[1] / self.hcell).floor() as i64, (hi[1] / self.hcell).floor() as i64),
        )
    }

    /// The keys of the cells a rectangle's bounds cover (rows wrapped on a mandrel).
    fn keys(&self, q: &crate::footprint::Quad) -> impl Iterator<Item = (i64, i64)> + '_ {
        let ((i0, i1), (j0, j1)) = self.ranges(q);
        let rows = self.rows;
        (i0..=i1).flat_map(move |i| {
            (j0..=j1).map(move |j| match rows {
                Some(r) => (i, j.rem_euclid(r)),
                None => (i, j),
            })
        })
    }
}

/// The error of a check that compared more than [`MAX_GRID_VISITS`] grid entries.
fn too_dense(what: &str) -> VerifyError {
    VerifyError::Setup(NcError::WorkLimit {
        what: what.into(),
        limit: MAX_GRID_VISITS,
        unit: "footprint comparisons".into(),
        advice: "the courses' footprints are piled up far more densely than on any real part; check the program and \
                 the course width"
            .into(),
    })
}

/// Sweeps the courses in their new order over a grid of the courses laid so far: a course
/// laid before an overlapping course of an earlier ply is a violation.
fn check_precedence(orig: &Program, fps: &Footprints, order: &[Placement]) -> Result<(), VerifyError> {
    let g = CellGrid::new(fps);
    // cell -> (max ply laid, entries (course, quad))
    type Cell = (usize, Vec<(u32, u32)>);
    let mut grid: HashMap<(i64, i64), Cell> = HashMap::new();
    let mut visits = 0u64;
    for p in order {
        let b = p.course;
        let pb = orig.courses[b].ply;
        for (qi, q) in fps.courses[b].quads.iter().enumerate() {
            for key in g.keys(q) {
                let entry = grid.entry(key).or_insert((0, Vec::new()));
                if entry.0 > pb {
                    visits += entry.1.len() as u64;
                    if visits > MAX_GRID_VISITS {
                        return Err(too_dense("checking precedence"));
                    }
                    for &(x, qx) in &entry.1 {
                        let px = orig.courses[x as usize].ply;
                        if px > pb
                            && crate::precedence::quads_overlap(
                                &fps.frame,
                                q,
                                &fps.courses[x as usize].quads[qx as usize],
                            )
                        {
                            return Err(VerifyError::Precedence {
                                before: orig.course_name(b),
                                after: orig.course_name(x as usize),
                            });
                        }
                    }
                }
                entry.0 = entry.0.max(pb);
                entry.1.push((b as u32, qi as u32));
            }
        }
    }
    Ok(())
}

/// Doherty et al.'s precedence sets, found here on their own: the plies in program order, each
/// joining the current set unless one of its courses overlaps a course already in it, else
/// starting the next set. Returns the set of each course (sets numbered from 0).
fn sets_of_courses(plies: &[Vec<usize>], fps: &Footprints) -> Result<Vec<usize>, VerifyError> {
    let g = CellGrid::new(fps);
    let mut set_of = vec![0usize; fps.courses.len()];
    let mut set = 0;
    // The current set's pieces, by cell.
    let mut grid: HashMap<(i64, i64), Vec<(usize, usize)>> = HashMap::new();
    let mut visits = 0u64;
    for ply in plies {
        let mut meets = false;
        'ply: for &c in ply {
            for q in &fps.courses[c].quads {
                for key in g.keys(q) {
                    let Some(v) = grid.get(&key) else { continue };
                    visits += v.len() as u64;
                    if visits > MAX_GRID_VISITS {
                        return Err(too_dense("finding Doherty et al.'s precedence sets"));
                    }
                    if v.iter()
                        .any(|&(x, qx)| crate::precedence::quads_overlap(&fps.frame, q, &fps.courses[x].quads[qx]))
                    {
                        meets = true;
                        break 'ply;
                    }
                }
            }
        }
        if meets {
            set += 1;
            grid.clear();
        }
        for &c in ply {
            set_of[c] = set;
            for (qi, q) in fps.courses[c].quads.iter().enumerate() {
                for key in g.keys(q) {
                    grid.entry(key).or_default().push((c, qi));
                }
            }
        }
    }
    Ok(set_of)
}

/// Every course of a Doherty et al.'s precedence set must be laid before any course of the next.
fn check_sets(orig: &Program, fps: &Footprints, order: &[Placement]) -> Result<(), VerifyError> {
    let plies: Vec<Vec<usize>> = orig.plies.iter().map(|p| p.courses.clone()).collect();
    let set_of = sets_of_courses(&plies, fps)?;
    let mut latest: Option<usize> = None;
    for p in order {
        if let Some(l) = latest {
            if set_of[p.course] < set_of[l] {
                return Err(VerifyError::Order(format!(
                    "{} (Doherty et al.'s precedence set {}) is laid after {} (set {}): each set must be finished before the next starts",
                    orig.course_name(p.course),
                    set_of[p.course] + 1,
                    orig.course_name(l),
                    set_of[l] + 1
                )));
            }
        }
        if latest.is_none_or(|l| set_of[p.course] >= set_of[l]) {
            latest = Some(p.course);
        }
    }
    Ok(())
}

/// Motion of a program under every cost model the machine supports; `course_of[c]` maps the
/// program's course c to the index it is reported under. Lines before `header_end` and from
/// `footer_start` count as header and footer. Under the time cost a rapid move takes the axes'
/// limits and a feed move its programmed feed (in the dialect's `feed_unit`, capped by the
/// limits; see [`Machine::feed_move_time`]).
pub fn measure(
    p: &Program,
    machine: &Machine,
    dialect: &Dialect,
    course_of: &[usize],
    header_end: usize,
    footer_start: usize,
) -> Vec<Motion> {
    let mut regions = p.regions();
    for (j, r) in regions.iter_mut().enumerate() {
        if j < header_end {
            *r = Region::Header;
        } else if j >= footer_start {
            *r = Region::Footer;
        }
    }
    let mut out = Vec::new();
    for kind in CostKind::ALL {
        let Ok(cost) = MachineCost::new(machine.clone(), kind, StateTable::new(machine.dim())) else {
            continue;
        };
        let mut m = Motion { kind, off_course: vec![0.0; p.courses.len()], off_other: 0.0, on_part: 0.0 };
        let mut d = vec![0.0; machine.dim()];
        for s in &p.segments {
            let (a, b) = (p.point(s.from), p.point(s.to));
            for i in 0..d.len() {
                d[i] = b[i] - a[i];
            }
            let feed = (!s.rapid).then(|| dialect.feed_per_second(s.feed));
            let c = cost.segment_at(a, b, &d, feed);
            if s.on_part {
                m.on_part += c;
                continue;
            }
            match regions[s.line as usize] {
                Region::Middle(k) | Region::Approach(k) | Region::OnPart(k) | Region::Retract(k) => {
                    m.off_course[course_of[k]] += c
                }
                Region::Header | Region::Footer => m.off_other += c,
            }
        }
        out.push(m);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::footprint::{Footprint, Frame, Quad};
    use proptest::prelude::*;

    fn band(a: [f64; 2], b: [f64; 2], w: f64) -> Footprint {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let q = Quad {
            c: [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0],
            u: [d[0] / len, d[1] / len],
            hl: len / 2.0,
            hw: w / 2.0 - 0.005,
        };
        Footprint { quads: vec![q], moves: vec![q], move_of: vec![0], paths: vec![vec![a, b]] }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// The verifier's own Doherty et al.'s precedence sets are the optimizer's (`precedence_sets`), found by
        /// other code.
        #[test]
        fn verifier_sets_agree_with_the_optimizer_s(
            seed in proptest::collection::vec((0.0f64..400.0, 0.0f64..400.0, 0.0f64..std::f64::consts::PI, 10.0f64..120.0, 4.0f64..30.0), 2..30),
            per_ply in 1usize..5,
        ) {
            let courses: Vec<Footprint> =
                seed.iter().map(|&(x, y, a, l, w)| band([x, y], [x + l * a.cos(), y + l * a.sin()], w)).collect();
            let n = courses.len();
            let plies: Vec<Vec<usize>> = (0..n).collect::<Vec<_>>().chunks(per_ply).map(|c| c.to_vec()).collect();
            let fps = Footprints { frame: Frame::Plan, courses };
            let mine = sets_of_courses(&plies, &fps).unwrap();
            let theirs = crate::precedence::precedence_sets(&fps, &plies).unwrap();
            let mut expect = vec![usize::MAX; n];
            for (s, ps) in theirs.iter().enumerate() {
                for &p in ps {
                    for &c in &plies[p] {
                        expect[c] = s;
                    }
                }
            }
            prop_assert_eq!(mine, expect);
        }
    }
}
