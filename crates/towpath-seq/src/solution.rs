//! Solutions and the independent checker.
//!
//! The checker shares no code with the solvers: it recomputes feasibility and cost from the
//! problem definition alone, so tests can trust it to judge them.

use crate::cost::{Cost, CostModel};
use crate::model::{End, Problem, TaskId};

/// One step of a route: a task done in one of its modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Step {
    /// The task.
    pub task: TaskId,
    /// Index into the task's modes.
    pub mode: u32,
}

/// A route: every task once, in order, each with a mode, and its cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// The steps in order.
    pub steps: Vec<Step>,
    /// The route cost as computed by [`crate::check`].
    pub cost: Cost,
}

/// Why a route is not a feasible solution of a problem.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Violation {
    /// The route has the wrong number of steps.
    #[error("the route has {got} steps but the problem has {expected} tasks")]
    WrongLength {
        /// Steps in the route.
        got: usize,
        /// Tasks in the problem.
        expected: usize,
    },
    /// A step names a task that does not exist.
    #[error("step {step} names task {task}, which does not exist")]
    UnknownTask {
        /// Position in the route.
        step: usize,
        /// The task index given.
        task: u32,
    },
    /// A task appears twice.
    #[error("task {task} appears twice (steps {first} and {second})")]
    Duplicate {
        /// The task.
        task: u32,
        /// Its first position.
        first: usize,
        /// Its second position.
        second: usize,
    },
    /// A step names a mode the task does not have.
    #[error("step {step}: task {task} has no mode {mode}")]
    UnknownMode {
        /// Position in the route.
        step: usize,
        /// The task.
        task: u32,
        /// The mode index given.
        mode: u32,
    },
    /// A precedence rule is broken.
    #[error("task {before} must come before task {after}")]
    Precedence {
        /// The task that should have come first.
        before: u32,
        /// The task that came too early.
        after: u32,
    },
    /// A consecutive group is interrupted.
    #[error("consecutive group {group} is interrupted at step {step}")]
    GroupSplit {
        /// The group.
        group: usize,
        /// Where the group is entered a second time.
        step: usize,
    },
    /// The pinned first task is not first.
    #[error("task {0} is pinned first but is not first")]
    NotFirst(u32),
    /// The pinned last task is not last.
    #[error("task {0} is pinned last but is not last")]
    NotLast(u32),
    /// A transition or mode on the route has a non-finite cost (a forbidden move).
    #[error("the route uses a forbidden (non-finite cost) transition at step {0}")]
    Forbidden(usize),
    /// Every move of the route has a finite cost but their sum does not fit in a [`Cost`].
    #[error("the route's cost overflows: its moves are finite but their sum is not")]
    CostOverflow,
}

/// Checks that `steps` is a feasible route of `problem` and returns its cost, recomputed from
/// scratch.
///
/// For a closed tour without a start state and without a pinned first task, any rotation is
/// accepted; otherwise the route is read from its first step.
pub fn check<C: CostModel>(problem: &Problem<C>, steps: &[Step]) -> Result<Cost, Violation> {
    let n = problem.num_tasks();
    if steps.len() != n {
        return Err(Violation::WrongLength { got: steps.len(), expected: n });
    }
    let mut pos = vec![usize::MAX; n];
    for (i, s) in steps.iter().enumerate() {
        let t = s.task.index();
        if t >= n {
            return Err(Violation::UnknownTask { step: i, task: s.task.0 });
        }
        if pos[t] != usize::MAX {
            return Err(Violation::Duplicate { task: s.task.0, first: pos[t], second: i });
        }
        pos[t] = i;
        if s.mode as usize >= problem.modes(s.task).len() {
            return Err(Violation::UnknownMode { step: i, task: s.task.0, mode: s.mode });
        }
    }
    for t in problem.tasks() {
        for &after in problem.precedence().successors(t) {
            if pos[t.index()] > pos[after.index()] {
                return Err(Violation::Precedence { before: t.0, after: after.0 });
            }
        }
    }
    if let Some(f) = problem.first_task() {
        if pos[f.index()] != 0 {
            return Err(Violation::NotFirst(f.0));
        }
    }
    if let Some(l) = problem.last_task() {
        if pos[l.index()] != n - 1 {
            return Err(Violation::NotLast(l.0));
        }
    }
    check_groups(problem, steps)?;

    // Cost, step by step.
    let cm = problem.cost_model();
    let mode = |s: &Step| problem.modes(s.task)[s.mode as usize];
    let mut total: Cost = 0.0;
    let mut prev = problem.start();
    for (i, s) in steps.iter().enumerate() {
        let m = mode(s);
        let mut c = m.cost;
        if let Some(p) = prev {
            c += cm.cost(p, m.entry);
        }
        if !c.is_finite() {
            return Err(Violation::Forbidden(i));
        }
        total += c;
        prev = Some(m.exit);
    }
    if let Some(p) = prev {
        let back = match problem.end() {
            End::Free => 0.0,
            End::At(e) => cm.cost(p, e),
            End::Closed => match problem.start() {
                Some(s) => cm.cost(p, s),
                None => cm.cost(p, mode(&steps[0]).entry),
            },
        };
        if !back.is_finite() {
            return Err(Violation::Forbidden(n));
        }
        total += back;
    }
    if !total.is_finite() {
        return Err(Violation::CostOverflow);
    }
    Ok(total)
}

fn check_groups<C: CostModel>(problem: &Problem<C>, steps: &[Step]) -> Result<(), Violation> {
    if problem.groups().is_empty() {
        return Ok(());
    }
    let cyclic = problem.is_cyclic() && problem.first_task().is_none();
    // In a cyclic route a group may wrap around the end: rotate to start at a group boundary.
    let n = steps.len();
    let mut offset = 0;
    if cyclic && n > 0 {
        let g0 = problem.group_of(steps[0].task);
        if g0.is_some() {
            // find a position i where steps[i-1] is in a different group than steps[i]
            offset =
                (1..n).find(|&i| problem.group_of(steps[i].task) != problem.group_of(steps[i - 1].task)).unwrap_or(0);
        }
    }
    let mut done = vec![false; problem.groups().len()];
    let mut current: Option<usize> = None;
    for k in 0..n {
        let i = (k + offset) % n;
        let g = problem.group_of(steps[i].task);
        if g != current {
            if let Some(c) = current {
                done[c] = true;
            }
            if let Some(gn) = g {
                if done[gn] {
                    return Err(Violation::GroupSplit { group: gn, step: i });
                }
            }
            current = g;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cost::StateId;
    use crate::model::Mode;

    /// Every move costs 1e308, and the model gives no bound: the route's sum overflows.
    struct Huge;
    impl CostModel for Huge {
        fn num_states(&self) -> usize {
            3
        }
        fn cost(&self, from: StateId, to: StateId) -> Cost {
            if from == to {
                0.0
            } else {
                1e308
            }
        }
    }

    #[test]
    fn an_overflowing_sum_is_not_a_cost() {
        let mut b = Problem::builder(Huge);
        for s in 0..3 {
            b.task(vec![Mode::point(StateId(s))]);
        }
        let p = b.build().unwrap();
        let steps: Vec<Step> = (0..3).map(|t| Step { task: TaskId(t), mode: 0 }).collect();
        assert_eq!(check(&p, &steps), Err(Violation::CostOverflow));
    }
}
