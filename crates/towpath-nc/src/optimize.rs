//! The whole job: parse, build the problem, sequence, rewrite, verify.

use std::time::{Duration, Instant};

use serde::Serialize;
use towpath_baselines::{BaselineParams, SolverName};
use towpath_machine::Machine;
use towpath_seq::{check, SolveOptions, Step};

use crate::dialect::Dialect;
use crate::error::NcError;
use crate::problem::{build_problem, placements, AfpOptions, AfpProblem};
use crate::program::Program;
use crate::rewrite::{rewrite, Placement};
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
    /// The solver: towpath's own (default) or one of the seed papers' (for comparison).
    pub solver: SolverName,
    /// Parameters of the seed papers' solvers. `doherty` without `sets` gets the program's
    /// seed-000 precedence sets ([`crate::seed000_sets`]).
    pub baselines: BaselineParams,
}

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
            .finish()
    }
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
    /// The course width used and where it came from (with a warning if the width given
    /// disagrees with the dialect's).
    pub width: crate::width::WidthUsed,
}

/// Optimizes a program: returns the rewritten text, verified against the input, never costing
/// more off-part motion (under the chosen cost model) than the input. The courses are
/// sequenced by `opts.solver` (towpath's own by default).
pub fn optimize(
    text: &str,
    machine: &Machine,
    dialect: &Dialect,
    opts: &OptimizeOptions,
) -> Result<Optimized, NcError> {
    let t0 = Instant::now();
    let program = crate::parse::parse(text, machine, dialect)?;
    let width = crate::width::WidthUsed::choose(opts.afp.width, dialect, &program);
    let t_parse = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let afp = build_problem(&program, machine, dialect, &opts.afp)?;
    let t_build = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let report = sequence(
        opts.solver,
        &opts.baselines,
        &program,
        &afp,
        &opts.afp,
        &SolveOptions {
            time_limit: opts.time_limit,
            iterations: opts.iterations,
            seed: opts.seed,
            threads: opts.threads.max(1),
            initial: Some(afp.original.clone()),
            progress: opts.progress.clone(),
            ..SolveOptions::default()
        },
    )?;
    let t_solve = t2.elapsed().as_secs_f64();
    let solver = SolverSummary {
        solver: opts.solver.to_string(),
        initial_cost: report.initial_cost.unwrap_or(f64::NAN),
        cost: report.solution.cost,
        iterations: report.iterations,
        exact: report.exact,
    };
    let t3 = Instant::now();
    let mut order = placements(&report.solution.steps);
    let mut out = rewrite(&program, &order, machine, dialect, &afp.reversed)?;
    let t_rewrite = t3.elapsed().as_secs_f64();
    let t4 = Instant::now();
    let vopts = VerifyOptions {
        width: opts.afp.width_or(dialect),
        strict_plies: opts.afp.precedence == crate::problem::PrecedenceRule::Plies,
        keep_ply_order: opts.afp.keep_ply_order,
        seed000_sets: opts.afp.precedence == crate::problem::PrecedenceRule::Sets,
    };
    let check = |text: &str| -> Result<Verification, NcError> {
        let parsed = crate::parse::parse(text, machine, dialect).map_err(|e| NcError::SelfCheck(e.to_string()))?;
        verify_parsed(&program, &parsed, machine, dialect, &vopts, afp.footprints.as_ref())
            .map_err(|e| NcError::SelfCheck(e.to_string()))
    };
    let mut verification = check(&out)?;
    let mut fell_back = false;
    if let Some((before, after)) = verification.motion(opts.afp.cost) {
        if after.off_part() > before.off_part() * (1.0 + 1e-12) + 1e-9 {
            fell_back = true;
            order = (0..program.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
            out = text.to_string();
            verification = check(&out)?;
        }
    }
    let t_verify = t4.elapsed().as_secs_f64();
    Ok(Optimized {
        text: out,
        program,
        afp,
        order,
        verification,
        solver,
        timings: Timings {
            parse: t_parse,
            build: t_build,
            solve: t_solve,
            rewrite: t_rewrite,
            verify: t_verify,
            total: t0.elapsed().as_secs_f64(),
        },
        fell_back,
        width,
    })
}

/// Writes the program for a route found by any solver over `afp.problem` and verifies it
/// against the original: the way to run another sequencing algorithm (seed 000's, for one) on
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
        seed000_sets: opts.precedence == crate::problem::PrecedenceRule::Sets,
    };
    let v = verify_parsed(program, &parsed, machine, dialect, &vopts, afp.footprints.as_ref())
        .map_err(|e| NcError::SelfCheck(e.to_string()))?;
    Ok((text, v))
}
