//! TSPLIB-style problem files: TSP, ATSP, SOP (TSPLIB95, SOPLIB), GTSP/AGTSP (GTSP-LIB in the
//! GLNS format) and PCGLNS (precedence-constrained GTSP), turned into sequencing problems.
//!
//! | file | tasks | modes | route | precedence |
//! |---|---|---|---|---|
//! | TSP, ATSP | one per node | the node | closed tour | — |
//! | SOP | one per node | the node | open path, node 1 first, node n last | `c[i][j] = -1`: j before i |
//! | GTSP, AGTSP | one per set | one per node of the set | closed tour | — |
//! | PCGLNS | one per set | one per node of the set | closed tour from the start set | `GTSP_SET_ORDERING` |
//!
//! In SOP and PCGLNS matrices an entry of -1 marks a forbidden move (+∞ cost); everywhere else
//! the matrix is taken as given (large TSPLIB "infinities" such as 9999 stay costs).

use std::path::Path;

use towpath_seq::{
    CostModel, End, MatrixCost, Metric, Mode, ModelError, PointCost, Problem, ProblemBuilder, StateId, TaskId,
    EXACT_INTEGER_LIMIT,
};

use crate::coords::read_coords;
use crate::error::{ErrorKind, FormatError};
use crate::instance::{FixedEdge, Instance, Kind, LoadedProblem, Numbering};
use crate::matrix::parse_integer;
use crate::matrix::{read_matrix, WeightFormat};
use crate::metric::FileMetric;
use crate::sets::{read_ordering, read_sets, read_start};
use crate::text::{lex, Document, Section};

/// The coordinate edge-weight types: (name, coordinates per node, metric).
const COORD_TYPES: &[(&str, usize, FileMetric)] = &[
    ("EUC_2D", 2, FileMetric::Plain(Metric::EuclideanNint)),
    ("EUC_3D", 3, FileMetric::Plain(Metric::EuclideanNint)),
    ("CEIL_2D", 2, FileMetric::Plain(Metric::EuclideanCeil)),
    ("ATT", 2, FileMetric::Att),
    ("GEO", 2, FileMetric::Geo),
    ("MAN_2D", 2, FileMetric::Plain(Metric::ManhattanNint)),
    ("MAN_3D", 3, FileMetric::Plain(Metric::ManhattanNint)),
    ("MAX_2D", 2, FileMetric::Plain(Metric::MaximumNint)),
    ("MAX_3D", 3, FileMetric::Plain(Metric::MaximumNint)),
];

/// Costs as read: points or a full matrix (with its -1 entries and their lines).
enum Costs {
    Points(PointCost<FileMetric>),
    Matrix { n: usize, data: Vec<f64>, minus_ones: Vec<(usize, usize, usize)> },
}

/// Parses a TSPLIB-style problem file (`path` is used for messages and the default name).
pub fn parse_tsplib(text: &str, path: &Path) -> Result<Instance, FormatError> {
    let doc = lex(text, path)?;
    let kind = detect_kind(&doc, path)?;
    check_sections(&doc, kind, path)?;
    let n = dimension(&doc, path)?;
    let name = doc
        .entry("NAME")
        .map(|e| strip_extension(e.value).to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| default_name(path));
    let costs = read_costs(&doc, kind, n, path)?;
    let mut fixed_edge = None;
    let (problem, numbering) = match kind {
        Kind::Tsp | Kind::Atsp => {
            let fixed = match doc.section("FIXED_EDGES_SECTION") {
                Some(s) => read_fixed_edge(s, n, path)?,
                None => None,
            };
            fixed_edge = fixed.map(|(a, b)| FixedEdge { a: a + 1, b: b + 1 });
            (build_tsp(costs, n, fixed, path)?, Numbering::Nodes((1..=n as u32).map(|v| vec![v]).collect()))
        }
        Kind::Sop => (build_sop(costs, n, path)?, Numbering::Nodes((1..=n as u32).map(|v| vec![v]).collect())),
        Kind::Gtsp | Kind::Pcgtsp => build_gtsp(&doc, kind, costs, n, path)?,
        Kind::Json => return Err(FormatError::in_file(path, ErrorKind::Unsupported("not a TSPLIB file".into()))),
    };
    Ok(Instance { name, kind, dimension: n, problem, numbering, fixed_edge })
}

/// A name without a known file extension (`ESC07.sop` → `ESC07`, `br17.10.sop` → `br17.10`).
fn strip_extension(name: &str) -> &str {
    for ext in [".tsp", ".atsp", ".sop", ".gtsp", ".pcglns", ".opt.tour", ".tour", ".json"] {
        if let Some(s) = name.strip_suffix(ext) {
            return s;
        }
    }
    name
}

/// The file name without its extensions, for instances without a `NAME`.
pub(crate) fn default_name(path: &Path) -> String {
    let file = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
    strip_extension(&file).to_string()
}

fn detect_kind(doc: &Document<'_>, path: &Path) -> Result<Kind, FormatError> {
    let ty = doc.entry("TYPE");
    let word = ty.and_then(|e| e.value.split_whitespace().next()).unwrap_or("TSP");
    let line = ty.map_or(1, |e| e.line);
    if doc.section("GTSP_SET_SECTION").is_some() {
        let pc = matches!(word, "PCGLNS" | "PCGTSP")
            || doc.section("GTSP_SET_ORDERING").is_some()
            || doc.section("START_GROUP_SECTION").is_some();
        return Ok(if pc { Kind::Pcgtsp } else { Kind::Gtsp });
    }
    match word {
        "TSP" => Ok(Kind::Tsp),
        "ATSP" => Ok(Kind::Atsp),
        "SOP" => Ok(Kind::Sop),
        "GTSP" | "AGTSP" | "PCGLNS" | "PCGTSP" => {
            Err(FormatError::in_file(path, ErrorKind::Missing("GTSP_SET_SECTION".into())))
        }
        "TOUR" => Err(FormatError::at_line(
            path,
            line,
            ErrorKind::Unsupported("this is a tour file (TYPE: TOUR), not a problem".into()),
        )),
        other => Err(FormatError::at_line(
            path,
            line,
            ErrorKind::Unsupported(format!(
                "TYPE {other} is not supported: towpath reads TSP, ATSP, SOP, GTSP, AGTSP and PCGLNS"
            )),
        )),
    }
}

/// Refuses sections the kind cannot honour (rather than silently ignoring them).
fn check_sections(doc: &Document<'_>, kind: Kind, path: &Path) -> Result<(), FormatError> {
    for s in &doc.sections {
        let ok = match s.name {
            "NODE_COORD_SECTION" | "EDGE_WEIGHT_SECTION" | "DISPLAY_DATA_SECTION" => true,
            "GTSP_SET_SECTION" => matches!(kind, Kind::Gtsp | Kind::Pcgtsp),
            "GTSP_SET_ORDERING" | "START_GROUP_SECTION" => kind == Kind::Pcgtsp,
            "FIXED_EDGES_SECTION" => matches!(kind, Kind::Tsp | Kind::Atsp),
            _ => false,
        };
        if !ok {
            return Err(FormatError::at_line(
                path,
                s.line,
                ErrorKind::Unsupported(format!("{} is not supported in a {kind} file", s.name)),
            ));
        }
    }
    Ok(())
}

/// The most nodes (and sets) a file may have: node and task numbers are 32-bit.
pub(crate) const MAX_DIMENSION: u64 = u32::MAX as u64 - 1;

/// `DIMENSION`: the number of nodes, from 1 to [`MAX_DIMENSION`].
fn dimension(doc: &Document<'_>, path: &Path) -> Result<usize, FormatError> {
    let e = doc.entry("DIMENSION").ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("DIMENSION".into())))?;
    count(e.value, "DIMENSION", e.line, path)
}

/// A count keyword's value: a positive integer up to [`MAX_DIMENSION`]; a larger one (even one
/// beyond 64 bits) is refused as too large, not as "not an integer".
pub(crate) fn count(value: &str, key: &str, line: usize, path: &Path) -> Result<usize, FormatError> {
    let digits = value.strip_prefix('+').unwrap_or(value);
    let all_digits = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
    match digits.parse::<u64>() {
        Ok(n) if (1..=MAX_DIMENSION).contains(&n) => Ok(n as usize),
        Ok(n) if n > MAX_DIMENSION => Err(too_large(key, value, line, path)),
        Err(_) if all_digits && digits.trim_start_matches('0').len() > 3 => Err(too_large(key, value, line, path)),
        _ => Err(FormatError::at_line(
            path,
            line,
            ErrorKind::BadValue { key: key.into(), value: value.into(), expected: "a positive integer".into() },
        )),
    }
}

fn too_large(key: &str, value: &str, line: usize, path: &Path) -> FormatError {
    let value = crate::matrix::short(value);
    FormatError::at_line(path, line, ErrorKind::TooLarge { key: key.into(), value, max: MAX_DIMENSION })
}

fn read_costs(doc: &Document<'_>, kind: Kind, n: usize, path: &Path) -> Result<Costs, FormatError> {
    let ewt = doc
        .entry("EDGE_WEIGHT_TYPE")
        .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("EDGE_WEIGHT_TYPE".into())))?;
    if ewt.value == "EXPLICIT" {
        let fmt_entry = doc
            .entry("EDGE_WEIGHT_FORMAT")
            .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("EDGE_WEIGHT_FORMAT".into())))?;
        let format = WeightFormat::from_name(fmt_entry.value).ok_or_else(|| {
            FormatError::at_line(
                path,
                fmt_entry.line,
                ErrorKind::Unsupported(format!(
                    "EDGE_WEIGHT_FORMAT {} is not supported with EXPLICIT weights: use FULL_MATRIX, UPPER_ROW, LOWER_ROW, \
                     UPPER_DIAG_ROW, LOWER_DIAG_ROW, UPPER_COL, LOWER_COL, UPPER_DIAG_COL or LOWER_DIAG_COL",
                    fmt_entry.value
                )),
            )
        })?;
        let section = doc
            .section("EDGE_WEIGHT_SECTION")
            .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("EDGE_WEIGHT_SECTION".into())))?;
        let m = read_matrix(section, n, format, path)?;
        if let Some((v, i, j, line)) = m.largest {
            // TSPLIB matrices hold integers: a route of n moves must add up exactly.
            let bound = v.abs() * n as f64;
            if bound > EXACT_INTEGER_LIMIT {
                return Err(FormatError::at_line(
                    path,
                    line,
                    ErrorKind::InexactCosts {
                        what: format!("the entry for node {} to node {} is {v}", i + 1, j + 1),
                        moves: n,
                        bound,
                        scale: "matrix entries".into(),
                    },
                ));
            }
        }
        return Ok(Costs::Matrix { n, data: m.data, minus_ones: m.minus_ones });
    }
    let Some(&(_, dims, metric)) = COORD_TYPES.iter().find(|t| t.0 == ewt.value) else {
        return Err(FormatError::at_line(
            path,
            ewt.line,
            ErrorKind::Unsupported(format!(
                "EDGE_WEIGHT_TYPE {} is not supported: towpath reads EXPLICIT, EUC_2D, EUC_3D, CEIL_2D, ATT, GEO, \
                 MAN_2D, MAN_3D, MAX_2D and MAX_3D",
                ewt.value
            )),
        ));
    };
    if kind == Kind::Sop {
        return Err(FormatError::at_line(
            path,
            ewt.line,
            ErrorKind::Unsupported("a SOP needs EDGE_WEIGHT_TYPE EXPLICIT (precedence is read from the matrix)".into()),
        ));
    }
    if let Some(s) = doc.section("EDGE_WEIGHT_SECTION") {
        return Err(FormatError::at_line(
            path,
            s.line,
            ErrorKind::Unsupported(format!("EDGE_WEIGHT_SECTION given, but EDGE_WEIGHT_TYPE is {}", ewt.value)),
        ));
    }
    let section = doc
        .section("NODE_COORD_SECTION")
        .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("NODE_COORD_SECTION".into())))?;
    let points = read_coords(section, n, dims, path)?;
    let cost = PointCost::new(points, metric);
    check_exact(&cost, n, &|node| format!("node {}", node + 1), section.line, path)?;
    Ok(Costs::Points(cost))
}

/// A coordinate for a message: plain when short, else in exponent form (`4e19`).
fn number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Refuses points so far apart that a route of `moves` integer distances (TSPLIB's roundings)
/// could exceed 2⁵³ and no longer add up exactly, naming the two states farthest apart (by
/// `label`) and pointing at `line`.
pub(crate) fn check_exact(
    cost: &PointCost<FileMetric>,
    moves: usize,
    label: &dyn Fn(u32) -> String,
    line: usize,
    path: &Path,
) -> Result<(), FormatError> {
    let largest = cost.cost_bound().unwrap_or(0.0);
    let bound = largest * moves as f64;
    if !cost.is_integral() || bound <= EXACT_INTEGER_LIMIT {
        return Ok(());
    }
    let (a, b) = cost.farthest_apart().unwrap_or((StateId(0), StateId(0)));
    let (pa, pb) = (cost.points()[a.index()], cost.points()[b.index()]);
    let axis = (0..3).max_by(|&x, &y| (pb[x] - pa[x]).abs().total_cmp(&(pb[y] - pa[y]).abs())).unwrap_or(0);
    let what = format!(
        "{} ({} = {}) and {} ({} = {}) are {} apart",
        label(a.0),
        ["x", "y", "z"][axis],
        number(pa[axis]),
        label(b.0),
        ["x", "y", "z"][axis],
        number(pb[axis]),
        number((pb[axis] - pa[axis]).abs())
    );
    Err(FormatError::at_line(path, line, ErrorKind::InexactCosts { what, moves, bound, scale: "coordinates".into() }))
}

/// Replaces -1 entries by +∞ (forbidden moves) in SOP and PCGLNS matrices.
fn forbid_minus_ones(n: usize, data: &mut [f64], minus_ones: &[(usize, usize, usize)]) {
    for &(i, j, _) in minus_ones {
        if let Some(v) = data.get_mut(i * n + j) {
            *v = f64::INFINITY;
        }
    }
}

fn matrix(n: usize, data: Vec<f64>, path: &Path) -> Result<MatrixCost, FormatError> {
    MatrixCost::new(n, data)
        .ok_or_else(|| FormatError::in_file(path, ErrorKind::Unsupported("internal: matrix size mismatch".into())))
}

/// `FIXED_EDGES_SECTION`: `a b` pairs ended by -1. One fixed edge is supported, as in TSPLIB's
/// linhp318 (the Hamiltonian-path version of lin318): the problem becomes the open path from b
/// to a, whose cost is the tour's less the fixed edge's (a constant), which is also the value
/// TSPLIB publishes. More edges are refused. Returns the 0-based `(a, b)`.
fn read_fixed_edge(section: &Section<'_>, n: usize, path: &Path) -> Result<Option<(u32, u32)>, FormatError> {
    let mut nodes = Vec::new();
    for (line, tok) in section.tokens() {
        let v = parse_integer(tok, line, path)?;
        if v == -1 {
            break;
        }
        let idx = usize::try_from(v)
            .ok()
            .filter(|&x| (1..=n).contains(&x))
            .ok_or_else(|| FormatError::at_line(path, line, ErrorKind::NodeOutOfRange { node: v, dimension: n }))?;
        nodes.push(((idx - 1) as u32, line));
    }
    match nodes.as_slice() {
        [] => Ok(None),
        [(a, _), (b, line)] => {
            if a == b {
                return Err(FormatError::at_line(
                    path,
                    *line,
                    ErrorKind::Unsupported(format!("fixed edge {} {} is a loop", a + 1, b + 1)),
                ));
            }
            Ok(Some((*a, *b)))
        }
        [_] => Err(FormatError::at_line(path, section.last_line(), ErrorKind::Unterminated("the fixed edge".into()))),
        _ => Err(FormatError::at_line(
            path,
            section.line,
            ErrorKind::Unsupported("FIXED_EDGES_SECTION with more than one edge is not supported".into()),
        )),
    }
}

fn build_tsp(costs: Costs, n: usize, fixed: Option<(u32, u32)>, path: &Path) -> Result<LoadedProblem, FormatError> {
    fn tsp<C: towpath_seq::CostModel>(
        cost: C,
        n: usize,
        fixed: Option<(u32, u32)>,
        path: &Path,
    ) -> Result<Problem<C>, FormatError> {
        let mut b = Problem::builder(cost);
        b.point_tasks(n).end(End::Closed);
        if let Some((a, z)) = fixed {
            // A tour through the edge a-b is a Hamiltonian path from b to a plus the edge's own
            // (constant) cost: solve the path, as TSPLIB's published value for linhp318 does.
            b.end(End::Free).first(TaskId(z)).last(TaskId(a));
        }
        b.build().map_err(|e| FormatError::in_file(path, ErrorKind::Model(e)))
    }
    Ok(match costs {
        Costs::Points(p) => LoadedProblem::Points(tsp(p, n, fixed, path)?),
        Costs::Matrix { n, data, .. } => LoadedProblem::Matrix(tsp(matrix(n, data, path)?, n, fixed, path)?),
    })
}

fn build_sop(costs: Costs, n: usize, path: &Path) -> Result<LoadedProblem, FormatError> {
    let Costs::Matrix { n: _, mut data, minus_ones } = costs else {
        return Err(FormatError::in_file(path, ErrorKind::Unsupported("a SOP needs an explicit matrix".into())));
    };
    forbid_minus_ones(n, &mut data, &minus_ones);
    let mut b = Problem::builder(matrix(n, data, path)?);
    b.point_tasks(n);
    // c[i][j] = -1: node j precedes node i.
    let edges: Vec<(u32, u32, usize)> = minus_ones.iter().map(|&(i, j, line)| (j as u32, i as u32, line)).collect();
    for &(before, after, _) in &edges {
        b.precede(TaskId(before), TaskId(after));
    }
    b.end(End::Free).first(TaskId(0)).last(TaskId(n as u32 - 1));
    let label = |t: u32| format!("node {}", t + 1);
    Ok(LoadedProblem::Matrix(build(b, &edges, &label, path)?))
}

fn build_gtsp(
    doc: &Document<'_>,
    kind: Kind,
    costs: Costs,
    n: usize,
    path: &Path,
) -> Result<(LoadedProblem, Numbering), FormatError> {
    let declared = match doc.entry("GTSP_SETS") {
        Some(e) => Some((count(e.value, "GTSP_SETS", e.line, path)?, e.line)),
        None => None,
    };
    let section = doc
        .section("GTSP_SET_SECTION")
        .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("GTSP_SET_SECTION".into())))?;
    let sets = read_sets(section, n, declared, path)?;
    let m = sets.members.len();
    let mut edges = Vec::new();
    let mut start = None;
    if kind == Kind::Pcgtsp {
        if let Some(s) = doc.section("GTSP_SET_ORDERING") {
            edges = read_ordering(s, m, path)?;
        }
        let s = doc
            .section("START_GROUP_SECTION")
            .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("START_GROUP_SECTION".into())))?;
        start = Some(read_start(s, m, path)?.0);
    }
    let label = |t: u32| format!("set {}", t + 1);
    let problem = match costs {
        Costs::Points(p) => {
            let b = gtsp_builder(p, &sets.members, &edges, start);
            LoadedProblem::Points(build(b, &edges, &label, path)?)
        }
        Costs::Matrix { n, mut data, minus_ones } => {
            if kind == Kind::Pcgtsp {
                forbid_minus_ones(n, &mut data, &minus_ones);
            }
            let b = gtsp_builder(matrix(n, data, path)?, &sets.members, &edges, start);
            LoadedProblem::Matrix(build(b, &edges, &label, path)?)
        }
    };
    Ok((problem, Numbering::Nodes(sets.members)))
}

/// One task per set, one mode per node of the set; a closed tour, pinned to begin with the start
/// set if there is one.
fn gtsp_builder<C: towpath_seq::CostModel>(
    cost: C,
    members: &[Vec<u32>],
    edges: &[(u32, u32, usize)],
    start: Option<u32>,
) -> ProblemBuilder<C> {
    let mut b = Problem::builder(cost);
    for set in members {
        b.task(set.iter().map(|&v| Mode::point(StateId(v - 1))).collect());
    }
    for &(before, after, _) in edges {
        b.precede(TaskId(before), TaskId(after));
    }
    b.end(End::Closed);
    if let Some(s) = start {
        b.first(TaskId(s));
    }
    b
}

/// Builds a problem, translating model errors into the file's terms: cycles and impossible
/// pins name the file's nodes or sets and the line of a rule involved.
fn build<C: towpath_seq::CostModel>(
    b: ProblemBuilder<C>,
    edges: &[(u32, u32, usize)],
    label: &dyn Fn(u32) -> String,
    path: &Path,
) -> Result<Problem<C>, FormatError> {
    b.build().map_err(|e| model_error(e, edges, label, path))
}

pub(crate) fn model_error(
    e: ModelError,
    edges: &[(u32, u32, usize)],
    label: &dyn Fn(u32) -> String,
    path: &Path,
) -> FormatError {
    let at = |line: Option<usize>, kind: ErrorKind| match line {
        Some(l) => FormatError::at_line(path, l, kind),
        None => FormatError::in_file(path, kind),
    };
    match e {
        ModelError::PrecedenceCycle(cycle) => {
            let a = cycle.first().copied();
            let b = cycle.get(1).or(cycle.first()).copied();
            let line = edges.iter().find(|e| Some(e.0) == a && Some(e.1) == b).map(|e| e.2);
            at(line, ErrorKind::PrecedenceCycle(cycle.iter().map(|&t| label(t)).collect()))
        }
        ModelError::FirstHasPredecessors(t) => match edges.iter().find(|e| e.1 == t) {
            Some(&(p, _, line)) => at(Some(line), ErrorKind::CannotBeFirst { what: label(t), predecessor: label(p) }),
            None => at(None, ErrorKind::Model(ModelError::FirstHasPredecessors(t))),
        },
        ModelError::LastHasSuccessors(t) => match edges.iter().find(|e| e.0 == t) {
            Some(&(_, s, line)) => at(Some(line), ErrorKind::CannotBeLast { what: label(t), successor: label(s) }),
            None => at(None, ErrorKind::Model(ModelError::LastHasSuccessors(t))),
        },
        other => at(None, ErrorKind::Model(other)),
    }
}
