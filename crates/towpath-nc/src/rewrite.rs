//! The rewriter: a program in a new course order, with only the off-part transit regenerated.
//!
//! Header, footer, every course span (approach, on-part and retract blocks) and every other line
//! are copied byte for byte; a reversed course's span is the one [`crate::reverse_course`] builds.
//! Between two spans the rewriter writes one rapid move (or, with a clearance in the dialect,
//! three: to the clearance, across, and down) that takes the machine from the end of
//! the first to exactly the state (programmed values, set-position offsets, distance mode,
//! motion mode, feed) in which the original program entered the second, so the second runs
//! exactly as it did. Continuous and mandrel axes move the short way round; when that leaves a
//! programmed value that differs from the original by whole turns, a set-position line
//! re-declares the original value. Each ply comment moves to where its ply first starts and is
//! repeated where the ply starts again. In the original order the output is the input, unchanged.

use towpath_machine::Machine;

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::interp::{wrap, ArcDir, Interp, Modal, MotionMode};
use crate::program::{join_lines, Item, Program};
use crate::reverse::{fmt_num, shift_decimal, Reversed};
use towpath_motion::Planner;

/// One course in the new order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Placement {
    /// The course (index into [`Program::courses`]).
    pub course: usize,
    /// Laid in reverse.
    pub reversed: bool,
}

/// Writes the program with its courses in `order`. `reversed[c]` must hold the reversed span of
/// every course placed reversed.
pub fn rewrite(
    program: &Program,
    order: &[Placement],
    machine: &Machine,
    dialect: &Dialect,
    reversed: &[Option<Reversed>],
) -> Result<String, NcError> {
    rewrite_with(program, order, machine, dialect, reversed, None)
}

/// As [`rewrite`]; with a `planner`, every transit between courses is the planned one (straight
/// where that keeps the clearance, else up, across and down at the least level that clears),
/// also when the order is the original's, and a transit with no safe plan is refused.
pub fn rewrite_with(
    program: &Program,
    order: &[Placement],
    machine: &Machine,
    dialect: &Dialect,
    reversed: &[Option<Reversed>],
    planner: Option<&Planner>,
) -> Result<String, NcError> {
    let k = program.courses.len();
    if order.len() != k {
        return Err(NcError::Request(format!("the order has {} courses, the program {k}", order.len())));
    }
    let mut seen = vec![false; k];
    for p in order {
        if p.course >= k || std::mem::replace(&mut seen[p.course], true) {
            return Err(NcError::Request(format!("course {} is missing or repeated in the order", p.course)));
        }
    }
    if planner.is_none() && order.iter().enumerate().all(|(i, p)| p.course == i && !p.reversed) {
        return Ok(program.text());
    }
    // Write the reversed spans that are needed and not written yet.
    let written: Vec<(usize, Reversed)> = {
        use rayon::prelude::*;
        order
            .par_iter()
            .filter(|p| {
                p.reversed && reversed.get(p.course).and_then(Option::as_ref).is_some_and(|r| r.lines.is_empty())
            })
            .map(|p| {
                crate::reverse::reverse_course(program, p.course, machine, dialect).map(|r| (p.course, r)).map_err(
                    |why| NcError::Request(format!("{} cannot be reversed: {why}", program.course_name(p.course))),
                )
            })
            .collect::<Result<_, _>>()?
    };
    let mut fresh: Vec<Option<&Reversed>> = vec![None; k];
    for (c, r) in &written {
        fresh[*c] = Some(r);
    }
    let crlf = program.lines.iter().filter(|l| l.ends_with('\r')).count() * 2 > program.lines.len();
    let mut e = Emitter {
        moved: Vec::new(),
        marker_of_line: Vec::new(),
        out: Vec::with_capacity(program.lines.len() + 2 * k),
        it: Interp::new(dialect, machine)?,
        dialect,
        machine,
        crlf,
        clearance: dialect.clearance_axis(machine)?,
        planner,
    };
    for j in 0..program.header_end {
        e.original(program, j)?;
    }
    let mut prev: Option<usize> = None;
    // Ply comments: each moves to where its ply first starts and is repeated where the ply
    // starts again, so the output reads ply by ply and, read again, divides into plies that
    // agree with its order.
    let mut marker_of_line: Vec<Option<usize>> = vec![None; program.lines.len()];
    for (x, ply) in program.plies.iter().enumerate() {
        if let Some(j) = ply.line {
            marker_of_line[j] = Some(x);
        }
    }
    e.moved = vec![false; program.plies.len()];
    e.marker_of_line = marker_of_line;
    for p in order {
        let course = &program.courses[p.course];
        if let Some(pc) = prev {
            e.items(program, &program.courses[pc].post)?;
        }
        let prev_ply = prev.map(|pc| program.courses[pc].ply);
        if prev_ply != Some(course.ply) {
            let ply = &program.plies[course.ply];
            match ply.line {
                Some(j) if !e.moved[course.ply] => {
                    e.moved[course.ply] = true;
                    e.original(program, j)?;
                }
                Some(j) => e.generated(program.lines[j].trim_end_matches('\r').to_string())?,
                None if prev_ply.is_some() => e.generated(
                    dialect.comment(&format!("{} 0 (courses before the first ply comment)", dialect.ply_comment)),
                )?,
                None => {}
            }
        }
        e.items(program, &course.pre_before)?;
        let rev = if p.reversed {
            match fresh[p.course].or_else(|| reversed.get(p.course).and_then(Option::as_ref)) {
                Some(r) => Some(r),
                None => return Err(NcError::Request(format!("{} cannot be reversed", program.course_name(p.course)))),
            }
        } else {
            None
        };
        match rev {
            None => {
                // The lines after the original transit run after the new one, as they did.
                e.transit(&course.insert)?;
                e.items(program, &course.pre_after)?;
            }
            Some(r) => {
                // The reversed span needs exactly its entry state: the lines that followed the
                // original transit (which may set positions or modes) go before the new one.
                e.items(program, &course.pre_after)?;
                e.transit(&r.entry)?;
            }
        }
        match rev {
            Some(r) => {
                for l in &r.lines {
                    e.generated(l.clone())?;
                }
            }
            None => {
                // The span runs exactly as in the original (the transit restored its entry
                // state), so its lines are copied and the machine state after it is the
                // original's, with continuous axes as many turns apart as they were before it.
                let shift: Vec<f64> = (0..machine.dim()).map(|i| e.it.m.phys[i] - course.span_start.phys[i]).collect();
                for j in course.span.clone() {
                    e.out.push(program.lines[j].clone());
                }
                e.it.m = course.exit.clone();
                for (i, d) in shift.iter().enumerate() {
                    e.it.m.phys[i] += d;
                }
            }
        }
        prev = Some(p.course);
    }
    if let Some(pc) = prev {
        e.items(program, &program.courses[pc].post)?;
    }
    for j in program.footer_start..program.lines.len() {
        e.original(program, j)?;
    }
    Ok(join_lines(e.out.iter().map(String::as_str), program.final_newline, program.breaks))
}

struct Emitter<'a> {
    /// Ply comments already written at the start of their ply.
    moved: Vec<bool>,
    /// The ply whose comment each line is, if any.
    marker_of_line: Vec<Option<usize>>,
    out: Vec<String>,
    it: Interp<'a>,
    dialect: &'a Dialect,
    machine: &'a Machine,
    crlf: bool,
    /// Transits go by way of this value of this axis.
    clearance: Option<(usize, f64)>,
    /// Transits are planned against the cell (the clearance above is then not used).
    planner: Option<&'a Planner>,
}

impl Emitter<'_> {
    fn original(&mut self, program: &Program, j: usize) -> Result<(), NcError> {
        let line = &program.lines[j];
        self.it.apply(j, line).map_err(|err| NcError::SelfCheck(format!("replaying original {err}")))?;
        self.out.push(line.clone());
        Ok(())
    }

    fn generated(&mut self, mut line: String) -> Result<(), NcError> {
        let n = self.out.len();
        self.it
            .apply(n, &line)
            .map_err(|err| NcError::SelfCheck(format!("a line towpath wrote ({line:?}) does not run: {err}")))?;
        if self.crlf {
            line.push('\r');
        }
        self.out.push(line);
        Ok(())
    }

    fn items(&mut self, program: &Program, items: &[Item]) -> Result<(), NcError> {
        for item in items {
            match item {
                Item::Line(j) => {
                    // A ply comment written at the start of its ply is not written again.
                    match self.marker_of_line.get(*j).copied().flatten() {
                        Some(x) if self.moved.get(x).copied().unwrap_or(false) => {}
                        _ => self.original(program, *j)?,
                    }
                }
                Item::Kept(_, text) => self.generated(text.clone())?,
            }
        }
        Ok(())
    }

    /// The transit to `target`: one rapid move, or with a clearance in the dialect, when an
    /// axis other than the clearance axis moves, three (to the clearance, across, and to the
    /// target's value); then set-position and mode lines if needed.
    fn transit(&mut self, target: &Modal) -> Result<(), NcError> {
        if let Some(planner) = self.planner {
            let cur = self.it.m.clone();
            let plan = planner
                .plan(&cur.phys, &target.phys)
                .map_err(|e| NcError::Unsafe(format!("no safe transit to line {} ({e})", self.out.len() + 1)))?;
            let n = plan.waypoints.len();
            for w in plan.waypoints.iter().take(n.saturating_sub(1)) {
                // An intermediate state: each axis moved from where it is now, the short way
                // for wrapping axes (as `move_to` moves them), so no set-position is needed.
                let now = self.it.m.clone();
                let mut via = now.clone();
                for (i, &v) in w.iter().enumerate() {
                    let d = v - now.phys[i];
                    let d = if self.machine.axes[i].kind.wraps() { wrap(d) } else { d };
                    if d.abs() > 1e-9 {
                        via.prog[i] = now.prog[i] + d;
                        via.phys[i] = now.phys[i] + d;
                        via.text[i] = None;
                    }
                }
                self.move_to(&via)?;
            }
            self.move_to(target)?;
            return self.restore_modes(target);
        }
        if let Some((z, h)) = self.clearance {
            let cur = self.it.m.clone();
            let m = self.machine;
            let others_move = (0..m.dim()).any(|i| {
                let d = target.phys[i] - cur.phys[i];
                i != z && (if m.axes[i].kind.wraps() { wrap(d) } else { d }).abs() > 1e-9
            });
            if others_move {
                if (cur.phys[z] - h).abs() > 1e-9 {
                    let mut up = cur.clone();
                    up.prog[z] = cur.prog[z] + (h - cur.phys[z]);
                    up.phys[z] = h;
                    up.text[z] = None;
                    self.move_to(&up)?;
                }
                let now = self.it.m.clone();
                let mut across = target.clone();
                across.prog[z] = now.prog[z];
                across.phys[z] = now.phys[z];
                across.text[z] = now.text[z];
                self.move_to(&across)?;
            }
        }
        self.move_to(target)?;
        self.restore_modes(target)
    }

    /// One rapid move (and set-position lines if needed) to the axis values of `target`.
    fn move_to(&mut self, target: &Modal) -> Result<(), NcError> {
        let d = self.dialect;
        let m = self.machine;
        let cur = self.it.m.clone();
        let dim = m.dim();
        let text_of = |t: &Modal, i: usize| t.text[i].map_or_else(|| fmt_num(t.prog[i], d.decimals), |x| x.to_string());
        let label = |i: usize| m.axes[i].label.to_ascii_uppercase();
        let mut axis_words = Vec::new();
        let mut reset = Vec::new();
        for i in 0..dim {
            let wraps = m.axes[i].kind.wraps();
            let delta = if wraps { wrap(target.phys[i] - cur.phys[i]) } else { target.phys[i] - cur.phys[i] };
            let same_prog = (cur.prog[i] - target.prog[i]).abs() <= 1e-9;
            if delta.abs() <= 1e-9 {
                if !same_prog {
                    reset.push(format!("{}{}", label(i), text_of(target, i)));
                }
                continue;
            }
            // The value that moves the axis by `delta`.
            let (written, needs_reset) = if d.rollover && wraps {
                if (wrap(target.prog[i] - cur.prog[i]) - delta).abs() <= 1e-9 {
                    (text_of(target, i), false)
                } else {
                    (fmt_num(cur.prog[i] + delta, d.decimals), true)
                }
            } else {
                // Writing the target value itself is best when that is a short-way move that
                // leaves the axis where the original had it (modulo whole turns).
                let literal = target.prog[i] - cur.prog[i];
                let lands = (wrap(cur.phys[i] + literal - target.phys[i])).abs() <= 1e-9;
                let v =
                    if wraps && literal.abs() <= 180.0 + 1e-9 && lands { target.prog[i] } else { cur.prog[i] + delta };
                if (v - target.prog[i]).abs() <= 1e-9 {
                    (text_of(target, i), false)
                } else {
                    let turns = ((v - target.prog[i]) / 360.0).round();
                    let exact = if wraps && (v - target.prog[i] - 360.0 * turns).abs() <= 1e-6 {
                        shift_decimal(&text_of(target, i), 360.0 * turns)
                    } else {
                        None
                    };
                    (exact.unwrap_or_else(|| fmt_num(v, d.decimals)), true)
                }
            };
            axis_words.push(format!("{}{}", label(i), written));
            if needs_reset {
                reset.push(format!("{}{}", label(i), text_of(target, i)));
            }
        }
        if !axis_words.is_empty() {
            let mut words = Vec::new();
            if cur.incremental {
                words.push(d.absolute.clone());
            }
            words.push(d.rapid.first().cloned().unwrap_or_else(|| "G0".into()));
            words.extend(axis_words);
            self.generated(words.join(" "))?;
        }
        if !reset.is_empty() {
            let mut words = vec![d.set_position.clone()];
            words.extend(reset);
            self.generated(words.join(" "))?;
        }
        Ok(())
    }

    /// A line restoring the distance mode, motion mode, arc plane and feed of `target`, if
    /// they differ.
    fn restore_modes(&mut self, target: &Modal) -> Result<(), NcError> {
        let d = self.dialect;
        let now = self.it.m.clone();
        let mut modal = Vec::new();
        if now.incremental != target.incremental {
            modal.push(if target.incremental { d.incremental.clone() } else { d.absolute.clone() });
        }
        if let Some(mode) = target.motion {
            if now.motion != Some(mode) {
                let code = match mode {
                    MotionMode::Arc(ArcDir::Cw) => d.arc_cw.first(),
                    MotionMode::Arc(ArcDir::Ccw) => d.arc_ccw.first(),
                    MotionMode::Rapid => d.rapid.first(),
                    MotionMode::Linear => d.feed.first(),
                };
                modal.push(code.cloned().unwrap_or_default());
            }
        }
        if now.plane != target.plane {
            modal.push(d.arc_planes.get(target.plane.index()).cloned().unwrap_or_default());
        }
        if let Some((v, t)) = &target.feed {
            if now.feed.as_ref().map(|f| f.0) != Some(*v) {
                modal.push(format!("{}{}", d.feed_word.to_ascii_uppercase(), t));
            }
        }
        if !modal.is_empty() {
            self.generated(modal.join(" "))?;
        }
        Ok(())
    }
}
