//! The sequencing problem of a program's courses, for `towpath_seq` (or any other solver).
//!
//! Each course is a task. Its forward mode enters at the state where the original program's
//! transit into it ended and leaves at the end of its retract block; its reverse mode (when
//! bidirectional layup is allowed and the course can be reversed) enters at the end of the
//! retract block turned round and leaves at the start of the approach turned round. A mode's
//! own cost is its approach and retract motion (at their programmed feeds under the time cost),
//! so the route cost is the off-part motion of the courses. The route starts at the end of the
//! header and ends free, or at the footer's end state when the footer writes every axis.

use std::sync::Arc;

use towpath_machine::{CostKind, Machine, MachineCost, StateTable};
use towpath_motion::TransitCost;
use towpath_seq::{Cost, CostModel, End, Mode, Problem, StateId, Step, TaskId};

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::footprint::{footprints, Footprints, Width};
use crate::interp::Interp;
use crate::precedence::{course_precedence, precedence_sets};
use crate::program::Program;
use crate::reverse::{reversal_of, Irreversible, Reversed};
use crate::safety::Safety;

/// The cost of a transit between courses, as the rewriter will write it.
#[derive(Clone, Debug)]
pub enum AfpCost {
    /// One direct move (or up to the dialect's fixed clearance, across and down), priced by
    /// the machine's cost model.
    Direct(Box<MachineCost>),
    /// The transit the motion-safety planner plans against the cell (straight where that keeps
    /// the clearance, else lifted only as high as the obstacles need), each move priced by the
    /// machine's cost model; arcs with no safe transit are forbidden.
    Planned(Arc<TransitCost>),
}

impl AfpCost {
    /// The machine's cost model and the states.
    pub fn machine_cost(&self) -> &MachineCost {
        match self {
            AfpCost::Direct(c) => c,
            AfpCost::Planned(t) => t.base(),
        }
    }
}

impl CostModel for AfpCost {
    fn num_states(&self) -> usize {
        self.machine_cost().num_states()
    }

    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        match self {
            AfpCost::Direct(c) => c.cost(from, to),
            AfpCost::Planned(t) => t.cost(from, to),
        }
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        self.machine_cost().position(state)
    }
}

/// Which precedence to impose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PrecedenceRule {
    /// A course after every course of an earlier ply it overlaps (default).
    #[default]
    Courses,
    /// Doherty et al.'s precedence sets: each set after the one before.
    Sets,
    /// Every ply after the one before.
    Plies,
}

impl std::str::FromStr for PrecedenceRule {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "courses" => Ok(PrecedenceRule::Courses),
            "sets" => Ok(PrecedenceRule::Sets),
            "plies" => Ok(PrecedenceRule::Plies),
            _ => Err(format!("unknown precedence {s:?}: expected courses, sets or plies")),
        }
    }
}

impl std::fmt::Display for PrecedenceRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PrecedenceRule::Courses => "courses",
            PrecedenceRule::Sets => "sets",
            PrecedenceRule::Plies => "plies",
        })
    }
}

/// What to optimize and under which rules.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AfpOptions {
    /// The cost model of transitions.
    pub cost: CostKind,
    /// Allow courses to be laid in reverse.
    pub bidirectional: bool,
    /// The precedence rule.
    pub precedence: PrecedenceRule,
    /// Keep the order of courses within each ply.
    pub keep_ply_order: bool,
    /// Course width (overrides the dialect's).
    pub width: Option<Width>,
}

impl Default for AfpOptions {
    fn default() -> Self {
        AfpOptions {
            cost: CostKind::Axis,
            bidirectional: false,
            precedence: PrecedenceRule::Courses,
            keep_ply_order: false,
            width: None,
        }
    }
}

/// The cost to optimize when none is chosen: cycle time ([`CostKind::Time`], all axes
/// together, a reversed course paying for its heading turn) when every axis of the machine has
/// a velocity limit, else Doherty et al.'s weighted axis distance ([`CostKind::Axis`]).
pub fn default_cost(machine: &Machine) -> CostKind {
    if machine.axes_without_velocity().is_empty() {
        CostKind::Time
    } else {
        CostKind::Axis
    }
}

impl AfpOptions {
    /// The default options for a machine: as [`AfpOptions::default`], with the cost
    /// [`default_cost`] chooses.
    pub fn for_machine(machine: &Machine) -> AfpOptions {
        AfpOptions { cost: default_cost(machine), ..AfpOptions::default() }
    }

    /// The width to use: the options', else the dialect's (course width first).
    pub fn width_or(&self, dialect: &Dialect) -> Option<Width> {
        self.width.or(dialect.course_width.map(Width::Course)).or(dialect.tow_width.map(Width::Tow))
    }
}

/// A program's courses as a sequencing problem, with everything needed to write the answer back.
#[derive(Clone, Debug)]
pub struct AfpProblem {
    /// The problem: task `c` is course `c`; mode 0 forward, mode 1 (if any) reverse.
    pub problem: Problem<AfpCost>,
    /// Doherty et al.'s precedence sets, in order, as lists of courses (each ply alone when there are
    /// no footprints).
    pub sets: Vec<Vec<usize>>,
    /// The plies of each set.
    pub set_plies: Vec<Vec<usize>>,
    /// The original order: every course forward.
    pub original: Vec<Step>,
    /// How every course that has a reverse mode reverses (its lines are written when needed).
    pub reversed: Vec<Option<Reversed>>,
    /// Courses that could not be reversed, and why.
    pub not_reversible: Vec<(usize, Irreversible)>,
    /// The footprints, if computed.
    pub footprints: Option<Footprints>,
    /// Number of precedence edges given to the solver.
    pub edges: usize,
}

/// Builds the sequencing problem of a parsed program, transits priced as one direct move (or
/// by way of the dialect's clearance).
pub fn build_problem(
    program: &Program,
    machine: &Machine,
    dialect: &Dialect,
    opts: &AfpOptions,
) -> Result<AfpProblem, NcError> {
    build_problem_with(program, machine, dialect, opts, None)
}

/// Builds the sequencing problem of a parsed program; with `safety`, every transit is priced as
/// the transit the planner plans against the cell (the one [`crate::rewrite_with`] writes).
pub fn build_problem_with(
    program: &Program,
    machine: &Machine,
    dialect: &Dialect,
    opts: &AfpOptions,
    safety: Option<&Safety>,
) -> Result<AfpProblem, NcError> {
    let k = program.courses.len();
    crate::reverse::check_switch_scope(program, dialect)?;
    let plies: Vec<Vec<usize>> = program.plies.iter().map(|p| p.courses.clone()).collect();
    let plies_with_courses = plies.iter().filter(|p| !p.is_empty()).count();
    let width = opts.width_or(dialect);
    let needs_fp = plies_with_courses > 1 && opts.precedence != PrecedenceRule::Plies;
    let fps = match (needs_fp, width) {
        (true, None) => return Err(NcError::NeedsWidth { plies: plies_with_courses, checking: false }),
        (true, Some(w)) => Some(footprints(program, machine, w)?),
        (false, Some(w)) if machine.kinematics().is_some() => footprints(program, machine, w).ok(),
        _ => None,
    };
    let set_plies = match &fps {
        Some(f) => precedence_sets(f, &plies)?,
        None => (0..plies.len()).map(|p| vec![p]).collect(),
    };
    let sets: Vec<Vec<usize>> =
        set_plies.iter().map(|ps| ps.iter().flat_map(|&p| plies[p].iter().copied()).collect()).collect();

    // Reversal.
    let mut reversed: Vec<Option<Reversed>> = vec![None; k];
    let mut not_reversible = Vec::new();
    if opts.bidirectional {
        use rayon::prelude::*;
        let all: Vec<Result<Reversed, Irreversible>> =
            (0..k).into_par_iter().map(|c| reversal_of(program, c, machine, dialect)).collect();
        for (c, r) in all.into_iter().enumerate() {
            match r {
                Ok(r) => reversed[c] = Some(r),
                Err(why) => not_reversible.push((c, why)),
            }
        }
    }

    // States and modes.
    let mut states = StateTable::new(machine.dim());
    let start = states.push(&program.start.phys)?;
    let mut modes: Vec<Vec<(towpath_seq::StateId, towpath_seq::StateId)>> = Vec::with_capacity(k);
    for (c, course) in program.courses.iter().enumerate() {
        let mut m = vec![(states.push(&course.insert.phys)?, states.push(&course.exit.phys)?)];
        if let Some(r) = &reversed[c] {
            let mut exit = course.span_start.phys.clone();
            if let Some(h) = machine.heading_axis() {
                exit[h] += r.shift;
            }
            m.push((states.push(&r.entry.phys)?, states.push(&exit)?));
        }
        modes.push(m);
    }
    let end_state = footer_end(program, machine, dialect)?.map(|s| states.push(&s)).transpose()?;
    let mut cost = MachineCost::new(machine.clone(), opts.cost, states)?;
    if safety.is_none() {
        if let Some((axis, value)) = dialect.clearance_axis(machine)? {
            // The rewriter writes every transit by way of the clearance; the solver prices them so.
            cost = cost.with_clearance(axis, value)?;
        }
    }

    let model = match safety {
        Some(s) => AfpCost::Planned(Arc::new(TransitCost::new(s.planner().clone(), cost.clone()))),
        None => AfpCost::Direct(Box::new(cost.clone())),
    };
    let mut b = Problem::builder(model);
    for (c, ms) in modes.iter().enumerate() {
        b.task(
            ms.iter()
                .enumerate()
                .map(|(i, &(e, x))| Mode { entry: e, exit: x, cost: own_cost(program, c, &cost, dialect, i == 1) })
                .collect(),
        );
    }
    let mut edges = 0;
    match opts.precedence {
        PrecedenceRule::Courses => {
            if let Some(f) = &fps {
                for (x, y) in course_precedence(f, &plies)? {
                    b.precede(TaskId(x as u32), TaskId(y as u32));
                    edges += 1;
                }
            }
        }
        PrecedenceRule::Sets => {
            for w in sets.windows(2) {
                let (a, z): (Vec<TaskId>, Vec<TaskId>) = (
                    w[0].iter().map(|&c| TaskId(c as u32)).collect(),
                    w[1].iter().map(|&c| TaskId(c as u32)).collect(),
                );
                b.precede_groups(&a, &z);
                edges += a.len() * z.len();
            }
        }
        PrecedenceRule::Plies => {
            let nonempty: Vec<&Vec<usize>> = plies.iter().filter(|p| !p.is_empty()).collect();
            for w in nonempty.windows(2) {
                let (a, z): (Vec<TaskId>, Vec<TaskId>) = (
                    w[0].iter().map(|&c| TaskId(c as u32)).collect(),
                    w[1].iter().map(|&c| TaskId(c as u32)).collect(),
                );
                b.precede_groups(&a, &z);
                edges += a.len() * z.len();
            }
        }
    }
    if opts.keep_ply_order {
        for p in &plies {
            for w in p.windows(2) {
                b.precede(TaskId(w[0] as u32), TaskId(w[1] as u32));
                edges += 1;
            }
        }
    }
    b.start(start);
    b.end(match end_state {
        Some(s) => End::At(s),
        None => End::Free,
    });
    let problem = b.build()?;
    let original = (0..k).map(|c| Step { task: TaskId(c as u32), mode: 0 }).collect();
    Ok(AfpProblem { problem, sets, set_plies, original, reversed, not_reversible, footprints: fps, edges })
}

/// A mode's own cost: course `c`'s approach and retract moves (its off-part moves), priced at
/// their programmed feeds. Reversed, the original retract runs backwards as the approach with
/// the motion code and feed of the original approach's last move, and the original approach
/// as the retract with those of the original retract's first move (as `reverse.rs` writes
/// them), so under the time cost the two modes may differ.
fn own_cost(program: &Program, c: usize, cost: &MachineCost, dialect: &Dialect, reversed: bool) -> f64 {
    let course = &program.courses[c];
    let segs = &program.segments[course.segments.clone()];
    let (start, end) = (course.on_part.start as u32, course.on_part.end as u32);
    let how = |s: &crate::program::Segment| (s.rapid, s.feed);
    let last_approach = segs.iter().rev().find(|s| s.line < start).map(how);
    let first_retract = segs.iter().find(|s| s.line >= end).map(how);
    segs.iter()
        .filter(|s| !s.on_part)
        .map(|s| {
            let (rapid, feed) = match (reversed, s.line < start, s.line >= end) {
                (true, true, _) => first_retract.unwrap_or(how(s)),
                (true, _, true) => last_approach.unwrap_or(how(s)),
                _ => how(s),
            };
            let (a, b) = (program.point(s.from), program.point(s.to));
            let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| y - x).collect();
            cost.segment_at(a, b, &d, (!rapid).then(|| dialect.feed_per_second(feed)))
        })
        .sum()
}

/// The machine state at the end of the footer, if the footer's moves write every axis in
/// absolute mode (so that it does not depend on where the last course left the machine).
fn footer_end(program: &Program, machine: &Machine, dialect: &Dialect) -> Result<Option<Vec<f64>>, NcError> {
    let last = match program.courses.last() {
        Some(c) => c,
        None => return Ok(None),
    };
    let mut it = Interp::new(dialect, machine)?;
    it.m = last.exit.clone();
    let mut written = vec![false; machine.dim()];
    let mut moved = false;
    for j in program.footer_start..program.lines.len() {
        let a = it.apply(j, &program.lines[j])?;
        if a.motion.is_some() {
            moved = true;
            if let Some(lexed) = &a.lexed {
                for w in &lexed.words {
                    if let Some(i) = it.axis_of(w.letter) {
                        if !it.m.incremental {
                            written[i] = true;
                        }
                    }
                }
            }
        }
    }
    Ok(if moved && written.iter().all(|&w| w) { Some(it.m.phys.clone()) } else { None })
}

/// Turns a solver's steps into placements.
pub fn placements(steps: &[Step]) -> Vec<crate::rewrite::Placement> {
    steps.iter().map(|s| crate::rewrite::Placement { course: s.task.index(), reversed: s.mode == 1 }).collect()
}
