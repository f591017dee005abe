//! The whole job: parse, build the problem, sequence, rewrite, verify.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::Serialize;
use towpath_baselines::{BaselineParams, SolverName};
use towpath_machine::{CostKind, Machine};
use towpath_seq::{check, SolveOptions, Step};

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::problem::{build_problem_with, placements, AfpOptions, AfpProblem};
use crate::program::Program;
use crate::rewrite::{rewrite, rewrite_with, Placement};
use crate::safety::{
    check_cell_under_path, check_courses_within_limits, check_program, limit_violations, Safety, SafetyReport, MOLD_GAP,
};
use crate::sequencer::sequence;
use crate::verify::{verify_parsed, Verification, VerifyOptions};

/// How to optimize.
#[derive(Clone)]
pub struct OptimizeOptions {
    /// Problem options (cost, reversal, precedence, width).
    pub afp: AfpOptions,
    /// Solver wall-time budget.
    pub time_limit: Option<Duration>,
    /// Solver work budget (deterministic when set without a time limit).
    pub iterations: Option<u64>,
    /// Solver seed.
    pub seed: u64,
    /// Solver threads.
    pub threads: usize,
    /// Called as the solver progresses.
    pub progress: Option<towpath_seq::ProgressFn>,
    /// The solver: towpath's own (default) or one of the published solvers (for comparison).
    pub solver: SolverName,
    /// Parameters of the published solvers (docs/references.md). `doherty` without `sets` gets the program's
    /// Doherty et al.'s precedence sets ([`crate::doherty_sets`]).
    pub baselines: BaselineParams,
    /// The cell and clearance: with it, transits are planned against the cell (priced so by the
    /// sequencer and written so), and the output is refused unless it is free of collisions
    /// and limit violations.
    pub safety: Option<Safety>,
    /// Set to stop: the solver returns at once and [`optimize`] with [`NcError::Cancelled`]
    /// (checked between stages too).
    pub cancel: Option<Arc<AtomicBool>>,
    /// Called as each stage starts (for a front end's progress display).
    pub stage: Option<StageFn>,
}

/// A stage of [`optimize`], reported to [`OptimizeOptions::stage`] as it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    /// Reading the program.
    Parsing,
    /// Checking the input against the travel limits and the cell.
    Checking,
    /// Footprints, precedence, reversal and the sequencing problem.
    Building,
    /// The solver runs; the route cost of the input order, when it is a feasible route.
    Solving {
        /// Route cost of the input order (the solver's objective).
        initial_cost: Option<f64>,
    },
    /// Writing the new program and verifying it against the input.
    Writing,
}

impl Stage {
    /// The stage in a few words.
    pub fn label(&self) -> &'static str {
        match self {
            Stage::Parsing => "parsing",
            Stage::Checking => "checking limits and the cell",
            Stage::Building => "building the problem",
            Stage::Solving { .. } => "solving",
            Stage::Writing => "writing and verifying",
        }
    }
}

/// A callback told of each [`Stage`].
pub type StageFn = Arc<dyn Fn(Stage) + Send + Sync>;

impl Default for OptimizeOptions {
    fn default() -> Self {
        OptimizeOptions {
            afp: AfpOptions::default(),
            time_limit: Some(Duration::from_secs(10)),
            iterations: None,
            seed: 1,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            progress: None,
            solver: SolverName::Towpath,
            baselines: BaselineParams::default(),
            safety: None,
            cancel: None,
            stage: None,
        }
    }
}

/// A solver time limit for a program of `courses` courses when none is given: one second plus
/// a fifth of a millisecond per course, at most ten seconds.
pub fn auto_time_limit(courses: usize) -> Duration {
    Duration::from_secs_f64((1.0 + 0.0002 * courses as f64).min(10.0))
}

impl std::fmt::Debug for OptimizeOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OptimizeOptions")
            .field("afp", &self.afp)
            .field("time_limit", &self.time_limit)
            .field("iterations", &self.iterations)
            .field("seed", &self.seed)
            .field("threads", &self.threads)
            .field("solver", &self.solver)
            .field("baselines", &self.baselines)
            .field("safety", &self.safety.as_ref().map(|s| s.clearance()))
            .finish()
    }
}

/// The motion safety of a program before and after optimization.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SafetyPair {
    /// The input program.
    pub before: SafetyReport,
    /// The program written.
    pub after: SafetyReport,
}

/// Wall time of each stage, in seconds.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Timings {
    /// Parsing the program.
    pub parse: f64,
    /// Footprints, precedence, reversal and the problem.
    pub build: f64,
    /// The solver.
    pub solve: f64,
    /// Writing the new program.
    pub rewrite: f64,
    /// Verifying it.
    pub verify: f64,
    /// Everything.
    pub total: f64,
}

/// The solver's side of the story.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SolverSummary {
    /// The solver that ran (`towpath`, `doherty`, `castelino`, `ga`, `aco1`, `aco2`).
    pub solver: String,
    /// Route cost of the original order (the solver's objective).
    pub initial_cost: f64,
    /// Route cost of the answer.
    pub cost: f64,
    /// Improvement kicks done.
    pub iterations: u64,
    /// The answer is optimal (exact solver).
    pub exact: bool,
}

/// The result of [`optimize`].
#[derive(Clone, Debug)]
pub struct Optimized {
    /// The optimized program text.
    pub text: String,
    /// The original, parsed.
    pub program: Program,
    /// The program returned ([`Optimized::text`]), parsed.
    pub output: Program,
    /// The sequencing problem.
    pub afp: AfpProblem,
    /// The new order.
    pub order: Vec<Placement>,
    /// The verification of the output against the input.
    pub verification: Verification,
    /// Solver figures.
    pub solver: SolverSummary,
    /// Stage times.
    pub timings: Timings,
    /// The solver's order measured worse than the input on the program itself, so the input
    /// was returned unchanged.
    pub fell_back: bool,
    /// Why the input was returned unchanged (when [`Optimized::fell_back`]).
    pub fallback: Option<Fallback>,
    /// The motion safety of the input and of the output, when a cell was given.
    pub safety: Option<SafetyPair>,
    /// The course width used and where it came from (with a warning if the width given
    /// disagrees with the dialect's).
    pub width: crate::width::WidthUsed,
}

/// Optimizes a program: returns the rewritten text, verified against the input, never costing
/// more off-part motion (under the chosen cost model) than the input and, when the machine has
/// velocities, never taking longer (cycle time under the machine's time model, as the verifier
/// measures it) than the input, whatever the cost optimized: otherwise the input order is
/// returned unchanged ([`Optimized::fallback`] says why). The courses are sequenced by
/// `opts.solver` (towpath's own by default).
pub fn optimize(
    text: &str,
    machine: &Machine,
    dialect: &Dialect,
    opts: &OptimizeOptions,
) -> Result<Optimized, NcError> {
    let t0 = Instant::now();
    let stage = |s: Stage| {
        if let Some(f) = &opts.stage {
            f(s)
        }
    };
    let cancelled = || -> Result<(), NcError> {
        match &opts.cancel {
            Some(c) if c.load(Ordering::Relaxed) => Err(NcError::Cancelled),
            _ => Ok(()),
        }
    };
    stage(Stage::Parsing);
    let program = crate::parse::parse(text, machine, dialect)?;
    let width = crate::width::WidthUsed::choose(opts.afp.width, dialect, &program);
    let t_parse = t0.elapsed().as_secs_f64();
    cancelled()?;
    stage(Stage::Checking);
    let t1 = Instant::now();
    let safety = opts.safety.as_ref();
    check_courses_within_limits(&program, machine)?;
    let input_safety = match safety {
        Some(sf) => {
            check_cell_under_path(&program, machine, sf, MOLD_GAP)?;
            Some(check_program(&program, sf))
        }
        None => None,
    };
    cancelled()?;
    stage(Stage::Building);
    let afp = build_problem_with(&program, machine, dialect, &opts.afp, safety)?;
    let t_build = t1.elapsed().as_secs_f64();
    cancelled()?;
    stage(Stage::Solving { initial_cost: check(&afp.problem, &afp.original).ok() });
    let t2 = Instant::now();
    let (solver, steps) = solve_order(&program, &afp, opts)?;
    let t_solve = t2.elapsed().as_secs_f64();
    cancelled()?;
    stage(Stage::Writing);
    let t3 = Instant::now();
    let planner = safety.map(|s| s.planner().as_ref());
    let proposed = placements(&steps);
    let proposed_text = rewrite_with(&program, &proposed, machine, dialect, &afp.reversed, planner)?;
    let t_rewrite = t3.elapsed().as_secs_f64();
    let t4 = Instant::now();
    let chosen = Written::choose(
        Written { order: proposed, text: proposed_text },
        text,
        &program,
        &afp,
        machine,
        dialect,
        opts,
        input_safety.as_ref().filter(|before| !before.is_safe()).and(planner),
    )?;
    let safety = check_output_safety(&program, &chosen.parsed, machine, safety, input_safety)?;
    let t_verify = t4.elapsed().as_secs_f64();
    Ok(Optimized {
        text: chosen.written.text,
        program,
        output: chosen.parsed,
        afp,
        order: chosen.written.order,
        verification: chosen.verification,
        solver,
        timings: Timings {
            parse: t_parse,
            build: t_build,
            solve: t_solve,
            rewrite: t_rewrite,
            verify: t_verify,
            total: t0.elapsed().as_secs_f64(),
        },
        fell_back: chosen.fallback.is_some(),
        fallback: chosen.fallback,
        width,
        safety,
    })
}

/// Runs the chosen solver from the program's own order; with a cell, a failure to find safe
/// transits is said as such. Returns the summary and the solver's steps.
fn solve_order(
    program: &Program,
    afp: &AfpProblem,
    opts: &OptimizeOptions,
) -> Result<(SolverSummary, Vec<Step>), NcError> {
    let report = sequence(
        opts.solver,
        &opts.baselines,
        program,
        afp,
        &opts.afp,
        &SolveOptions {
            time_limit: opts.time_limit,
            iterations: opts.iterations,
            seed: opts.seed,
            threads: opts.threads.max(1),
            initial: Some(afp.original.clone()),
            progress: opts.progress.clone(),
            cancel: opts.cancel.clone(),
            ..SolveOptions::default()
        },
    )
    .map_err(|e| match (opts.safety.as_ref(), &e) {
        (Some(sf), NcError::Sequencing(_) | NcError::Solver(_)) => NcError::Unsafe(format!(
            "no order of the courses found whose every transit can be made safe (a clearance of {} mm within the \
             travel limits): {e}",
            sf.clearance()
        )),
        _ => e,
    })?;
    let summary = SolverSummary {
        solver: opts.solver.to_string(),
        initial_cost: report.initial_cost.unwrap_or(f64::NAN),
        cost: report.solution.cost,
        iterations: report.iterations,
        exact: report.exact,
    };
    Ok((summary, report.solution.steps))
}

/// A program text and the order of courses it was written in.
struct Written {
    order: Vec<Placement>,
    text: String,
}

/// The program optimize hands back, verified against the input, with its parse.
struct Chosen {
    written: Written,
    verification: Verification,
    parsed: Program,
    /// Why the input order was kept instead of the solver's, if it was.
    fallback: Option<Fallback>,
}

impl Written {
    /// Verifies the solver's program against the input and keeps it unless it is worse under
    /// the chosen cost, in which case the input order is kept: the input itself, or, when the
    /// input is unsafe in the cell (`unsafe_input_planner` given), the input order re-written
    /// with safe transits (then that is no fallback but the better of two safe programs).
    #[allow(clippy::too_many_arguments)]
    fn choose(
        proposed: Written,
        input: &str,
        program: &Program,
        afp: &AfpProblem,
        machine: &Machine,
        dialect: &Dialect,
        opts: &OptimizeOptions,
        unsafe_input_planner: Option<&towpath_motion::Planner>,
    ) -> Result<Chosen, NcError> {
        let vopts = VerifyOptions {
            width: opts.afp.width_or(dialect),
            strict_plies: opts.afp.precedence == crate::problem::PrecedenceRule::Plies,
            keep_ply_order: opts.afp.keep_ply_order,
            doherty_sets: opts.afp.precedence == crate::problem::PrecedenceRule::Sets,
        };
        // A program parsed and verified; the parse is kept for the safety checks.
        let check = |written: Written| -> Result<Chosen, NcError> {
            let parsed =
                crate::parse::parse(&written.text, machine, dialect).map_err(|e| NcError::SelfCheck(e.to_string()))?;
            let verification = verify_parsed(program, &parsed, machine, dialect, &vopts, afp.footprints.as_ref())
                .map_err(|e| NcError::SelfCheck(e.to_string()))?;
            Ok(Chosen { written, verification, parsed, fallback: None })
        };
        let identity: Vec<Placement> =
            (0..program.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        let mut chosen = check(proposed)?;
        match unsafe_input_planner {
            Some(planner) => {
                let text = rewrite_with(program, &identity, machine, dialect, &afp.reversed, Some(planner))?;
                let safe_input = check(Written { order: identity, text })?;
                if let Some(why) = worse_than(&chosen.verification, &safe_input.verification, opts.afp.cost) {
                    chosen = Chosen { fallback: Some(why), ..safe_input };
                }
            }
            None => {
                if let Some(why) = fallback_reason(&chosen.verification, opts.afp.cost) {
                    let kept = check(Written { order: identity, text: input.to_string() })?;
                    chosen = Chosen { fallback: Some(why), ..kept };
                }
            }
        }
        Ok(chosen)
    }
}

/// The motion-safety checks of what optimize writes: with a cell, no collision and no axis
/// outside its limits (the input's state said beside); without one, the travel limits alone.
fn check_output_safety(
    program: &Program,
    output: &Program,
    machine: &Machine,
    safety: Option<&Safety>,
    input_safety: Option<SafetyReport>,
) -> Result<Option<SafetyPair>, NcError> {
    if let (Some(sf), Some(before)) = (safety, input_safety) {
        let after = check_program(output, sf);
        if !after.is_safe() {
            let mut why = vec![format!("the program towpath would write has {}", after.summary())];
            if !before.is_safe() {
                why.push(format!("the input has {}", before.summary()));
            }
            why.extend(after.details(5));
            return Err(NcError::Unsafe(why.join("\n")));
        }
        return Ok(Some(SafetyPair { before, after }));
    }
    let outside = limit_violations(output, machine);
    if outside.is_empty() {
        return Ok(None);
    }
    let input = limit_violations(program, machine).len();
    let report = SafetyReport { limit_violations: outside, ..SafetyReport::default() };
    Err(NcError::Unsafe(format!(
        "the program towpath would write leaves the travel limits ({}):\n{}",
        if input > 0 { format!("the input does too, on {input} lines") } else { "the input does not".into() },
        report.details(5).join("\n")
    )))
}

/// Why the solver's order is not returned, if it is not: measured on the rewritten program by
/// the verifier, it costs more off-part motion than the input under the optimized cost, or its
/// cycle time (the machine's time model, when the machine has velocities) is longer than the
/// input's, whatever cost was optimized.
pub fn fallback_reason(v: &Verification, cost: CostKind) -> Option<Fallback> {
    let worse = |before: f64, after: f64| after > before * (1.0 + 1e-12) + 1e-9;
    if let Some((before, after)) = v.motion(CostKind::Time) {
        if worse(before.total(), after.total()) {
            return Some(Fallback::CycleTime { before: before.total(), after: after.total() });
        }
    }
    let (before, after) = v.motion(cost)?;
    worse(before.off_part(), after.off_part()).then(|| Fallback::Cost {
        kind: cost,
        before: before.off_part(),
        after: after.off_part(),
    })
}

/// Why `cand` (a written program's verification) is worse than `base` (another written
/// order of the same input): a longer cycle time, or more off-part motion under `cost`.
fn worse_than(cand: &Verification, base: &Verification, cost: CostKind) -> Option<Fallback> {
    let worse = |b: f64, a: f64| a > b * (1.0 + 1e-12) + 1e-9;
    if let (Some((_, a)), Some((_, b))) = (cand.motion(CostKind::Time), base.motion(CostKind::Time)) {
        if worse(b.total(), a.total()) {
            return Some(Fallback::CycleTime { before: b.total(), after: a.total() });
        }
    }
    let ((_, a), (_, b)) = (cand.motion(cost)?, base.motion(cost)?);
    worse(b.off_part(), a.off_part()).then(|| Fallback::Cost { kind: cost, before: b.off_part(), after: a.off_part() })
}

/// Why [`optimize`] returned the input unchanged.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Fallback {
    /// The solver's order, as written, had a longer cycle time than the input (seconds, under
    /// the machine's time model).
    CycleTime {
        /// The input's cycle time.
        before: f64,
        /// The solver's order's cycle time.
        after: f64,
    },
    /// The solver's order, as written, cost more off-part motion than the input under the
    /// optimized cost.
    Cost {
        /// The cost model.
        kind: CostKind,
        /// The input's off-part motion.
        before: f64,
        /// The solver's order's off-part motion.
        after: f64,
    },
}

impl std::fmt::Display for Fallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Fallback::CycleTime { before, after } => write!(
                f,
                "the best order found would take {after:.1} s against the input's {before:.1} s, so the input order is kept"
            ),
            Fallback::Cost { kind, before, after } => write!(
                f,
                "the best order found costs {after:.1} {} of off-part motion against the input's {before:.1}, so the input order is kept",
                kind.unit()
            ),
        }
    }
}

/// Writes the program for a route found by any solver over `afp.problem` and verifies it
/// against the original: the way to run another sequencing algorithm (Doherty et al.'s, for one) on
/// the same parts. The steps are checked against the problem first.
pub fn apply_steps(
    program: &Program,
    afp: &AfpProblem,
    steps: &[Step],
    machine: &Machine,
    dialect: &Dialect,
    opts: &crate::problem::AfpOptions,
) -> Result<(String, Verification), NcError> {
    check(&afp.problem, steps).map_err(|v| NcError::Sequencing(format!("the route is not feasible: {v}")))?;
    let order = placements(steps);
    let text = rewrite(program, &order, machine, dialect, &afp.reversed)?;
    let parsed = crate::parse::parse(&text, machine, dialect).map_err(|e| NcError::SelfCheck(e.to_string()))?;
    let vopts = VerifyOptions {
        width: opts.width_or(dialect),
        strict_plies: opts.precedence == crate::problem::PrecedenceRule::Plies,
        keep_ply_order: opts.keep_ply_order,
        doherty_sets: opts.precedence == crate::problem::PrecedenceRule::Sets,
    };
    let v = verify_parsed(program, &parsed, machine, dialect, &vopts, afp.footprints.as_ref())
        .map_err(|e| NcError::SelfCheck(e.to_string()))?;
    Ok((text, v))
}
