//! towpath's native JSON problem format (documented in `docs/json-format.md`).
//!
//! [`JsonProblem`] is the file's serde model; [`JsonProblem::to_instance`] validates it and
//! builds the sequencing problem. Syntax and type errors carry serde_json's line and column;
//! errors found afterwards (an unknown task id, a state out of range, a precedence cycle) are
//! located in the text by their JSON path.

use std::collections::HashMap;
use std::path::Path;

use crate::metric::FileMetric;
use serde::{Deserialize, Serialize};
use towpath_seq::{End, MatrixCost, Metric, Mode, ModelError, PointCost, Problem, ProblemBuilder, StateId, TaskId};

use crate::error::{ErrorKind, FormatError};
use crate::instance::{Instance, Kind, LoadedProblem, Numbering};
use crate::json_locate::{locate, path_text, Seg};
use crate::json_shape::{friendly, MapOnly};
use crate::tsplib::default_name;

/// A problem in towpath's JSON format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub struct JsonProblem {
    /// A name for reports (default: the file name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The states (machine configurations, points) and the cost of moving between them.
    pub states: JsonStates,
    /// The tasks, each done exactly once in one of its modes.
    pub tasks: Vec<JsonTask>,
    /// `[before, after]` pairs of task ids.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub precedence: Vec<(String, String)>,
    /// Groups of task ids to be done one after another, in any order among themselves.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub consecutive: Vec<Vec<String>>,
    /// The state the route starts from (a home position), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<u32>,
    /// How the route ends (default: closed).
    #[serde(default)]
    pub end: JsonEnd,
    /// The task to do first, if pinned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first: Option<String>,
    /// The task to do last, if pinned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub last: Option<String>,
}

/// The states: either points with a metric, or an explicit matrix.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub struct JsonStates {
    /// One point per state, 2 or 3 coordinates each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<Vec<f64>>>,
    /// How point distances become costs (default: euclidean).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metric: Option<JsonMetric>,
    /// Square matrix, `matrix[i][j]` = cost of moving from state i to state j; `null` forbids
    /// the move.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<Vec<Vec<Option<f64>>>>,
}

/// Point metrics (TSPLIB's roundings included).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JsonMetric {
    /// Euclidean distance.
    Euclidean,
    /// Euclidean, rounded to the nearest integer (TSPLIB EUC_2D).
    EuclideanNint,
    /// Euclidean, rounded up (TSPLIB CEIL_2D).
    EuclideanCeil,
    /// TSPLIB pseudo-Euclidean ATT.
    Att,
    /// Manhattan distance.
    Manhattan,
    /// Manhattan, rounded to the nearest integer (TSPLIB MAN_2D).
    ManhattanNint,
    /// Maximum (Chebyshev), rounded to the nearest integer (TSPLIB MAX_2D).
    MaximumNint,
    /// TSPLIB GEO: coordinates are DDD.MM latitude and longitude.
    Geo,
}

impl JsonMetric {
    fn metric(self) -> FileMetric {
        match self {
            JsonMetric::Euclidean => FileMetric::Plain(Metric::Euclidean),
            JsonMetric::EuclideanNint => FileMetric::Plain(Metric::EuclideanNint),
            JsonMetric::EuclideanCeil => FileMetric::Plain(Metric::EuclideanCeil),
            JsonMetric::Att => FileMetric::Att,
            JsonMetric::Manhattan => FileMetric::Plain(Metric::Manhattan),
            JsonMetric::ManhattanNint => FileMetric::Plain(Metric::ManhattanNint),
            JsonMetric::MaximumNint => FileMetric::Plain(Metric::MaximumNint),
            JsonMetric::Geo => FileMetric::Geo,
        }
    }
}

/// A task: an id and its modes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub struct JsonTask {
    /// Unique id, used by precedence, groups, pins and answers.
    pub id: String,
    /// The ways of doing the task (at least one).
    pub modes: Vec<JsonMode>,
}

/// A mode: entry state, exit state (default: the entry) and internal cost (default 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub struct JsonMode {
    /// State index where the task begins this way.
    pub entry: u32,
    /// State index where it ends (default: `entry`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit: Option<u32>,
    /// Cost of doing the task this way (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub cost: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// How the route ends: `"closed"` (back to the start state, or a cycle), `"free"` (an open path)
/// or `{"at": state}` (an open path ending at that state).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JsonEnd {
    /// A closed tour.
    #[default]
    Closed,
    /// An open path.
    Free,
    /// An open path ending at this state.
    At(u32),
}

/// The format's structs are read from JSON objects only (see [`MapOnly`]); written as usual.
macro_rules! objects_only {
    ($($t:ident),*) => {$(
        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                $t::deserialize(MapOnly(d))
            }
        }
        impl Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                $t::serialize(self, s)
            }
        }
    )*};
}

objects_only!(JsonProblem, JsonStates, JsonTask, JsonMode);

/// Parses JSON text into the serde model (no validation beyond types).
pub fn parse_json_problem(text: &str, path: &Path) -> Result<JsonProblem, FormatError> {
    serde_json::from_str(text).map_err(|e| {
        let (line, column) = (e.line(), e.column());
        let msg = e.to_string();
        let msg = friendly(msg.strip_suffix(&format!(" at line {line} column {column}")).unwrap_or(&msg));
        if line == 0 {
            FormatError::in_file(path, ErrorKind::Json(msg))
        } else {
            FormatError::at(path, line, column.max(1), ErrorKind::Json(msg))
        }
    })
}

/// Parses and validates a JSON problem file.
pub fn parse_json(text: &str, path: &Path) -> Result<Instance, FormatError> {
    parse_json_problem(text, path)?.to_instance(text, path)
}

/// Writes a problem as pretty-printed JSON.
pub fn write_json(problem: &JsonProblem) -> String {
    // Serializing these plain structs cannot fail (no maps with non-string keys); fall back to
    // an empty object rather than panic.
    serde_json::to_string_pretty(problem).unwrap_or_else(|_| "{}".into())
}

/// Validation context: the source text (to locate paths) and the file name.
struct Ctx<'a> {
    text: &'a str,
    path: &'a Path,
}

impl Ctx<'_> {
    fn err(&self, at: &[Seg], kind: ErrorKind) -> FormatError {
        match locate(self.text, at) {
            Some((l, c)) => FormatError::at(self.path, l, c, kind),
            None => FormatError::in_file(self.path, kind),
        }
    }

    fn invalid(&self, at: &[Seg], message: String) -> FormatError {
        self.err(at, ErrorKind::Invalid { at: path_text(at), message })
    }
}

impl JsonProblem {
    /// Validates the problem and builds the instance. `text` is the JSON it was read from (used
    /// only to give errors a line and column; pass `""` if there is none).
    pub fn to_instance(&self, text: &str, path: &Path) -> Result<Instance, FormatError> {
        let ctx = Ctx { text, path };
        let num_states = self.check_states(&ctx)?;
        if self.tasks.is_empty() {
            return Err(ctx.err(&[Seg::Key("tasks")], ErrorKind::NoTasks));
        }
        let mut index: HashMap<&str, u32> = HashMap::new();
        for (t, task) in self.tasks.iter().enumerate() {
            let at = [Seg::Key("tasks"), Seg::Index(t), Seg::Key("id")];
            if let Some(&prev) = index.get(task.id.as_str()) {
                return Err(ctx.invalid(&at, format!("task id \"{}\" is used twice (first by tasks[{prev}])", task.id)));
            }
            index.insert(&task.id, t as u32);
            if task.modes.is_empty() {
                return Err(ctx.invalid(&at[..2], format!("task \"{}\" has no modes", task.id)));
            }
            for (k, m) in task.modes.iter().enumerate() {
                for (field, s) in [("entry", Some(m.entry)), ("exit", m.exit)] {
                    if let Some(s) = s.filter(|&s| s as usize >= num_states) {
                        let at = [Seg::Key("tasks"), Seg::Index(t), Seg::Key("modes"), Seg::Index(k), Seg::Key(field)];
                        return Err(ctx.invalid(&at, state_range(s, num_states)));
                    }
                }
            }
        }
        let task_id = |id: &str, at: &[Seg]| {
            index
                .get(id)
                .map(|&t| TaskId(t))
                .ok_or_else(|| ctx.err(at, ErrorKind::UnknownTask { at: path_text(at), id: id.into() }))
        };
        let mut edges = Vec::with_capacity(self.precedence.len());
        for (k, (a, b)) in self.precedence.iter().enumerate() {
            let ta = task_id(a, &[Seg::Key("precedence"), Seg::Index(k), Seg::Index(0)])?;
            let tb = task_id(b, &[Seg::Key("precedence"), Seg::Index(k), Seg::Index(1)])?;
            edges.push((ta, tb, k));
        }
        let mut groups = Vec::with_capacity(self.consecutive.len());
        for (g, group) in self.consecutive.iter().enumerate() {
            let mut members = Vec::with_capacity(group.len());
            for (k, id) in group.iter().enumerate() {
                members.push(task_id(id, &[Seg::Key("consecutive"), Seg::Index(g), Seg::Index(k)])?);
            }
            groups.push(members);
        }
        let first = self.first.as_deref().map(|id| task_id(id, &[Seg::Key("first")])).transpose()?;
        let last = self.last.as_deref().map(|id| task_id(id, &[Seg::Key("last")])).transpose()?;
        if let Some(s) = self.start.filter(|&s| s as usize >= num_states) {
            return Err(ctx.invalid(&[Seg::Key("start")], state_range(s, num_states)));
        }
        let end = match self.end {
            JsonEnd::Closed => End::Closed,
            JsonEnd::Free => End::Free,
            JsonEnd::At(s) if (s as usize) < num_states => End::At(StateId(s)),
            JsonEnd::At(s) => return Err(ctx.invalid(&[Seg::Key("end"), Seg::Key("at")], state_range(s, num_states))),
        };
        let setup = Setup { edges: &edges, groups: &groups, first, last, end, start: self.start };
        let problem = match (&self.states.points, &self.states.matrix) {
            (Some(points), _) => {
                let coord = |p: &[f64], k: usize| p.get(k).copied().unwrap_or(0.0);
                let pts = points.iter().map(|p| [coord(p, 0), coord(p, 1), coord(p, 2)]).collect();
                let metric = self.states.metric.unwrap_or(JsonMetric::Euclidean).metric();
                let cost = PointCost::new(pts, metric);
                let (line, _) = locate(text, &[Seg::Key("states"), Seg::Key("points")]).unwrap_or((1, 1));
                let label = |s: u32| format!("states.points[{s}]");
                crate::tsplib::check_exact(&cost, self.tasks.len() + 1, &label, line, path)?;
                LoadedProblem::Points(self.build(cost, &setup, &ctx)?)
            }
            (None, Some(rows)) => {
                let n = rows.len();
                let data = rows.iter().flatten().map(|c| c.unwrap_or(f64::INFINITY)).collect();
                let m = MatrixCost::new(n, data).ok_or_else(|| {
                    ctx.invalid(&[Seg::Key("states"), Seg::Key("matrix")], "the matrix is not square".into())
                })?;
                LoadedProblem::Matrix(self.build(m, &setup, &ctx)?)
            }
            (None, None) => return Err(ctx.invalid(&[Seg::Key("states")], "give `points` or `matrix`".into())),
        };
        let name = self.name.clone().filter(|s| !s.is_empty()).unwrap_or_else(|| default_name(path));
        let ids = self.tasks.iter().map(|t| t.id.clone()).collect();
        Ok(Instance {
            name,
            kind: Kind::Json,
            dimension: num_states,
            problem,
            numbering: Numbering::Tasks(ids),
            fixed_edge: None,
        })
    }

    /// Checks the states and returns their number.
    fn check_states(&self, ctx: &Ctx<'_>) -> Result<usize, FormatError> {
        let st = &self.states;
        let at = |rest: &[Seg<'static>]| [&[Seg::Key("states")][..], rest].concat();
        match (&st.points, &st.matrix) {
            (Some(_), Some(_)) => Err(ctx.invalid(&at(&[]), "give either `points` or `matrix`, not both".into())),
            (None, None) => Err(ctx.invalid(&at(&[]), "give `points` (with a `metric`) or `matrix`".into())),
            (Some(points), None) => {
                for (i, p) in points.iter().enumerate() {
                    if !(2..=3).contains(&p.len()) {
                        return Err(ctx.invalid(
                            &at(&[Seg::Key("points"), Seg::Index(i)]),
                            format!("a point has 2 or 3 coordinates, found {}", p.len()),
                        ));
                    }
                }
                Ok(points.len())
            }
            (None, Some(rows)) => {
                if st.metric.is_some() {
                    return Err(ctx.invalid(&at(&[Seg::Key("metric")]), "`metric` applies to `points` only".into()));
                }
                let n = rows.len();
                for (i, r) in rows.iter().enumerate() {
                    if r.len() != n {
                        return Err(ctx.invalid(
                            &at(&[Seg::Key("matrix"), Seg::Index(i)]),
                            format!("row {i} has {} entries; the matrix has {n} rows", r.len()),
                        ));
                    }
                }
                Ok(n)
            }
        }
    }

    fn build<C: towpath_seq::CostModel>(
        &self,
        cost: C,
        s: &Setup<'_>,
        ctx: &Ctx<'_>,
    ) -> Result<Problem<C>, FormatError> {
        let mut b: ProblemBuilder<C> = Problem::builder(cost);
        for task in &self.tasks {
            b.task(
                task.modes
                    .iter()
                    .map(|m| Mode { entry: StateId(m.entry), exit: StateId(m.exit.unwrap_or(m.entry)), cost: m.cost })
                    .collect(),
            );
        }
        for &(a, bb, _) in s.edges {
            b.precede(a, bb);
        }
        for g in s.groups {
            b.consecutive(g.clone());
        }
        if let Some(st) = s.start {
            b.start(StateId(st));
        }
        b.end(s.end);
        if let Some(f) = s.first {
            b.first(f);
        }
        if let Some(l) = s.last {
            b.last(l);
        }
        b.build().map_err(|e| self.model_error(e, s, ctx))
    }

    fn model_error(&self, e: ModelError, s: &Setup<'_>, ctx: &Ctx<'_>) -> FormatError {
        let label = |t: u32| format!("task \"{}\"", self.tasks.get(t as usize).map_or("?", |x| x.id.as_str()));
        let rule = |k: usize| [Seg::Key("precedence"), Seg::Index(k)];
        match e {
            ModelError::PrecedenceCycle(cycle) => {
                let a = cycle.first().copied();
                let b = cycle.get(1).or(cycle.first()).copied();
                let k = s.edges.iter().find(|e| Some(e.0 .0) == a && Some(e.1 .0) == b).map_or(0, |e| e.2);
                ctx.err(&rule(k), ErrorKind::PrecedenceCycle(cycle.iter().map(|&t| label(t)).collect()))
            }
            ModelError::FirstHasPredecessors(t) => {
                let p = s.edges.iter().find(|e| e.1 .0 == t).map_or(t, |e| e.0 .0);
                ctx.err(&[Seg::Key("first")], ErrorKind::CannotBeFirst { what: label(t), predecessor: label(p) })
            }
            ModelError::LastHasSuccessors(t) => {
                let q = s.edges.iter().find(|e| e.0 .0 == t).map_or(t, |e| e.1 .0);
                ctx.err(&[Seg::Key("last")], ErrorKind::CannotBeLast { what: label(t), successor: label(q) })
            }
            ModelError::FirstIsLast(t) => {
                ctx.invalid(&[Seg::Key("last")], format!("{} is pinned both first and last", label(t)))
            }
            ModelError::TaskInTwoGroups(t) => {
                ctx.invalid(&[Seg::Key("consecutive")], format!("{} is in more than one consecutive group", label(t)))
            }
            ModelError::EmptyGroup(g) => ctx.invalid(
                &[Seg::Key("consecutive"), Seg::Index(g)],
                "a consecutive group needs at least one task".into(),
            ),
            ModelError::GroupPrecedenceConflict(groups) => ctx.invalid(
                &[Seg::Key("consecutive")],
                format!("consecutive groups {groups:?} and the precedence rules contradict each other"),
            ),
            ModelError::PrecedenceNeedsAnchor => ctx.invalid(
                &[Seg::Key("precedence")],
                "a closed tour without `start` has no beginning: pin a `first` task, give a `start` state or make \
                 `end` \"free\""
                    .into(),
            ),
            e @ ModelError::CostTooLarge { .. } => ctx.invalid(&[Seg::Key("states")], e.to_string()),
            other => ctx.err(&[], ErrorKind::Model(other)),
        }
    }
}

/// What [`JsonProblem::build`] adds besides tasks.
struct Setup<'a> {
    edges: &'a [(TaskId, TaskId, usize)],
    groups: &'a [Vec<TaskId>],
    first: Option<TaskId>,
    last: Option<TaskId>,
    end: End,
    start: Option<u32>,
}

fn state_range(s: u32, n: usize) -> String {
    format!("state {s} is out of range: there are {n} states (numbered from 0)")
}
