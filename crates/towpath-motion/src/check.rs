//! Move checking: the swept tool point and head of one move against the cell, and the move's
//! axis values against the travel limits.
//!
//! A move interpolates every axis linearly between two states ([`Rig::at`]); its path in the
//! part frame bends when rotary or mandrel axes move. The checker splits the parameter range
//! into pieces, bounds how far each piece's path can stray from its chord
//! ([`Rig::bend_bound`]: M·h²/8), and measures the exact distance from the chord (tool point)
//! or from the head's swept quadrilateral to every obstacle triangle under the cell's BVH.
//! The distance of a piece is therefore known to within an error that shrinks with the piece;
//! pieces are split until the answer is settled within the tolerance (branch and bound).

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use towpath_geom::DVec3;

use crate::cell::Cell;
use crate::rig::{Pose, Rig};

/// How moves are checked.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckOptions {
    /// The clearance, mm: a move whose tool point or head comes closer than this to an
    /// obstacle is a near miss (default 5).
    pub clearance: f64,
    /// The tolerance, mm (default 0.01): reported clearances are lower bounds at most this far
    /// below the true minimum, and a move that comes within it of an obstacle is a collision.
    pub tolerance: f64,
    /// Clearances are measured up to this distance, mm (default 10, twice the default
    /// clearance; never below the clearance): a move that stays farther from everything
    /// reports this value ("at least"). Measuring far clearances exactly costs more, as more
    /// of the mesh lies within reach.
    pub horizon: f64,
    /// On a move that starts or ends on the part, the stretch of this length (mm along the tool
    /// point's path) next to its on-part end is checked for collisions only (default 10).
    pub contact_zone: f64,
    /// ... and the last stretch of this length at the on-part end is not checked at all, so
    /// that a tool programmed into the surface (compaction) does not count (default 1).
    pub contact_skip: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions { clearance: 5.0, tolerance: 0.01, horizon: 10.0, contact_zone: 10.0, contact_skip: 1.0 }
    }
}

/// Which end of a move, if any, is on the part (in contact by design).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Contact {
    /// Neither: a transit, checked for the full clearance.
    None,
    /// The move starts on the part (a retract).
    Start,
    /// The move ends on the part (an approach or plunge).
    End,
}

/// Which body came closest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Body {
    /// The tool point.
    Tool,
    /// The head capsule.
    Head,
}

/// An axis value outside its travel limits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LimitViolation {
    /// The axis index.
    pub axis: usize,
    /// The axis label.
    pub label: String,
    /// The value (the worst one on the move; moves interpolate linearly, so it is an end's).
    pub value: f64,
    /// The lower limit, if any.
    pub min: Option<f64>,
    /// The upper limit, if any.
    pub max: Option<f64>,
}

/// The outcome of checking one move.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MoveCheck {
    /// The least distance of the tool point or head from any obstacle over the part of the
    /// move checked for clearance (outside contact zones), as a lower bound at most the
    /// tolerance below the truth, capped at the horizon; `None` when the whole move lies in
    /// contact zones.
    pub min_clearance: Option<f64>,
    /// Where that least distance was found: the move parameter t ∈ [0, 1] and the body.
    pub closest: Option<(f64, Body)>,
    /// The tool point or head touches or crosses an obstacle (comes within the tolerance),
    /// anywhere but in the skipped stretch at an on-part end.
    pub collision: bool,
    /// Not a collision, but closer than the clearance outside the contact zones.
    pub near_miss: bool,
    /// Axis values outside their travel limits.
    pub limits: Vec<LimitViolation>,
}

impl MoveCheck {
    /// True when the move has no collision, no near miss and no limit violation.
    pub fn is_clear(&self) -> bool {
        !self.collision && !self.near_miss && self.limits.is_empty()
    }
}

/// Checks moves of one machine (with its head) against one cell.
#[derive(Clone, Debug)]
pub struct Checker {
    cell: Arc<Cell>,
    rig: Arc<Rig>,
    opts: CheckOptions,
}

/// One move being checked.
struct Path<'a> {
    rig: &'a Rig,
    from: &'a [f64],
    deltas: Vec<f64>,
    bend: f64,
}

impl Path<'_> {
    fn pose(&self, t: f64, buf: &mut Vec<f64>) -> Pose {
        self.rig.at(self.from, &self.deltas, t, buf);
        self.rig.pose(buf)
    }
}

/// One piece of a move with its distance bounds.
#[derive(Clone, Copy, Debug)]
struct Piece {
    t0: f64,
    t1: f64,
    p0: Pose,
    p1: Pose,
    lb: f64,
    ub: f64,
    body: Body,
}

impl PartialEq for Piece {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Piece {}
impl PartialOrd for Piece {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Piece {
    /// Smallest lower bound first (as a max-heap), then earliest piece: a total order, so the
    /// search runs the same way every time.
    fn cmp(&self, o: &Self) -> Ordering {
        o.lb.total_cmp(&self.lb).then(o.t0.total_cmp(&self.t0))
    }
}

/// Lowers the running upper bound to a piece's, noting where it was found.
fn note(p: &Piece, upper: &mut f64, at: &mut Option<(f64, Body)>) {
    if p.ub < *upper {
        *upper = p.ub;
        *at = Some((0.5 * (p.t0 + p.t1), p.body));
    }
}

/// Pieces shorter than this (in the move parameter) are not split further.
const MIN_PIECE: f64 = 1e-9;

/// Most pieces a range is cut into before its first queries.
const MAX_FIRST_PIECES: f64 = 4096.0;

/// Cuts `[ta, tb]` into equal pieces whose chord error bound (bend·h²/8) is at most `limit`:
/// a piece whose chord may stray far from its path would be queried with a cap as wide as
/// that error, over every triangle within it (the whole mold under a long curved transit),
/// to be split anyway.
fn first_pieces(bend: f64, ta: f64, tb: f64, limit: f64) -> Vec<(f64, f64)> {
    let h = tb - ta;
    let n = if bend > 0.0 && limit > 0.0 {
        (h * (bend / (8.0 * limit)).sqrt()).ceil().clamp(1.0, MAX_FIRST_PIECES)
    } else {
        1.0
    };
    let n = n as usize;
    (0..n)
        .map(|k| (ta + h * k as f64 / n as f64, if k + 1 == n { tb } else { ta + h * (k + 1) as f64 / n as f64 }))
        .collect()
}

impl Checker {
    /// A checker of moves of `rig` against `cell`.
    pub fn new(cell: Arc<Cell>, rig: Arc<Rig>, opts: CheckOptions) -> Checker {
        let mut opts = opts;
        opts.horizon = opts.horizon.max(opts.clearance + opts.tolerance);
        Checker { cell, rig, opts }
    }

    /// The cell.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }

    /// The rig.
    pub fn rig(&self) -> &Rig {
        &self.rig
    }

    /// The options.
    pub fn options(&self) -> &CheckOptions {
        &self.opts
    }

    fn path<'a>(&'a self, from: &'a [f64], to: &[f64]) -> Path<'a> {
        let deltas = self.rig.deltas(from, to);
        let bend = self.rig.bend_bound(from, &deltas);
        Path { rig: &self.rig, from, deltas, bend }
    }

    /// Evaluates a piece: its distance bounds. The cell is queried only as far as can matter:
    /// a piece whose lower bound would reach `cap_lb` is not looked at beyond (its lower bound
    /// is then `cap_lb`). With `stop_ub`, a yes/no query: the search stops as soon as the upper
    /// bound falls to `stop_ub` (the lower bound is then not exact, but below `stop_ub` too).
    /// Without, a measurement: the cell is searched best first, to within a quarter of the
    /// tolerance (taken off the lower bound).
    fn piece(&self, bend: f64, t0: f64, t1: f64, p0: Pose, p1: Pose, cap_lb: f64, stop_ub: Option<f64>) -> Piece {
        let slack = if stop_ub.is_none() { 0.25 * self.opts.tolerance } else { 0.0 };
        let h = t1 - t0;
        let dev = bend * h * h / 8.0;
        let cap = cap_lb + dev + slack;
        let d = match stop_ub {
            Some(s) => self.cell.segment_distance(p0.tool, p1.tool, cap, s - dev),
            None => self.cell.segment_min(p0.tool, p1.tool, cap, slack),
        };
        // Nothing nearer than the cap: the lower bound is the cap itself (not a rounding below).
        let (mut lb, mut ub, mut body) = (if d >= cap { cap_lb } else { d - dev - slack }, d + dev, Body::Tool);
        if let Some(head) = self.rig.head() {
            // The head need not be looked at when the tool point already settles a yes/no
            // piece below `stop_ub` (a distance found, not the cap).
            let settled = stop_ub.is_some_and(|s| ub <= s && d < cap);
            if !settled {
                // The head's axis twists over the piece by e; the triangulated quadrilateral
                // is within |e|/4 of the swept (bilinear) surface, both ways.
                let e = ((p1.top - p1.bottom) - (p0.top - p0.bottom)).length();
                let herr = dev + e / 4.0;
                let r = head.radius;
                let cap = cap_lb + r + herr + slack;
                let dq = match stop_ub {
                    Some(s) => self.cell.quad_distance(p0.bottom, p0.top, p1.top, p1.bottom, cap, s + r - herr),
                    None => self.cell.quad_min(p0.bottom, p0.top, p1.top, p1.bottom, cap, slack),
                };
                let (hl, hu) = (if dq >= cap { cap_lb } else { dq - r - herr - slack }, dq - r + herr);
                if hu < ub {
                    body = Body::Head;
                }
                lb = lb.min(hl);
                ub = ub.min(hu);
            }
        }
        Piece { t0, t1, p0, p1, lb, ub, body }
    }

    /// True when the move's path over [ta, tb] keeps at least `c` from every obstacle, decided
    /// within the tolerance (an undecidable piece counts as not clear).
    fn clear_over(&self, path: &Path, ta: f64, tb: f64, c: f64) -> bool {
        if tb <= ta {
            return true;
        }
        let mut buf = Vec::with_capacity(self.rig.dim());
        let tol = self.opts.tolerance;
        let mut stack: Vec<(f64, f64, Pose, Pose)> = first_pieces(path.bend, ta, tb, c.max(tol))
            .into_iter()
            .rev()
            .map(|(t0, t1)| (t0, t1, path.pose(t0, &mut buf), path.pose(t1, &mut buf)))
            .collect();
        while let Some((t0, t1, p0, p1)) = stack.pop() {
            let p = self.piece(path.bend, t0, t1, p0, p1, c, Some(c));
            if p.lb >= c {
                continue;
            }
            if p.ub <= c || p.ub - p.lb <= tol || t1 - t0 < MIN_PIECE {
                return false;
            }
            let tm = 0.5 * (t0 + t1);
            let pm = path.pose(tm, &mut buf);
            stack.push((tm, t1, pm, p1));
            stack.push((t0, tm, p0, pm));
        }
        true
    }

    /// The least distance over [ta, tb] (lower bound within the tolerance, capped at the
    /// horizon) and where it was found.
    fn min_over(&self, path: &Path, ta: f64, tb: f64) -> (f64, Option<(f64, Body)>) {
        let tol = self.opts.tolerance;
        let horizon = self.opts.horizon;
        let mut buf = Vec::with_capacity(self.rig.dim());
        let mut upper = horizon;
        let mut at = None;
        let mut heap = BinaryHeap::new();
        for (t0, t1) in first_pieces(path.bend, ta, tb, horizon) {
            let (p0, p1) = (path.pose(t0, &mut buf), path.pose(t1, &mut buf));
            let first = self.piece(path.bend, t0, t1, p0, p1, upper, None);
            note(&first, &mut upper, &mut at);
            if first.lb < upper {
                heap.push(first);
            }
        }
        let mut resolved = f64::INFINITY;
        let lower = loop {
            if upper < tol {
                // A collision: the true minimum lies in [0, upper), so 0 is within tolerance.
                break 0.0;
            }
            let Some(p) = heap.pop() else { break resolved.min(upper) };
            if p.lb >= upper - tol {
                break p.lb.min(resolved);
            }
            if p.ub - p.lb <= tol || p.t1 - p.t0 < MIN_PIECE {
                resolved = resolved.min(p.lb);
                continue;
            }
            let tm = 0.5 * (p.t0 + p.t1);
            let pm = path.pose(tm, &mut buf);
            for (t0, t1, p0, p1) in [(p.t0, tm, p.p0, pm), (tm, p.t1, pm, p.p1)] {
                let c = self.piece(path.bend, t0, t1, p0, p1, upper, None);
                note(&c, &mut upper, &mut at);
                if c.lb < upper {
                    heap.push(c);
                }
            }
        };
        (lower.clamp(0.0, horizon), at)
    }

    /// The parameter at which the tool point has travelled `len` mm along its path from the
    /// start (`from_end`: from the end), measured on a 64-chord polyline.
    fn param_at_length(&self, path: &Path, len: f64, from_end: bool) -> f64 {
        const N: usize = 64;
        let mut buf = Vec::new();
        let pts: Vec<DVec3> = (0..=N)
            .map(|k| {
                let t = k as f64 / N as f64;
                path.pose(if from_end { 1.0 - t } else { t }, &mut buf).tool
            })
            .collect();
        let mut acc = 0.0;
        for k in 0..N {
            let l = pts[k].distance(pts[k + 1]);
            if acc + l >= len {
                let f = if l > 0.0 { (len - acc) / l } else { 0.0 };
                let t = (k as f64 + f) / N as f64;
                return if from_end { 1.0 - t } else { t };
            }
            acc += l;
        }
        if from_end {
            0.0
        } else {
            1.0
        }
    }

    /// The ranges of a move: (checked for clearance, checked for collision only) as parameter
    /// intervals.
    fn ranges(&self, path: &Path, contact: Contact) -> ((f64, f64), [(f64, f64); 1]) {
        let (zone, skip) = (self.opts.contact_zone.max(0.0), self.opts.contact_skip.max(0.0));
        match contact {
            Contact::None => ((0.0, 1.0), [(1.0, 1.0)]),
            Contact::End => {
                let tz = self.param_at_length(path, zone.max(skip), true);
                let ts = self.param_at_length(path, skip, true);
                ((0.0, tz), [(tz, ts)])
            }
            Contact::Start => {
                let tz = self.param_at_length(path, zone.max(skip), false);
                let ts = self.param_at_length(path, skip, false);
                ((tz, 1.0), [(ts, tz)])
            }
        }
    }

    /// The axis values of a move outside their travel limits. Axes interpolate linearly, so
    /// the worst value of each axis is at an end.
    pub fn limit_violations(&self, from: &[f64], to: &[f64]) -> Vec<LimitViolation> {
        let mut out = Vec::new();
        for (i, a) in self.rig.machine().axes.iter().enumerate() {
            let (Some(&x), Some(&y)) = (from.get(i), to.get(i)) else { continue };
            let below = a.min.filter(|m| x.min(y) < m - 1e-9).map(|_| x.min(y));
            let above = a.max.filter(|m| x.max(y) > m + 1e-9).map(|_| x.max(y));
            if let Some(value) = below.or(above) {
                out.push(LimitViolation { axis: i, label: a.label.clone(), value, min: a.min, max: a.max });
            }
        }
        out
    }

    /// Checks one move from state `from` to state `to` (the machine's axis values; wrapping
    /// axes go the short way round), `contact` saying which end is on the part. States must
    /// have one finite value per axis ([`Rig::check_state`]).
    pub fn check(&self, from: &[f64], to: &[f64], contact: Contact) -> MoveCheck {
        let path = self.path(from, to);
        let ((a, b), zones) = self.ranges(&path, contact);
        let tol = self.opts.tolerance;
        let (min_clearance, closest) = if b > a {
            let (m, at) = self.min_over(&path, a, b);
            (Some(m), at)
        } else {
            (None, None)
        };
        let mut collision = min_clearance.is_some_and(|m| m < tol);
        for &(za, zb) in &zones {
            if !collision && !self.clear_over(&path, za, zb, tol) {
                collision = true;
            }
        }
        let near_miss = !collision && min_clearance.is_some_and(|m| m < self.opts.clearance);
        MoveCheck { min_clearance, closest, collision, near_miss, limits: self.limit_violations(from, to) }
    }

    /// True when the move keeps the clearance plus the tolerance (and, in the contact zones of
    /// an on-part end, is free of collisions); quicker than [`Checker::check`], which also
    /// measures. A move it passes is clear by [`Checker::check`] too (the tolerance covers the
    /// measurement's error); one within the tolerance above the clearance may fail it. Limits
    /// are not looked at.
    pub fn is_clear(&self, from: &[f64], to: &[f64], contact: Contact) -> bool {
        let path = self.path(from, to);
        let ((a, b), zones) = self.ranges(&path, contact);
        self.clear_over(&path, a, b, self.opts.clearance + self.opts.tolerance)
            && zones.iter().all(|&(za, zb)| self.clear_over(&path, za, zb, self.opts.tolerance))
    }

    /// The least distance of the tool point or head from any obstacle at one state (capped at
    /// the horizon; exact up to rounding).
    pub fn state_clearance(&self, state: &[f64]) -> f64 {
        let p = self.rig.pose(state);
        self.piece(0.0, 0.0, 0.0, p, p, self.opts.horizon, None).lb.clamp(0.0, self.opts.horizon)
    }
}
