//! Writing any loaded instance back out as towpath's JSON problem format, so that another
//! program (a peer solver in the benchmarks, a user's script) reads exactly the problem towpath
//! solves without parsing TSPLIB itself.

use towpath_seq::{CostModel, End, Metric, Problem, StateId, TaskId};

use crate::instance::{Instance, Kind, LoadedProblem, Numbering};
use crate::json::{JsonEnd, JsonMetric, JsonMode, JsonProblem, JsonStates, JsonTask};
use crate::metric::FileMetric;

/// How [`Instance::to_json`] writes the transition costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CostsAs {
    /// As the instance holds them: points with their metric for coordinate files, the matrix
    /// for explicit ones (compact: no n² matrix for a coordinate file).
    #[default]
    Native,
    /// Always an explicit matrix (every point distance computed), for programs that know no
    /// metric. Forbidden moves are `null`.
    Matrix,
}

/// The most entries [`Instance::to_json`] writes as a matrix computed from points (about 45
/// bytes each in memory and pretty-printed text: a 5000-node instance).
pub const MAX_MATRIX_ENTRIES: u64 = 25_000_000;

/// An instance [`Instance::to_json`] does not write.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExportError {
    /// The matrix of a coordinate instance would be too large.
    #[error(
        "a matrix of {states} × {states} = {entries} costs is too large to write (at most {MAX_MATRIX_ENTRIES}, a \
         {side}-node instance); write the points and their metric instead"
    )]
    MatrixTooLarge {
        /// States of the instance.
        states: usize,
        /// Entries the matrix would have.
        entries: u64,
        /// The largest number of states written as a matrix.
        side: u64,
    },
}

impl Instance {
    /// The instance as a [`JsonProblem`]: the same states, costs, tasks and modes (in the same
    /// order), precedence, consecutive groups, pins and ends, so that every route has the same
    /// feasibility and cost in both. Task ids are the file's node numbers (`"1"`, `"2"`, …) for
    /// TSP/ATSP/SOP, `"set1"`, `"set2"`, … for GTSP/PCGTSP (a mode's `entry` is then its node
    /// number minus one), and the original ids for JSON problems.
    ///
    /// A coordinate instance written as a matrix ([`CostsAs::Matrix`]) is refused above
    /// [`MAX_MATRIX_ENTRIES`]: its n² costs are not bounded by the file's size. (An explicit matrix
    /// is written as read.)
    pub fn to_json(&self, costs: CostsAs) -> Result<JsonProblem, ExportError> {
        if let (LoadedProblem::Points(p), CostsAs::Matrix) = (&self.problem, costs) {
            let states = p.cost_model().num_states();
            let entries = (states as u64).saturating_mul(states as u64);
            if entries > MAX_MATRIX_ENTRIES {
                let side = (MAX_MATRIX_ENTRIES as f64).sqrt() as u64;
                return Err(ExportError::MatrixTooLarge { states, entries, side });
            }
        }
        let ids = self.task_ids();
        let states = match (&self.problem, costs) {
            (LoadedProblem::Points(p), CostsAs::Native) => {
                let model = p.cost_model();
                let three_d = model.points().iter().any(|q| q[2] != 0.0);
                let dims = if three_d { 3 } else { 2 };
                JsonStates {
                    points: Some(model.points().iter().map(|q| q[..dims].to_vec()).collect()),
                    metric: Some(json_metric(model.metric())),
                    matrix: None,
                }
            }
            (LoadedProblem::Points(p), CostsAs::Matrix) => matrix_states(p.cost_model()),
            (LoadedProblem::Matrix(p), _) => matrix_states(p.cost_model()),
        };
        Ok(crate::with_problem!(&self.problem, p => structure(p, &ids, states, Some(self.name.clone()))))
    }

    /// One id per task, in task order (see [`Instance::to_json`]).
    fn task_ids(&self) -> Vec<String> {
        match &self.numbering {
            Numbering::Tasks(ids) => ids.clone(),
            Numbering::Nodes(node_of) => match self.kind {
                Kind::Gtsp | Kind::Pcgtsp => (1..=node_of.len()).map(|k| format!("set{k}")).collect(),
                _ => node_of
                    .iter()
                    .enumerate()
                    .map(|(t, modes)| modes.first().map_or_else(|| format!("task{}", t + 1), |n| n.to_string()))
                    .collect(),
            },
        }
    }
}

/// Every transition cost as a matrix row by row; non-finite costs (forbidden moves) are `null`.
fn matrix_states<C: CostModel>(model: &C) -> JsonStates {
    let n = model.num_states();
    let rows = (0..n as u32)
        .map(|i| {
            (0..n as u32)
                .map(|j| {
                    let c = model.cost(StateId(i), StateId(j));
                    c.is_finite().then_some(c)
                })
                .collect()
        })
        .collect();
    JsonStates { points: None, metric: None, matrix: Some(rows) }
}

/// Tasks, modes, precedence, groups, pins and ends of `p`, named by `ids`.
fn structure<C: CostModel>(p: &Problem<C>, ids: &[String], states: JsonStates, name: Option<String>) -> JsonProblem {
    let id = |t: TaskId| ids.get(t.index()).cloned().unwrap_or_else(|| format!("task{}", t.0 + 1));
    let tasks = p
        .tasks()
        .map(|t| JsonTask {
            id: id(t),
            modes: p
                .modes(t)
                .iter()
                .map(|m| JsonMode { entry: m.entry.0, exit: (m.exit != m.entry).then_some(m.exit.0), cost: m.cost })
                .collect(),
        })
        .collect();
    let precedence =
        p.tasks().flat_map(|t| p.precedence().successors(t).iter().map(move |&s| (t, s))).map(|(a, b)| (id(a), id(b)));
    JsonProblem {
        name,
        states,
        tasks,
        precedence: precedence.collect(),
        consecutive: p.groups().iter().map(|g| g.iter().map(|&t| id(t)).collect()).collect(),
        start: p.start().map(|s| s.0),
        end: match p.end() {
            End::Closed => JsonEnd::Closed,
            End::Free => JsonEnd::Free,
            End::At(s) => JsonEnd::At(s.0),
        },
        first: p.first_task().map(id),
        last: p.last_task().map(id),
    }
}

fn json_metric(m: FileMetric) -> JsonMetric {
    match m {
        FileMetric::Plain(Metric::Euclidean) => JsonMetric::Euclidean,
        FileMetric::Plain(Metric::EuclideanNint) => JsonMetric::EuclideanNint,
        FileMetric::Plain(Metric::EuclideanCeil) => JsonMetric::EuclideanCeil,
        FileMetric::Att => JsonMetric::Att,
        FileMetric::Plain(Metric::ManhattanNint) => JsonMetric::ManhattanNint,
        FileMetric::Plain(Metric::Manhattan) => JsonMetric::Manhattan,
        FileMetric::Plain(Metric::MaximumNint) => JsonMetric::MaximumNint,
        FileMetric::Geo => JsonMetric::Geo,
    }
}
