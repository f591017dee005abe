//! The one error type of the readers: where (file, line, column) and what ([`ErrorKind`]).

use std::fmt;
use std::path::{Path, PathBuf};

use towpath_seq::ModelError;

/// A refused input: the file, the line (and column, for JSON) where the problem was found, and
/// what is wrong. Displays as `path:line: problem` (or `path:line:column: problem`, or
/// `path: problem` when no line applies), e.g.
/// `kroA100.tsp:57: expected 2 coordinates for node 55, found 1`.
#[derive(Debug)]
pub struct FormatError(Box<Located>);

/// The parts of a [`FormatError`], boxed to keep `Result`s small.
#[derive(Debug)]
struct Located {
    path: PathBuf,
    line: Option<usize>,
    column: Option<usize>,
    kind: ErrorKind,
}

impl FormatError {
    fn new(path: &Path, line: Option<usize>, column: Option<usize>, kind: ErrorKind) -> Self {
        FormatError(Box::new(Located { path: path.to_path_buf(), line, column, kind }))
    }

    /// An error at a line (1-based) of a file.
    pub fn at_line(path: &Path, line: usize, kind: ErrorKind) -> Self {
        Self::new(path, Some(line), None, kind)
    }

    /// An error at a line and column (both 1-based) of a file.
    pub fn at(path: &Path, line: usize, column: usize, kind: ErrorKind) -> Self {
        Self::new(path, Some(line), Some(column), kind)
    }

    /// An error about a file as a whole (a missing keyword, an unreadable file).
    pub fn in_file(path: &Path, kind: ErrorKind) -> Self {
        Self::new(path, None, None, kind)
    }

    /// The file the error is about, as the caller named it.
    pub fn path(&self) -> &Path {
        &self.0.path
    }

    /// The 1-based line of the problem, if one applies.
    pub fn line(&self) -> Option<usize> {
        self.0.line
    }

    /// The 1-based column of the problem (JSON only).
    pub fn column(&self) -> Option<usize> {
        self.0.column
    }

    /// What is wrong.
    pub fn kind(&self) -> &ErrorKind {
        &self.0.kind
    }
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0.path.display())?;
        if let Some(l) = self.0.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.0.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": {}", self.0.kind)
    }
}

/// The message already includes the underlying I/O or model error, so no `source` is given (a
/// reporter printing the chain would repeat it).
impl std::error::Error for FormatError {}

/// What is wrong with an input. Node and set numbers are the file's own (1-based); task names
/// are the JSON file's task ids.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
    /// A line outside any data section does not start with a keyword.
    #[error("expected a keyword such as NAME, TYPE or DIMENSION, found `{0}`")]
    ExpectedKeyword(String),
    /// A keyword or section name this reader does not know.
    #[error("unknown keyword `{0}`")]
    UnknownKeyword(String),
    /// A keyword or section given twice.
    #[error("{key} is given twice (first on line {first_line})")]
    DuplicateKey {
        /// The keyword.
        key: String,
        /// Where it was first given.
        first_line: usize,
    },
    /// A required keyword or section is missing.
    #[error("missing {0}")]
    Missing(String),
    /// A problem type, edge-weight type, format or section this reader does not handle.
    #[error("{0}")]
    Unsupported(String),
    /// A keyword has a value of the wrong kind.
    #[error("{key}: `{value}` is not {expected}")]
    BadValue {
        /// The keyword.
        key: String,
        /// The value given.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// A count is larger than towpath reads.
    #[error("{key} {value} is too large: towpath reads at most {max}")]
    TooLarge {
        /// The keyword.
        key: String,
        /// The value given.
        value: String,
        /// The largest value read.
        max: u64,
    },
    /// Integer costs so large that a route's cost would not add up exactly.
    #[error(
        "{what}: a route of {moves} moves could cost up to {bound:e}, beyond 2^53 ≈ 9.0e15 where integer costs \
         stop adding up exactly; scale the {scale} down"
    )]
    InexactCosts {
        /// Where the large costs come from (the nodes, or the matrix entry).
        what: String,
        /// Moves of a route.
        moves: usize,
        /// The bound on a route's cost.
        bound: f64,
        /// What to scale: coordinates or matrix entries.
        scale: String,
    },
    /// A token that should be a number is not one.
    #[error("`{0}` is not a number")]
    NotANumber(String),
    /// A token that should be an integer (a node or set number) is not one.
    #[error("`{0}` is not an integer")]
    NotAnInteger(String),
    /// A number is NaN or infinite.
    #[error("`{0}` is not a finite number")]
    NotFinite(String),
    /// A coordinate line has the wrong number of coordinates.
    #[error("expected {expected} coordinates for node {node}, found {found}")]
    CoordinateCount {
        /// The node.
        node: u64,
        /// Coordinates the edge-weight type needs.
        expected: usize,
        /// Coordinates on the line.
        found: usize,
    },
    /// A section holds the wrong number of entries.
    #[error("{section}: expected {expected} ({detail}), found {found}")]
    WrongCount {
        /// The section.
        section: String,
        /// The count expected.
        expected: usize,
        /// The count found.
        found: usize,
        /// Why that many were expected.
        detail: String,
    },
    /// A node number outside `1..=DIMENSION`.
    #[error("node {node} is out of range 1..={dimension}")]
    NodeOutOfRange {
        /// The node number given.
        node: i64,
        /// The dimension.
        dimension: usize,
    },
    /// A node given twice.
    #[error("node {node} is given twice (first on line {first_line})")]
    DuplicateNode {
        /// The node.
        node: u64,
        /// Where it was first given.
        first_line: usize,
    },
    /// A section gives nothing for some node.
    #[error("{section} gives nothing for node {node} ({missing} of {dimension} nodes missing)")]
    MissingNode {
        /// The section.
        section: String,
        /// The first node missing.
        node: u64,
        /// How many are missing.
        missing: usize,
        /// The dimension.
        dimension: usize,
    },
    /// A set number outside `1..=GTSP_SETS`.
    #[error("set {set} is out of range 1..={sets}")]
    SetOutOfRange {
        /// The set number given.
        set: i64,
        /// The number of sets.
        sets: usize,
    },
    /// A set defined twice.
    #[error("set {set} is defined twice (first on line {first_line})")]
    DuplicateSet {
        /// The set.
        set: u64,
        /// Where it was first defined.
        first_line: usize,
    },
    /// A set with no nodes.
    #[error("set {0} has no nodes")]
    EmptySet(u64),
    /// A list that must end with -1 does not.
    #[error("{0} is not terminated by -1")]
    Unterminated(String),
    /// A node in two sets.
    #[error("node {node} is in set {first_set} and in set {second_set}")]
    NodeInTwoSets {
        /// The node.
        node: u64,
        /// The first set it is in.
        first_set: u64,
        /// The second set it is in.
        second_set: u64,
    },
    /// Nodes in no set.
    #[error("node {node} is in no set ({count} nodes are in no set)")]
    NodeInNoSet {
        /// The first such node.
        node: u64,
        /// How many nodes are in no set.
        count: usize,
    },
    /// The precedence rules contain a cycle; the members are listed in order.
    #[error("precedence cycle: {}", cycle_text(.0))]
    PrecedenceCycle(Vec<String>),
    /// Something pinned first has predecessors.
    #[error("{what} must come first, but {predecessor} must precede it")]
    CannotBeFirst {
        /// What is pinned first.
        what: String,
        /// One of its predecessors.
        predecessor: String,
    },
    /// Something pinned last has successors.
    #[error("{what} must come last, but it must precede {successor}")]
    CannotBeLast {
        /// What is pinned last.
        what: String,
        /// One of its successors.
        successor: String,
    },
    /// JSON syntax or a value of the wrong type (the message is serde_json's).
    #[error("{0}")]
    Json(String),
    /// A JSON value refers to a task id that no task has.
    #[error("{at}: unknown task id \"{id}\"")]
    UnknownTask {
        /// Where, as a JSON path such as `precedence[3][1]`.
        at: String,
        /// The id.
        id: String,
    },
    /// A JSON value is well-typed but not acceptable.
    #[error("{at}: {message}")]
    Invalid {
        /// Where, as a JSON path such as `tasks[2].modes[0].entry`.
        at: String,
        /// What is wrong.
        message: String,
    },
    /// The problem has no tasks.
    #[error("the problem has no tasks")]
    NoTasks,
    /// The sequencing model refused the problem for a reason not covered above.
    #[error("the problem cannot be built: {0}")]
    Model(ModelError),
}

fn cycle_text(cycle: &[String]) -> String {
    let mut s = cycle.join(" -> ");
    if let Some(first) = cycle.first() {
        s.push_str(" -> ");
        s.push_str(first);
    }
    s
}
