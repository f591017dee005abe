//! The sequencing model: tasks with modes, precedence, consecutive groups and route ends.
//!
//! A **task** is one piece of productive motion that must be done exactly once. Each task has one
//! or more **modes**, the ways it can be done; a mode has an entry state, an exit state and an
//! internal cost. **Precedence** is a DAG over tasks (a group-level rule is expanded to task
//! pairs). A **consecutive group** is a set of tasks that must be done one after another without
//! anything else in between. The route may start from a fixed state, end at a fixed state, return
//! to its start (a closed tour) or end anywhere (an open path).

use crate::cost::{Cost, CostModel, StateId, MAX_ROUTE_COST};
use crate::precedence::Precedence;

/// Identifies a task: an index in `0..problem.num_tasks()`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TaskId(pub u32);

impl TaskId {
    /// The task's index as a `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One way of doing a task.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mode {
    /// The state the tool must be in to begin the task this way.
    pub entry: StateId,
    /// The state the tool is left in afterwards.
    pub exit: StateId,
    /// The cost of doing the task this way (added to the route cost; 0 if irrelevant).
    pub cost: Cost,
}

impl Mode {
    /// A mode that begins and ends in the same state at no internal cost (a TSP city).
    pub fn point(state: StateId) -> Self {
        Mode { entry: state, exit: state, cost: 0.0 }
    }

    /// A mode from `entry` to `exit` at no internal cost.
    pub fn new(entry: StateId, exit: StateId) -> Self {
        Mode { entry, exit, cost: 0.0 }
    }
}

/// How the route ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// An open path: the route ends wherever its last task leaves the tool.
    Free,
    /// A closed tour: back to the start state, or, without one, back to the entry of the first
    /// task (a cycle through the tasks).
    Closed,
    /// An open path that ends by moving to this state.
    At(StateId),
}

/// Why a [`ProblemBuilder`] refused to build a problem.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A task was given no modes.
    #[error("task {0} has no modes")]
    NoModes(u32),
    /// A mode or route end names a state the cost model does not have.
    #[error("state {state} is out of range: the cost model has {num_states} states")]
    StateOutOfRange {
        /// The offending state.
        state: u32,
        /// How many states the model has.
        num_states: usize,
    },
    /// A precedence rule, group or pinned task names a task that does not exist.
    #[error("task {task} is out of range: the problem has {num_tasks} tasks")]
    TaskOutOfRange {
        /// The offending task index.
        task: u32,
        /// How many tasks there are.
        num_tasks: usize,
    },
    /// A mode cost is NaN.
    #[error("task {task} mode {mode} has a NaN cost")]
    NanCost {
        /// Task index.
        task: u32,
        /// Mode index within the task.
        mode: u32,
    },
    /// The precedence rules contain a cycle; the tasks of one cycle are listed in order.
    #[error("precedence cycle through tasks {0:?}")]
    PrecedenceCycle(Vec<u32>),
    /// A task is in more than one consecutive group.
    #[error("task {0} is in more than one consecutive group")]
    TaskInTwoGroups(u32),
    /// A consecutive group is empty.
    #[error("consecutive group {0} is empty")]
    EmptyGroup(usize),
    /// Precedence and consecutive groups contradict each other (the groups, contracted to one
    /// node each, form a precedence cycle).
    #[error("precedence rules and consecutive groups contradict each other (groups {0:?})")]
    GroupPrecedenceConflict(Vec<usize>),
    /// The pinned first task has predecessors, or the pinned last task has successors.
    #[error("task {0} is pinned first but has predecessors")]
    FirstHasPredecessors(u32),
    /// The pinned last task has successors.
    #[error("task {0} is pinned last but has successors")]
    LastHasSuccessors(u32),
    /// The same task is pinned first and last while there are other tasks.
    #[error("task {0} is pinned both first and last")]
    FirstIsLast(u32),
    /// A closed tour with no start state needs a pinned first task to give precedence a meaning.
    #[error("a closed tour without a start state has no beginning: pin a first task to use precedence")]
    PrecedenceNeedsAnchor,
    /// A route could cost more than [`MAX_ROUTE_COST`]: its costs are too large for towpath to
    /// add up.
    #[error(
        "costs are too large: a route of {transitions} moves of up to {largest:e} each could cost {bound:e}, \
         more than the {MAX_ROUTE_COST:e} towpath adds up; scale the costs or coordinates down"
    )]
    CostTooLarge {
        /// The bound on a single transition cost.
        largest: Cost,
        /// Transitions a route has at most.
        transitions: usize,
        /// The bound on a route's cost (transitions and mode costs).
        bound: Cost,
    },
}

/// A sequencing problem over a cost model `C`.
#[derive(Clone, Debug)]
pub struct Problem<C> {
    cost: C,
    mode_offsets: Vec<u32>,
    modes: Vec<Mode>,
    precedence: Precedence,
    group_of: Vec<u32>,
    groups: Vec<Vec<TaskId>>,
    start: Option<StateId>,
    end: End,
    first: Option<TaskId>,
    last: Option<TaskId>,
}

/// Marks "not in any group" in `group_of`.
pub(crate) const NO_GROUP: u32 = u32::MAX;

impl<C: CostModel> Problem<C> {
    /// Starts building a problem over `cost`.
    pub fn builder(cost: C) -> ProblemBuilder<C> {
        ProblemBuilder {
            cost,
            tasks: Vec::new(),
            edges: Vec::new(),
            groups: Vec::new(),
            start: None,
            end: End::Closed,
            first: None,
            last: None,
        }
    }

    /// The cost model.
    pub fn cost_model(&self) -> &C {
        &self.cost
    }

    /// Number of tasks.
    pub fn num_tasks(&self) -> usize {
        self.mode_offsets.len() - 1
    }

    /// All task ids in order.
    pub fn tasks(&self) -> impl Iterator<Item = TaskId> {
        (0..self.num_tasks() as u32).map(TaskId)
    }

    /// The modes of a task.
    #[inline]
    pub fn modes(&self, task: TaskId) -> &[Mode] {
        let a = self.mode_offsets[task.index()] as usize;
        let b = self.mode_offsets[task.index() + 1] as usize;
        &self.modes[a..b]
    }

    /// The largest number of modes of any task.
    pub fn max_modes(&self) -> usize {
        self.mode_offsets.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0)
    }

    /// The precedence DAG.
    pub fn precedence(&self) -> &Precedence {
        &self.precedence
    }

    /// The consecutive group of a task, if any (an index into [`Problem::groups`]).
    #[inline]
    pub fn group_of(&self, task: TaskId) -> Option<usize> {
        match self.group_of[task.index()] {
            NO_GROUP => None,
            g => Some(g as usize),
        }
    }

    /// The consecutive groups.
    pub fn groups(&self) -> &[Vec<TaskId>] {
        &self.groups
    }

    /// The fixed start state, if any.
    pub fn start(&self) -> Option<StateId> {
        self.start
    }

    /// How the route ends.
    pub fn end(&self) -> End {
        self.end
    }

    /// The task pinned first, if any.
    pub fn first_task(&self) -> Option<TaskId> {
        self.first
    }

    /// The task pinned last, if any.
    pub fn last_task(&self) -> Option<TaskId> {
        self.last
    }

    /// True for a cycle through the tasks with no start state: any rotation is the same route.
    pub fn is_cyclic(&self) -> bool {
        self.start.is_none() && self.end == End::Closed
    }

    /// Transition cost between two states.
    #[inline]
    pub fn transition(&self, from: StateId, to: StateId) -> Cost {
        self.cost.cost(from, to)
    }

    /// Cost of doing the tasks in this order with these modes (no feasibility checks; mode
    /// indices must be in range). See [`crate::check`] for the checked version.
    pub fn route_cost(&self, steps: &[crate::Step]) -> Cost {
        let mut total = 0.0;
        let mut prev: Option<StateId> = self.start;
        for s in steps {
            let m = self.modes(s.task)[s.mode as usize];
            if let Some(p) = prev {
                total += self.cost.cost(p, m.entry);
            }
            total += m.cost;
            prev = Some(m.exit);
        }
        if let Some(p) = prev {
            match self.end {
                End::Free => {}
                End::At(e) => total += self.cost.cost(p, e),
                End::Closed => {
                    if let Some(s) = self.start {
                        total += self.cost.cost(p, s);
                    } else if let Some(first) = steps.first() {
                        let m = self.modes(first.task)[first.mode as usize];
                        total += self.cost.cost(p, m.entry);
                    }
                }
            }
        }
        total
    }
}

/// Builds a [`Problem`]; see [`Problem::builder`].
#[derive(Debug)]
pub struct ProblemBuilder<C> {
    cost: C,
    tasks: Vec<Vec<Mode>>,
    edges: Vec<(u32, u32)>,
    groups: Vec<Vec<TaskId>>,
    start: Option<StateId>,
    end: End,
    first: Option<TaskId>,
    last: Option<TaskId>,
}

impl<C: CostModel> ProblemBuilder<C> {
    /// Adds a task with the given modes and returns its id.
    pub fn task(&mut self, modes: Vec<Mode>) -> TaskId {
        self.tasks.push(modes);
        TaskId(self.tasks.len() as u32 - 1)
    }

    /// Adds one single-mode task per state `0..n`, entry = exit = that state (a TSP).
    pub fn point_tasks(&mut self, n: usize) -> &mut Self {
        for i in 0..n {
            self.task(vec![Mode::point(StateId(i as u32))]);
        }
        self
    }

    /// Requires `before` to be done before `after`.
    pub fn precede(&mut self, before: TaskId, after: TaskId) -> &mut Self {
        self.edges.push((before.0, after.0));
        self
    }

    /// Requires every task of `before` to be done before every task of `after`.
    pub fn precede_groups(&mut self, before: &[TaskId], after: &[TaskId]) -> &mut Self {
        for &b in before {
            for &a in after {
                self.edges.push((b.0, a.0));
            }
        }
        self
    }

    /// Requires these tasks to be done consecutively, in any order among themselves.
    pub fn consecutive(&mut self, tasks: Vec<TaskId>) -> &mut Self {
        self.groups.push(tasks);
        self
    }

    /// Fixes the state the route starts from.
    pub fn start(&mut self, state: StateId) -> &mut Self {
        self.start = Some(state);
        self
    }

    /// Sets how the route ends (default: [`End::Closed`]).
    pub fn end(&mut self, end: End) -> &mut Self {
        self.end = end;
        self
    }

    /// Pins a task to be done first.
    pub fn first(&mut self, task: TaskId) -> &mut Self {
        self.first = Some(task);
        self
    }

    /// Pins a task to be done last.
    pub fn last(&mut self, task: TaskId) -> &mut Self {
        self.last = Some(task);
        self
    }

    /// Validates and builds the problem.
    pub fn build(self) -> Result<Problem<C>, ModelError> {
        let n = self.tasks.len();
        let num_states = self.cost.num_states();
        let check_state = |s: StateId| {
            if s.index() < num_states {
                Ok(())
            } else {
                Err(ModelError::StateOutOfRange { state: s.0, num_states })
            }
        };
        let check_task = |t: u32| {
            if (t as usize) < n {
                Ok(())
            } else {
                Err(ModelError::TaskOutOfRange { task: t, num_tasks: n })
            }
        };
        let mut mode_offsets = Vec::with_capacity(n + 1);
        let mut modes = Vec::new();
        mode_offsets.push(0u32);
        for (t, ms) in self.tasks.iter().enumerate() {
            if ms.is_empty() {
                return Err(ModelError::NoModes(t as u32));
            }
            for (k, m) in ms.iter().enumerate() {
                check_state(m.entry)?;
                check_state(m.exit)?;
                if m.cost.is_nan() {
                    return Err(ModelError::NanCost { task: t as u32, mode: k as u32 });
                }
            }
            modes.extend_from_slice(ms);
            mode_offsets.push(modes.len() as u32);
        }
        if let Some(s) = self.start {
            check_state(s)?;
        }
        if let Some(largest) = self.cost.cost_bound() {
            // One move into each task and one to end the route, plus every task's dearest mode.
            let transitions = n + 1;
            let modes_cost: Cost = self
                .tasks
                .iter()
                .map(|ms| ms.iter().filter(|m| m.cost.is_finite()).fold(0.0, |a: Cost, m| a.max(m.cost.abs())))
                .sum();
            let bound = largest * transitions as Cost + modes_cost;
            if bound.is_nan() || bound > MAX_ROUTE_COST {
                return Err(ModelError::CostTooLarge { largest, transitions, bound });
            }
        }
        if let End::At(s) = self.end {
            check_state(s)?;
        }
        for &(a, b) in &self.edges {
            check_task(a)?;
            check_task(b)?;
        }
        let precedence = Precedence::new(n, &self.edges).map_err(ModelError::PrecedenceCycle)?;

        let mut group_of = vec![NO_GROUP; n];
        for (g, members) in self.groups.iter().enumerate() {
            if members.is_empty() {
                return Err(ModelError::EmptyGroup(g));
            }
            for t in members {
                check_task(t.0)?;
                if group_of[t.index()] != NO_GROUP {
                    return Err(ModelError::TaskInTwoGroups(t.0));
                }
                group_of[t.index()] = g as u32;
            }
        }
        if !self.groups.is_empty() && precedence.num_edges() > 0 {
            check_groups_against_precedence(n, &group_of, self.groups.len(), &precedence)?;
        }
        if let Some(f) = self.first {
            check_task(f.0)?;
            if !precedence.predecessors(f).is_empty() {
                return Err(ModelError::FirstHasPredecessors(f.0));
            }
        }
        if let Some(l) = self.last {
            check_task(l.0)?;
            if !precedence.successors(l).is_empty() {
                return Err(ModelError::LastHasSuccessors(l.0));
            }
            if self.first == Some(l) && n > 1 {
                return Err(ModelError::FirstIsLast(l.0));
            }
        }
        if self.start.is_none() && self.end == End::Closed && precedence.num_edges() > 0 && self.first.is_none() {
            return Err(ModelError::PrecedenceNeedsAnchor);
        }
        Ok(Problem {
            cost: self.cost,
            mode_offsets,
            modes,
            precedence,
            group_of,
            groups: self.groups,
            start: self.start,
            end: self.end,
            first: self.first,
            last: self.last,
        })
    }
}

/// Contracts each consecutive group to one node and checks the contracted precedence graph for
/// cycles: if one exists, no order can satisfy both.
fn check_groups_against_precedence(
    n: usize,
    group_of: &[u32],
    num_groups: usize,
    prec: &Precedence,
) -> Result<(), ModelError> {
    // Node ids: groups 0..num_groups, ungrouped tasks num_groups + task.
    let node = |t: usize| match group_of[t] {
        NO_GROUP => num_groups + t,
        g => g as usize,
    };
    let mut edges = Vec::new();
    for t in 0..n {
        for &s in prec.successors(TaskId(t as u32)) {
            let (a, b) = (node(t), node(s.index()));
            if a != b {
                edges.push((a as u32, b as u32));
            }
        }
    }
    match Precedence::new(num_groups + n, &edges) {
        Ok(_) => Ok(()),
        Err(cycle) => Err(ModelError::GroupPrecedenceConflict(
            cycle.into_iter().filter(|&x| (x as usize) < num_groups).map(|x| x as usize).collect(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cost::{MatrixCost, Metric, PointCost};

    #[test]
    fn costs_too_large_to_add_up_are_refused() {
        // Five points 4e19 apart at most: fine (a route costs at most 6 · 4e19).
        let pts: Vec<[f64; 3]> = [0.0, 3e19, 1e19, 4e19, 2e19].iter().map(|&x| [x, 0.0, 0.0]).collect();
        let mut b = Problem::builder(PointCost::new(pts, Metric::EuclideanNint));
        b.point_tasks(5);
        assert!(b.build().is_ok());
        // 5e149 apart: 3 moves exceed MAX_ROUTE_COST.
        let mut b = Problem::builder(PointCost::new(vec![[0.0; 3], [5e149, 0.0, 0.0]], Metric::Euclidean));
        b.point_tasks(2);
        let e = b.build().unwrap_err();
        assert!(matches!(e, ModelError::CostTooLarge { transitions: 3, .. }), "{e}");
        // A matrix entry of 1e300 (forbidden entries do not count), or a mode cost.
        let mut b = Problem::builder(MatrixCost::new(2, vec![0.0, 1e300, f64::INFINITY, 0.0]).unwrap());
        b.point_tasks(2);
        assert!(matches!(b.build(), Err(ModelError::CostTooLarge { .. })));
        let mut b = Problem::builder(MatrixCost::new(2, vec![0.0, 1.0, f64::INFINITY, 0.0]).unwrap());
        b.point_tasks(2);
        assert!(b.build().is_ok());
        let mut b = Problem::builder(MatrixCost::new(1, vec![0.0]).unwrap());
        b.task(vec![Mode { entry: StateId(0), exit: StateId(0), cost: 1e200 }]);
        assert!(matches!(b.build(), Err(ModelError::CostTooLarge { .. })));
    }
}
