//! What every baseline shares: the last step that checks the answer, keeps the initial route if
//! it is better, and fills in the report. The clock (time limit and cancel flag) is
//! [`towpath_seq::Clock`], the same as towpath's solver's.

use towpath_seq::{check, Clock, CostModel, Problem, Solution, SolveOptions, SolveReport, Step};

use crate::BaselineError;

/// Checks the initial route given in the options, if any, and returns its cost.
pub(crate) fn initial_cost<C: CostModel>(
    problem: &Problem<C>,
    opts: &SolveOptions,
) -> Result<Option<f64>, BaselineError> {
    match &opts.initial {
        Some(steps) => Ok(Some(check(problem, steps).map_err(BaselineError::BadInitial)?)),
        None => Ok(None),
    }
}

/// Checks the route a baseline found and builds the report. If an initial route was given and
/// is cheaper, it is returned instead (seed 000 §3.2 requirement 4: F(p) ≤ F(o)).
pub(crate) fn finish<C: CostModel>(
    problem: &Problem<C>,
    steps: Vec<Step>,
    opts: &SolveOptions,
    clock: &Clock,
    first_cost: f64,
    iterations: u64,
) -> Result<SolveReport, BaselineError> {
    let initial_cost = initial_cost(problem, opts)?;
    let mut solution = match check(problem, &steps) {
        Ok(cost) => Some(Solution { steps, cost }),
        Err(v) => {
            if initial_cost.is_none() {
                return Err(BaselineError::NoFeasibleRoute(v));
            }
            None
        }
    };
    if let (Some(init), Some(ic)) = (&opts.initial, initial_cost) {
        if solution.as_ref().is_none_or(|s| ic < s.cost) {
            solution = Some(Solution { steps: init.clone(), cost: ic });
        }
    }
    let Some(solution) = solution else {
        // unreachable: either the route checked or the initial one exists
        return Err(BaselineError::NoFeasibleRoute(towpath_seq::Violation::WrongLength {
            got: 0,
            expected: problem.num_tasks(),
        }));
    };
    Ok(SolveReport {
        solution,
        initial_cost,
        first_local_optimum: first_cost,
        iterations,
        elapsed: clock.elapsed(),
        // a baseline's iterations run from its start
        search_elapsed: clock.elapsed(),
        exact: false,
        lower_bound: None,
    })
}
