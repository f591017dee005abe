//! Exact dynamic programming (Held–Karp over subsets) with modes, precedence, consecutive groups,
//! pinned tasks and every route end. Exponential: meant for small instances (up to about 13 tasks
//! with a few modes) and used by the tests to judge the heuristics.

use crate::cost::{Cost, CostModel, StateId};
use crate::model::{End, Problem, TaskId};
use crate::solution::{Solution, Step};

/// The largest number of tasks [`solve_exact`] accepts.
pub const MAX_EXACT_TASKS: usize = 20;

/// Why the exact solver refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExactError {
    /// Too many tasks for the subset DP.
    #[error("{0} tasks is too many for the exact solver (at most {MAX_EXACT_TASKS})")]
    TooLarge(usize),
}

/// Finds an optimal route, or `Ok(None)` if no feasible route exists.
pub fn solve_exact<C: CostModel>(problem: &Problem<C>) -> Result<Option<Solution>, ExactError> {
    let n = problem.num_tasks();
    if n > MAX_EXACT_TASKS {
        return Err(ExactError::TooLarge(n));
    }
    if n == 0 {
        let cost = match (problem.start(), problem.end()) {
            (Some(s), End::At(e)) => problem.transition(s, e),
            _ => 0.0,
        };
        return Ok(Some(Solution { steps: Vec::new(), cost }));
    }
    if problem.is_cyclic() {
        // Fix an anchor task at the front and try each of its modes.
        let anchor = problem.first_task().unwrap_or(TaskId(0));
        let mut best: Option<Solution> = None;
        for m in 0..problem.modes(anchor).len() as u32 {
            let entry = problem.modes(anchor)[m as usize].entry;
            if let Some(sol) = dp(problem, Some((anchor, m)), None, Some(entry)) {
                if best.as_ref().is_none_or(|b| sol.cost < b.cost) {
                    best = Some(sol);
                }
            }
        }
        return Ok(best);
    }
    let back = match problem.end() {
        End::Free => None,
        End::At(e) => Some(e),
        End::Closed => problem.start(),
    };
    Ok(dp(problem, None, problem.start(), back))
}

/// Subset DP. `fixed_first` forces the first step; `start` prices the move into the first task;
/// `back` prices the move out of the last one.
fn dp<C: CostModel>(
    problem: &Problem<C>,
    fixed_first: Option<(TaskId, u32)>,
    start: Option<StateId>,
    back: Option<StateId>,
) -> Option<Solution> {
    let n = problem.num_tasks();
    let cm = problem.cost_model();
    let mm = problem.max_modes();
    let full: usize = (1usize << n) - 1;
    let idx = |mask: usize, t: usize, m: usize| (mask * n + t) * mm + m;
    let mut best = vec![Cost::INFINITY; (full + 1) * n * mm];
    let mut parent = vec![u32::MAX; (full + 1) * n * mm];

    let pred_mask: Vec<usize> = (0..n)
        .map(|t| problem.precedence().predecessors(TaskId(t as u32)).iter().fold(0, |a, p| a | 1 << p.index()))
        .collect();
    let group_mask: Vec<usize> = problem.groups().iter().map(|g| g.iter().fold(0, |a, t| a | 1 << t.index())).collect();
    let group = |t: usize| problem.group_of(TaskId(t as u32));
    // In a cyclic route read from any rotation, the anchor's group may wrap around the end.
    let wrap_group = fixed_first.and_then(|(t, _)| {
        if problem.is_cyclic() && problem.first_task().is_none() {
            group(t.index())
        } else {
            None
        }
    });

    for t in 0..n {
        let task = TaskId(t as u32);
        if pred_mask[t] != 0 {
            continue;
        }
        if let Some(f) = problem.first_task() {
            if f != task {
                continue;
            }
        }
        if problem.last_task() == Some(task) && n > 1 {
            continue;
        }
        for (m, mode) in problem.modes(task).iter().enumerate() {
            if let Some((ft, fm)) = fixed_first {
                if ft != task || fm as usize != m {
                    continue;
                }
            }
            let c = mode.cost + start.map_or(0.0, |s| cm.cost(s, mode.entry));
            let k = idx(1 << t, t, m);
            if c < best[k] {
                best[k] = c;
            }
        }
    }
    for mask in 1..=full {
        for t in 0..n {
            if mask & (1 << t) == 0 {
                continue;
            }
            let gt = group(t);
            // Must the next task stay in t's group?
            let stay = gt.is_some_and(|g| {
                group_mask[g] & !mask != 0 && Some(g) != wrap_group_left(wrap_group, g, mask, &group_mask)
            });
            for m in 0..problem.modes(TaskId(t as u32)).len() {
                let cur = best[idx(mask, t, m)];
                if !cur.is_finite() {
                    continue;
                }
                let exit = problem.modes(TaskId(t as u32))[m].exit;
                for u in 0..n {
                    if mask & (1 << u) != 0 || pred_mask[u] & !mask != 0 {
                        continue;
                    }
                    let nmask = mask | 1 << u;
                    if problem.last_task() == Some(TaskId(u as u32)) && nmask != full {
                        continue;
                    }
                    let gu = group(u);
                    if stay && gu != gt {
                        continue;
                    }
                    if let Some(g) = gu {
                        if gu != gt && group_mask[g] & mask != 0 {
                            // re-entering a group already left: only the wrapping group, and only
                            // to finish the route with it
                            if wrap_group != Some(g) || (nmask | group_mask[g]) != full {
                                continue;
                            }
                        }
                    }
                    for (mu, mode) in problem.modes(TaskId(u as u32)).iter().enumerate() {
                        let c = cur + cm.cost(exit, mode.entry) + mode.cost;
                        let k = idx(nmask, u, mu);
                        if c < best[k] {
                            best[k] = c;
                            parent[k] = (t * mm + m) as u32;
                        }
                    }
                }
            }
        }
    }
    let mut end_best = (Cost::INFINITY, usize::MAX, usize::MAX);
    for t in 0..n {
        for (m, mode) in problem.modes(TaskId(t as u32)).iter().enumerate() {
            let c = best[idx(full, t, m)] + back.map_or(0.0, |b| cm.cost(mode.exit, b));
            if c < end_best.0 {
                end_best = (c, t, m);
            }
        }
    }
    if !end_best.0.is_finite() {
        return None;
    }
    let (cost, mut t, mut m) = end_best;
    let mut mask = full;
    let mut steps = Vec::with_capacity(n);
    loop {
        steps.push(Step { task: TaskId(t as u32), mode: m as u32 });
        let p = parent[idx(mask, t, m)];
        if p == u32::MAX {
            break;
        }
        mask &= !(1 << t);
        t = p as usize / mm;
        m = p as usize % mm;
    }
    steps.reverse();
    Some(Solution { steps, cost })
}

/// In a cyclic route whose anchor group wraps, the route may leave the anchor's group before it is
/// complete (its remaining members come at the very end). Returns `Some(g)` when that freedom
/// applies to group `g` at this point, which lifts the "must stay" rule.
fn wrap_group_left(wrap: Option<usize>, g: usize, mask: usize, group_mask: &[usize]) -> Option<usize> {
    match wrap {
        // Only while the route is still in the opening block of the wrapping group.
        Some(w) if w == g && mask & !group_mask[g] == 0 => Some(g),
        _ => None,
    }
}
