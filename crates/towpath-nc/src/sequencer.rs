//! Which solver sequences the courses: towpath's own, or one of the published algorithms towpath is built from
//! from `towpath-baselines`, on the same problem.
//!
//! Doherty et al.'s solver (`doherty`) works per precedence set: it gets the program's Doherty et al.'s precedence sets
//! ([`doherty_sets`]) unless the caller gave its own. Every solver starts from the original
//! order (`SolveOptions::initial`) and returns it when it finds nothing cheaper.

use towpath_baselines::{solve_with, BaselineError, BaselineParams, PrecedenceSet, SolverName};
use towpath_seq::{SolveOptions, SolveReport, TaskId};

use crate::error::NcError;
use crate::problem::{AfpOptions, AfpProblem, PrecedenceRule};
use crate::program::Program;

/// The precedence sets Doherty et al.'s solver orders one after another, for the problem built under
/// `opts`:
///
/// - course-level precedence (`courses`) and Doherty et al.'s own (`sets`): the Doherty et al.'s precedence sets of the
///   program ([`AfpProblem::sets`]), each with the count of its plies that hold courses; every
///   course-level precedence rule goes from an earlier set to a later one, because plies are
///   only joined into a set while they do not intersect;
/// - ply by ply (`plies`): one set per ply, since plies joined into one of Doherty et al.'s sets must then
///   still be laid in order.
///
/// Keeping the order of the courses within each ply is not part of Doherty et al.'s model (its
/// solver orders each set freely), so it is refused.
pub fn doherty_sets(program: &Program, afp: &AfpProblem, opts: &AfpOptions) -> Result<Vec<PrecedenceSet>, NcError> {
    if opts.keep_ply_order {
        return Err(NcError::DohertyKeepsNoPlyOrder);
    }
    let tasks = |courses: &[usize]| courses.iter().map(|&c| TaskId(c as u32)).collect::<Vec<_>>();
    let sets = match opts.precedence {
        PrecedenceRule::Plies => program
            .plies
            .iter()
            .filter(|p| !p.courses.is_empty())
            .map(|p| PrecedenceSet { tasks: tasks(&p.courses), plies: 1 })
            .collect(),
        PrecedenceRule::Courses | PrecedenceRule::Sets => afp
            .sets
            .iter()
            .zip(&afp.set_plies)
            .filter(|(courses, _)| !courses.is_empty())
            .map(|(courses, plies)| {
                let with_courses =
                    plies.iter().filter(|&&p| program.plies.get(p).is_some_and(|p| !p.courses.is_empty())).count();
                PrecedenceSet { tasks: tasks(courses), plies: with_courses.max(1) }
            })
            .collect(),
    };
    Ok(sets)
}

/// Runs `solver` on the program's problem from the original order. For `doherty` without sets
/// in `params`, the program's Doherty et al.'s precedence sets are used ([`doherty_sets`]).
pub fn sequence(
    solver: SolverName,
    params: &BaselineParams,
    program: &Program,
    afp: &AfpProblem,
    afp_opts: &AfpOptions,
    solve_opts: &SolveOptions,
) -> Result<SolveReport, NcError> {
    let mut solve_opts = solve_opts.clone();
    // The program's own order is the starting point, when it is feasible (with a cell, a
    // transit of the input may have no safe plan).
    solve_opts.initial = towpath_seq::check(&afp.problem, &afp.original).is_ok().then(|| afp.original.clone());
    let named = |e: BaselineError| match e {
        BaselineError::Solve(e) => NcError::from(e),
        e => {
            let text = e.to_string();
            NcError::Solver(if text.starts_with(solver.as_str()) { text } else { format!("solver {solver}: {text}") })
        }
    };
    if solver == SolverName::Doherty && params.doherty.sets.is_none() {
        let mut params = params.clone();
        params.doherty.sets = Some(doherty_sets(program, afp, afp_opts)?);
        return solve_with(solver, &afp.problem, &solve_opts, &params).map_err(named);
    }
    solve_with(solver, &afp.problem, &solve_opts, params).map_err(named)
}
