//! A loaded instance: the sequencing problem plus what is needed to print answers in the file's
//! own numbering.

use std::fmt;

use crate::metric::FileMetric;
use serde::Serialize;
use towpath_seq::{CostModel, End, MatrixCost, PointCost, Problem, Step, TaskId, Violation};

/// What kind of file an instance came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// TSPLIB symmetric TSP: a closed tour through every node.
    Tsp,
    /// TSPLIB asymmetric TSP: a closed tour through every node.
    Atsp,
    /// TSPLIB sequential ordering problem: an open path from node 1 to node n under precedence.
    Sop,
    /// Generalized TSP (GTSP-LIB, GLNS format): a closed tour through one node of every set.
    Gtsp,
    /// Precedence-constrained GTSP (PCGLNS format): a GTSP with precedence between sets and a
    /// start set.
    Pcgtsp,
    /// towpath's native JSON problem format.
    Json,
}

impl Kind {
    /// The canonical name (`TSP`, `ATSP`, `SOP`, `GTSP`, `PCGTSP`, `JSON`), as in the benchmark
    /// index.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Tsp => "TSP",
            Kind::Atsp => "ATSP",
            Kind::Sop => "SOP",
            Kind::Gtsp => "GTSP",
            Kind::Pcgtsp => "PCGTSP",
            Kind::Json => "JSON",
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A problem over one of the two cost models the readers produce. Coordinate files give
/// [`PointCost`] (distances on demand, never an n² matrix); explicit matrices give
/// [`MatrixCost`]. Use [`with_problem!`](crate::with_problem) to run generic code on either.
#[derive(Clone, Debug)]
pub enum LoadedProblem {
    /// Costs from an explicit matrix.
    Matrix(Problem<MatrixCost>),
    /// Costs computed from point coordinates.
    Points(Problem<PointCost<FileMetric>>),
}

/// Runs an expression on the problem inside a [`LoadedProblem`], whichever cost model it has:
/// `with_problem!(&instance.problem, p => towpath_seq::solve(p, &options))`. The expression is
/// compiled once per cost model, so the solver is dispatched statically.
#[macro_export]
macro_rules! with_problem {
    ($loaded:expr, $p:ident => $body:expr) => {
        match $loaded {
            $crate::LoadedProblem::Matrix($p) => $body,
            $crate::LoadedProblem::Points($p) => $body,
        }
    };
}

impl LoadedProblem {
    /// Number of tasks.
    pub fn num_tasks(&self) -> usize {
        with_problem!(self, p => p.num_tasks())
    }

    /// Number of states of the cost model.
    pub fn num_states(&self) -> usize {
        with_problem!(self, p => p.cost_model().num_states())
    }

    /// Checks a route with [`towpath_seq::check`] and returns its cost.
    pub fn check(&self, steps: &[Step]) -> Result<f64, Violation> {
        with_problem!(self, p => towpath_seq::check(p, steps))
    }
}

/// How tasks and modes map back to the file's numbering.
#[derive(Clone, Debug)]
pub(crate) enum Numbering {
    /// TSPLIB-style files: `node_of[task][mode]` is the file's 1-based node number.
    Nodes(Vec<Vec<u32>>),
    /// JSON files: the task ids.
    Tasks(Vec<String>),
}

/// One step of an answer to a JSON problem: the task id and the index of the mode used.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct TaskStep {
    /// The task's id as given in the file.
    pub task: String,
    /// Index of the mode in the task's `modes` list.
    pub mode: u32,
}

/// A route in the file's own terms. Serializes as a JSON array: node numbers for TSPLIB-style
/// files, `{"task": id, "mode": index}` objects for JSON problems.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum Answer {
    /// 1-based node numbers: a permutation for TSP/ATSP (from node 1), the path from node 1 to
    /// node n for SOP, one node per set for GTSP/PCGTSP (from the start set, or the first set).
    Nodes(Vec<u32>),
    /// Task ids with mode indices, for JSON problems.
    Tasks(Vec<TaskStep>),
}

impl Answer {
    /// Number of steps.
    pub fn len(&self) -> usize {
        match self {
            Answer::Nodes(v) => v.len(),
            Answer::Tasks(v) => v.len(),
        }
    }

    /// True if there are no steps.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl fmt::Display for Answer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Answer::Nodes(v) => {
                for (i, n) in v.iter().enumerate() {
                    if i > 0 {
                        f.write_str(" ")?;
                    }
                    write!(f, "{n}")?;
                }
            }
            Answer::Tasks(v) => {
                for (i, s) in v.iter().enumerate() {
                    if i > 0 {
                        f.write_str(" ")?;
                    }
                    write!(f, "{}#{}", s.task, s.mode)?;
                }
            }
        }
        Ok(())
    }
}

/// A node number that the instance does not have (see [`Instance::steps_from_nodes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("node {0} is not a node of the instance")]
pub struct UnknownNode(pub u32);

/// A problem read from a file, with its name, kind and numbering.
#[derive(Clone, Debug)]
pub struct Instance {
    /// The `NAME` of the file (or JSON `name`), else the file name without extension.
    pub name: String,
    /// The kind of file.
    pub kind: Kind,
    /// The number of nodes (TSPLIB `DIMENSION`) or, for JSON, of states.
    pub dimension: usize,
    /// The sequencing problem.
    pub problem: LoadedProblem,
    pub(crate) numbering: Numbering,
    /// The one fixed edge of a TSP/ATSP file's `FIXED_EDGES_SECTION`, if it has one: the
    /// problem is then the open path between its ends (see [`FixedEdge`]).
    pub fixed_edge: Option<FixedEdge>,
}

/// A TSP or ATSP file's one fixed edge, read as TSPLIB's linhp318 reads it: the tour must use
/// the edge from node `a` to node `b`, so what is solved is the Hamiltonian path from `b` to `a`
/// through every node; the fixed edge closes it into the tour and is not counted in the cost
/// (TSPLIB publishes linhp318's optimum that way). Answers list the path, from `b` to `a`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct FixedEdge {
    /// The edge's first node as written (1-based); the path ends here.
    pub a: u32,
    /// The edge's second node (1-based); the path starts here.
    pub b: u32,
}

impl FixedEdge {
    /// The node the path starts from (`b`).
    pub fn path_from(&self) -> u32 {
        self.b
    }

    /// The node the path ends at (`a`).
    pub fn path_to(&self) -> u32 {
        self.a
    }
}

impl Instance {
    /// Number of tasks (nodes for TSP/ATSP/SOP, sets for GTSP/PCGTSP).
    pub fn num_tasks(&self) -> usize {
        self.problem.num_tasks()
    }

    /// The route `steps` in the file's own numbering (see [`Answer`]). A closed tour without a
    /// start state is rotated: TSP/ATSP tours to begin at node 1, others to begin with the task
    /// pinned first (the PCGLNS start set) or else task 0 (the first set, the first JSON task). Steps naming tasks or modes the problem does not have are
    /// skipped; pass routes through [`LoadedProblem::check`] first.
    pub fn answer(&self, steps: &[Step]) -> Answer {
        let (closed_cycle, first) =
            with_problem!(&self.problem, p => (p.end() == End::Closed && p.start().is_none(), p.first_task()));
        let target = match self.kind {
            _ if !closed_cycle => None,
            Kind::Tsp | Kind::Atsp => Some(TaskId(0)),
            _ => Some(first.unwrap_or(TaskId(0))),
        };
        let offset = target.and_then(|t| steps.iter().position(|s| s.task == t)).unwrap_or(0);
        let rotated = steps.iter().skip(offset).chain(steps.iter().take(offset));
        match &self.numbering {
            Numbering::Nodes(node_of) => Answer::Nodes(
                rotated
                    .filter_map(|s| node_of.get(s.task.index()).and_then(|m| m.get(s.mode as usize)).copied())
                    .collect(),
            ),
            Numbering::Tasks(ids) => Answer::Tasks(
                rotated
                    .filter_map(|s| ids.get(s.task.index()).map(|id| TaskStep { task: id.clone(), mode: s.mode }))
                    .collect(),
            ),
        }
    }

    /// Turns a route given as the file's node numbers (a TSPLIB tour: every node for TSP/ATSP/SOP,
    /// one node per set for GTSP) into steps. Feasibility is not checked here: pass the steps
    /// to [`LoadedProblem::check`].
    pub fn steps_from_nodes(&self, nodes: &[u32]) -> Result<Vec<Step>, UnknownNode> {
        let mut lookup = std::collections::HashMap::new();
        if let Numbering::Nodes(node_of) = &self.numbering {
            for (t, modes) in node_of.iter().enumerate() {
                for (m, &node) in modes.iter().enumerate() {
                    lookup.entry(node).or_insert(Step { task: TaskId(t as u32), mode: m as u32 });
                }
            }
        }
        let mut steps: Vec<Step> =
            nodes.iter().map(|&n| lookup.get(&n).copied().ok_or(UnknownNode(n))).collect::<Result<_, _>>()?;
        self.rotate_to_first(&mut steps);
        Ok(steps)
    }

    /// A closed tour without a start state is a cycle: rotate it to begin with the task pinned
    /// first, if any, so that the checker reads it from there.
    fn rotate_to_first(&self, steps: &mut [Step]) {
        let (closed_cycle, first) =
            with_problem!(&self.problem, p => (p.end() == End::Closed && p.start().is_none(), p.first_task()));
        if let (true, Some(f)) = (closed_cycle, first) {
            if let Some(k) = steps.iter().position(|s| s.task == f) {
                steps.rotate_left(k);
            }
        }
    }

    /// Turns a route given as JSON task ids with mode indices into steps (JSON problems only).
    pub fn steps_from_tasks(&self, route: &[TaskStep]) -> Result<Vec<Step>, String> {
        let Numbering::Tasks(ids) = &self.numbering else {
            return Err("the instance has numbered nodes, not task ids".into());
        };
        let index: std::collections::HashMap<&str, u32> =
            ids.iter().enumerate().map(|(i, id)| (id.as_str(), i as u32)).collect();
        let mut steps = route
            .iter()
            .map(|s| match index.get(s.task.as_str()) {
                Some(&t) => Ok(Step { task: TaskId(t), mode: s.mode }),
                None => Err(format!("unknown task id \"{}\"", s.task)),
            })
            .collect::<Result<Vec<_>, _>>()?;
        self.rotate_to_first(&mut steps);
        Ok(steps)
    }
}
