//! Motion safety of programs: every move of a program checked against the cell (the mold tool,
//! fixtures, stringers) and the machine's travel limits, and the transit planner the sequencer
//! and the writer share ([`towpath_motion`]; `docs/motion.md`).

use std::sync::Arc;

use serde::Serialize;
use towpath_machine::Machine;
use towpath_motion::{Cell, CheckOptions, Checker, Contact, LiftRule, PlanOptions, Planner, Rig};

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::program::Program;

/// Default clearance, mm: a move closer than this to the cell is a near miss.
pub const DEFAULT_CLEARANCE: f64 = 5.0;

/// Every laid tool point must lie within this distance of the cell, mm: the mold tool is
/// under the laid path (plies and compaction included), else it is the wrong mesh or in the
/// wrong units or frame.
pub const MOLD_GAP: f64 = 25.0;

/// The cell of a job and the rules moves are checked and transits planned by. Cheap to clone
/// (the cell and planner are shared).
#[derive(Clone, Debug)]
pub struct Safety {
    planner: Arc<Planner>,
}

/// How a [`Safety`] checks and plans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyOptions {
    /// Clearance, mm (default [`DEFAULT_CLEARANCE`]).
    pub clearance: f64,
    /// A lifted transit's level is the least that clears, to within this step, mm (default 1).
    pub step: f64,
}

impl Default for SafetyOptions {
    fn default() -> Self {
        SafetyOptions { clearance: DEFAULT_CLEARANCE, step: 1.0 }
    }
}

impl Safety {
    /// The safety of `machine` (with the machine file's `[head]`, if any) in `cell`. Transits
    /// lift along the dialect's clearance axis when it has one, else as
    /// [`LiftRule::Auto`] says (along Z, or radially on a mandrel machine).
    pub fn new(machine: &Machine, dialect: &Dialect, cell: Arc<Cell>, opts: SafetyOptions) -> Result<Safety, NcError> {
        if !(opts.clearance.is_finite() && opts.clearance > 0.0 && opts.clearance <= 1e4) {
            return Err(NcError::Request(format!(
                "clearance {} mm: expected a number > 0 and at most 10000",
                opts.clearance
            )));
        }
        if !(opts.step.is_finite() && opts.step > 0.0 && opts.step <= 1e4) {
            return Err(NcError::Request(format!(
                "lift step {} mm: expected a number > 0 and at most 10000",
                opts.step
            )));
        }
        let rig = Rig::new(machine, machine.head).map_err(|e| NcError::Machine(e.to_string()))?;
        let checks = CheckOptions {
            clearance: opts.clearance,
            horizon: CheckOptions::default().horizon.max(2.0 * opts.clearance),
            ..CheckOptions::default()
        };
        let checker = Checker::new(cell, Arc::new(rig), checks);
        let lift = match dialect.clearance_axis(machine)? {
            Some((axis, _)) => LiftRule::Axis(axis),
            None => LiftRule::Auto,
        };
        let planner = Planner::new(checker, PlanOptions { lift, step: opts.step })
            .map_err(|e| NcError::Machine(e.to_string()))?;
        Ok(Safety { planner: Arc::new(planner) })
    }

    /// The safety of `machine` in the cell made of `meshes` (each named, e.g. by its file, for
    /// messages). A mesh with an index out of range or a coordinate that is not finite, and a
    /// cell with no triangle at all, are refused.
    pub fn from_meshes(
        machine: &Machine,
        dialect: &Dialect,
        meshes: &[(String, towpath_geom::Soup)],
        opts: SafetyOptions,
    ) -> Result<Safety, NcError> {
        for (name, soup) in meshes {
            soup.validate().map_err(|e| NcError::Request(format!("{name}: {e}")))?;
        }
        let soups: Vec<towpath_geom::Soup> = meshes.iter().map(|(_, s)| s.clone()).collect();
        let cell = Cell::from_soups(&soups).map_err(|e| NcError::Request(e.to_string()))?;
        if cell.num_triangles() == 0 {
            let names: Vec<&str> = meshes.iter().map(|(n, _)| n.as_str()).collect();
            return Err(NcError::Request(if names.is_empty() {
                "no mesh given: the cell is empty".to_string()
            } else {
                format!("{}: no triangles: the cell is empty", names.join(", "))
            }));
        }
        Safety::new(machine, dialect, Arc::new(cell), opts)
    }

    /// The transit planner.
    pub fn planner(&self) -> &Arc<Planner> {
        &self.planner
    }

    /// The move checker.
    pub fn checker(&self) -> &Checker {
        self.planner.checker()
    }

    /// The clearance, mm.
    pub fn clearance(&self) -> f64 {
        self.checker().options().clearance
    }
}

/// What came too close on one move.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MoveIssue {
    /// 1-based line of the move.
    pub line: usize,
    /// The least clearance found on the move, mm (a lower bound within the checking tolerance).
    pub clearance: f64,
    /// Where: the tool point in the part frame at the closest place of the move.
    pub at: [f64; 3],
    /// The body that came closest: "tool" or "head".
    pub body: &'static str,
}

/// An axis value a program sets outside the machine's travel limits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LimitIssue {
    /// 1-based line.
    pub line: usize,
    /// The axis label.
    pub axis: String,
    /// The value.
    pub value: f64,
    /// The lower limit, if any.
    pub min: Option<f64>,
    /// The upper limit, if any.
    pub max: Option<f64>,
}

/// The motion safety of one program.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SafetyReport {
    /// Moves checked against the cell (every move outside roller contact).
    pub moves_checked: usize,
    /// The least clearance of any checked move, mm (capped at the checking horizon: a program
    /// farther than that from everything reports the horizon), and its 1-based line.
    pub min_clearance: Option<(f64, usize)>,
    /// Moves whose tool point or head touches or crosses the cell.
    pub collisions: Vec<MoveIssue>,
    /// Moves closer than the clearance, without touching.
    pub near_misses: Vec<MoveIssue>,
    /// Axis values outside the travel limits (every move, on the part too).
    pub limit_violations: Vec<LimitIssue>,
    /// The clearance checked, mm.
    pub clearance: f64,
    /// Clearances are measured up to this distance, mm.
    pub horizon: f64,
}

impl SafetyReport {
    /// True when nothing collides and no axis leaves its limits (near misses allowed).
    pub fn is_safe(&self) -> bool {
        self.collisions.is_empty() && self.limit_violations.is_empty()
    }

    /// One line for people: counts and the worst clearance with its line.
    pub fn summary(&self) -> String {
        let worst = match self.min_clearance {
            Some((c, line)) if c >= self.horizon => {
                format!("least clearance at least {:.0} mm (line {line})", self.horizon)
            }
            Some((c, line)) => format!("least clearance {c:.2} mm (line {line})"),
            None => "no move checked".into(),
        };
        format!(
            "{} collision{}, {} near miss{} (< {} mm), {} limit violation{}; {worst}; {} moves checked",
            self.collisions.len(),
            plural(self.collisions.len()),
            self.near_misses.len(),
            if self.near_misses.len() == 1 { "" } else { "es" },
            self.clearance,
            self.limit_violations.len(),
            plural(self.limit_violations.len()),
            self.moves_checked,
        )
    }

    /// The first problems, one per line, for an error message or a report (at most `n` of
    /// each kind).
    pub fn details(&self, n: usize) -> Vec<String> {
        let mut out = Vec::new();
        for c in self.collisions.iter().take(n) {
            out.push(format!(
                "line {}: collision: the {} comes within {:.2} mm of the cell near ({:.1}, {:.1}, {:.1})",
                c.line, c.body, c.clearance, c.at[0], c.at[1], c.at[2]
            ));
        }
        for l in self.limit_violations.iter().take(n) {
            let lim = |v: Option<f64>| v.map_or_else(|| "none".to_string(), |v| v.to_string());
            out.push(format!(
                "line {}: axis {} at {} is outside its travel limits [{}, {}]",
                l.line,
                l.axis,
                l.value,
                lim(l.min),
                lim(l.max)
            ));
        }
        for c in self.near_misses.iter().take(n) {
            out.push(format!(
                "line {}: near miss: the {} passes {:.2} mm from the cell (clearance {} mm) near ({:.1}, {:.1}, {:.1})",
                c.line, c.body, c.clearance, self.clearance, c.at[0], c.at[1], c.at[2]
            ));
        }
        out
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// Checks every move of `program`: moves outside roller contact against the cell (a move that
/// leads onto or off the part, or to or from a state itself closer than the clearance, counts
/// only collisions near that end, as `docs/motion.md` says), and every move against the travel
/// limits. The first move, from the machine's home state before the program writes any axis,
/// is not checked against the cell: where the machine really starts is not known.
pub fn check_program(program: &Program, safety: &Safety) -> SafetyReport {
    use rayon::prelude::*;
    let checker = safety.checker();
    let clearance = safety.clearance();
    let segs = &program.segments;
    let rig = checker.rig();
    let per_move: Vec<Option<towpath_motion::MoveCheck>> = segs
        .par_iter()
        .enumerate()
        .map(|(i, s)| {
            let (from, to) = (program.point(s.from), program.point(s.to));
            if s.on_part || s.from == 0 || rig.check_state(from).is_err() || rig.check_state(to).is_err() {
                return None;
            }
            let next_on = segs.get(i + 1).is_some_and(|n| n.on_part && n.from == s.to);
            let prev_on = i > 0 && segs[i - 1].on_part && segs[i - 1].to == s.from;
            let contact = if prev_on || checker.state_clearance(from) < clearance {
                Contact::Start
            } else if next_on || checker.state_clearance(to) < clearance {
                Contact::End
            } else {
                Contact::None
            };
            Some(checker.check(from, to, contact))
        })
        .collect();
    let mut report = SafetyReport {
        clearance,
        horizon: checker.options().horizon,
        limit_violations: limit_violations(program, rig.machine()),
        ..SafetyReport::default()
    };
    for (s, check) in segs.iter().zip(per_move) {
        let line = s.line as usize + 1;
        let Some(c) = check else { continue };
        report.moves_checked += 1;
        let (from, to) = (program.point(s.from), program.point(s.to));
        if let Some(m) = c.min_clearance {
            if report.min_clearance.is_none_or(|(w, _)| m < w) {
                report.min_clearance = Some((m, line));
            }
        }
        if c.collision || c.near_miss {
            let (t, body) = c.closest.unwrap_or((0.0, towpath_motion::Body::Tool));
            // The checker stops as soon as a move is known to collide, so the place it found
            // need not be the deepest; the closest of 65 samples (and the checker's) marks it.
            let deltas = rig.deltas(from, to);
            let mut state = Vec::new();
            let mut best = (f64::INFINITY, t);
            for k in (0..=64).map(|k| k as f64 / 64.0).chain([t]) {
                rig.at(from, &deltas, k, &mut state);
                let d = checker.state_clearance(&state);
                if d < best.0 {
                    best = (d, k);
                }
            }
            rig.at(from, &deltas, best.1, &mut state);
            let p = rig.pose(&state).tool;
            let issue = MoveIssue {
                line,
                clearance: c.min_clearance.unwrap_or(0.0).max(0.0),
                at: [p.x, p.y, p.z],
                body: match body {
                    towpath_motion::Body::Tool => "tool",
                    towpath_motion::Body::Head => "head",
                },
            };
            let list = if c.collision { &mut report.collisions } else { &mut report.near_misses };
            if list.last().is_none_or(|x| x.line != line) {
                list.push(issue);
            } else if let Some(last) = list.last_mut() {
                if issue.clearance < last.clearance {
                    *last = issue;
                }
            }
        }
    }
    report
}

/// The axis values `program` sets outside the machine's travel limits (`min`/`max`), one per
/// line and axis, the worst value of the line. Every point of every move counts (axes move
/// linearly between them), the machine's home state before the program writes an axis not.
pub fn limit_violations(program: &Program, machine: &Machine) -> Vec<LimitIssue> {
    let mut out: Vec<LimitIssue> = Vec::new();
    for s in &program.segments {
        let line = s.line as usize + 1;
        let ends: &[u32] = if s.from == 0 { &[s.to] } else { &[s.from, s.to] };
        for &p in ends {
            for (a, &v) in machine.axes.iter().zip(program.point(p)) {
                let outside = a.min.is_some_and(|m| v < m - 1e-9) || a.max.is_some_and(|m| v > m + 1e-9);
                if !outside {
                    continue;
                }
                match out.iter_mut().find(|x| x.line == line && x.axis == a.label) {
                    Some(x) => {
                        let excess = |v: f64| (a.min.map_or(0.0, |m| m - v)).max(a.max.map_or(0.0, |m| v - m));
                        if excess(v) > excess(x.value) {
                            x.value = v;
                        }
                    }
                    None => out.push(LimitIssue { line, axis: a.label.clone(), value: v, min: a.min, max: a.max }),
                }
            }
        }
    }
    out
}

/// Refuses a set-up the checks would be meaningless in: laid points on (within
/// [`MIN_MANDREL_RADIUS`] of) a mandrel's axis, or a cell that does not lie under the program's
/// laid path (wrong mesh, units or frame): every laid tool point must be within `max_gap` mm of
/// some obstacle triangle.
pub fn check_cell_under_path(
    program: &Program,
    machine: &Machine,
    safety: &Safety,
    max_gap: f64,
) -> Result<(), NcError> {
    let Some(points) = program.part_points(machine) else { return Ok(()) };
    let laid: Vec<[f64; 3]> = program
        .segments
        .iter()
        .filter(|s| s.on_part)
        .flat_map(|s| [points[s.from as usize], points[s.to as usize]])
        .collect();
    towpath_motion::check_mandrel_radius(safety.checker().rig(), &laid, MIN_MANDREL_RADIUS)
        .map_err(|e| NcError::Request(e.to_string()))?;
    towpath_motion::check_laid_points(safety.checker().cell(), &laid, max_gap)
        .map_err(|e| NcError::Request(e.to_string()))
}

/// Laid points closer than this to a mandrel's axis are refused, mm: a course cannot be laid
/// there, and angles round the mandrel mean nothing.
pub const MIN_MANDREL_RADIUS: f64 = 1.0;

/// Refuses a program that lays a course outside the travel limits, naming the course and line.
pub fn check_courses_within_limits(program: &Program, machine: &Machine) -> Result<(), NcError> {
    let outside = limit_violations(program, machine);
    for (c, course) in program.courses.iter().enumerate() {
        if let Some(l) = outside.iter().find(|l| course.on_part.contains(&(l.line - 1))) {
            let lim = |v: Option<f64>| v.map_or_else(|| "none".to_string(), |v| v.to_string());
            return Err(NcError::Line {
                line: l.line,
                message: format!(
                    "{} is laid outside the travel limits: axis {} at {} is outside [{}, {}]",
                    program.course_name(c),
                    l.axis,
                    l.value,
                    lim(l.min),
                    lim(l.max)
                ),
            });
        }
    }
    Ok(())
}
