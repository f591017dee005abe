//! Errors of the AFP program layer.

use towpath_baselines::BaselineError;
use towpath_machine::{CostError, MachineError};
use towpath_seq::{ModelError, SolveError};

/// Why a program, dialect or request was refused, or an optimization failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NcError {
    /// A problem at one line of the program (1-based).
    #[error("line {line}: {message}")]
    Line {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A line that cannot stand inside a course (while the roller is in contact or tows are
    /// on); the parser names the course it is in.
    #[error("line {line}: {message} (inside a course)")]
    InCourse {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A program towpath would write does not pass the motion-safety checks (a collision with
    /// the cell or an axis outside its travel limits), so it is not written.
    #[error("motion safety: {0}")]
    Unsafe(String),
    /// The dialect file or settings are wrong.
    #[error("dialect: {0}")]
    Dialect(String),
    /// The machine does not fit the program or the request.
    #[error("machine: {0}")]
    Machine(String),
    /// The program needs a course width and none was given.
    #[error("{0}")]
    Width(String),
    /// Precedence between plies needs course footprints, hence a width, and none was given (in
    /// the options or the dialect). Front ends say how to give one (a command-line flag, a
    /// request field) or to check ply by ply, which needs none.
    #[error(
        "the program has {plies} plies and {} between them needs course footprints, so a course or tow width, \
         and none was given (neither in the options nor in the dialect); ply-by-ply precedence needs none",
        if *.checking { "checking precedence" } else { "precedence" }
    )]
    NeedsWidth {
        /// Plies that hold courses.
        plies: usize,
        /// True when the verifier needs it (false: the optimizer).
        checking: bool,
    },
    /// A tow width was given but a course restarts no tows, so it has no width by tows: a
    /// course width is needed.
    #[error(
        "line {line}: this course restarts no tows, so a tow width cannot give its width: a course width is needed"
    )]
    TowWidthWithoutTows {
        /// 1-based line where the course's on-part block starts.
        line: usize,
    },
    /// Course footprints need the tool point, and the machine has no kinematics.
    #[error(
        "course footprints need the tool point: give the machine a DH chain or X/Y/Z linear axes (ply-by-ply \
         precedence needs no footprints)"
    )]
    NoToolPoint,
    /// Doherty et al.'s solver orders every precedence set freely, so it cannot keep the order of the
    /// courses within each ply.
    #[error(
        "doherty cannot keep the order of the courses within each ply: Doherty et al.'s solver orders every \
         precedence set freely"
    )]
    DohertyKeepsNoPlyOrder,
    /// The course width cannot be right for this program: narrower than the overlap tolerance
    /// (footprints would vanish) or far wider than the whole laid part (most likely a width in
    /// other units).
    #[error("a course width of {} mm {problem}", short(.width))]
    ImplausibleWidth {
        /// The widest course width the width gives, mm.
        width: f64,
        /// What is wrong with it.
        problem: String,
    },
    /// A laid tool point lies on or near the mandrel's axis, so the footprints cannot be
    /// unrolled around the mandrel: almost always a mandrel `origin` (or `direction`) in the
    /// machine file that does not match the program.
    #[error(
        "line {line}: the tool point is {radius:.4} mm from the mandrel axis (through {origin:?} along {direction:?}) \
         while laying a course {width:.3} mm wide: closer than the width / 2π ({min:.4} mm), so the course would wrap the \
         whole mandrel and its footprint cannot be unrolled; check the origin and direction of the machine's mandrel \
         axis {label} against the program's axis values",
        min = width / std::f64::consts::TAU
    )]
    MandrelAxis {
        /// 1-based line of the laid move.
        line: usize,
        /// The tool point's distance from the mandrel axis, mm.
        radius: f64,
        /// The course width there, mm.
        width: f64,
        /// Index of the mandrel among the machine's axes.
        axis: usize,
        /// The mandrel axis's label.
        label: String,
        /// The axis's origin, as used.
        origin: [f64; 3],
        /// The axis's unit direction, as used.
        direction: [f64; 3],
    },
    /// Building or checking precedence would take more work or memory than towpath allows
    /// (footprints far denser than any real part's).
    #[error("{what}: more than {limit} {unit}; {advice}")]
    WorkLimit {
        /// What was being built.
        what: String,
        /// The limit that was reached.
        limit: u64,
        /// What is counted.
        unit: String,
        /// What to do instead.
        advice: String,
    },
    /// The request cannot be met (for example, a tool cost on a machine without kinematics).
    #[error("{0}")]
    Request(String),
    /// The sequencing engine refused the problem.
    #[error("sequencing: {0}")]
    Sequencing(String),
    /// The chosen solver cannot sequence this program (one of the published solvers towpath is built from: the
    /// message names it and what it cannot handle).
    #[error("{0}")]
    Solver(String),
    /// The optimizer's own output did not verify (a bug: the input is left untouched).
    #[error("the optimized program did not verify: {0}")]
    SelfCheck(String),
    /// The run was cancelled through its cancel flag.
    #[error("cancelled")]
    Cancelled,
}

/// A number for a message: as it is when it reads well, else in exponent form.
fn short(v: &f64) -> String {
    if *v == 0.0 || (1e-4..1e9).contains(&v.abs()) || !v.is_finite() {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

impl NcError {
    pub(crate) fn line(line: usize, message: impl Into<String>) -> Self {
        NcError::Line { line, message: message.into() }
    }
}

impl From<MachineError> for NcError {
    fn from(e: MachineError) -> Self {
        NcError::Machine(e.to_string())
    }
}

impl From<CostError> for NcError {
    fn from(e: CostError) -> Self {
        NcError::Request(e.to_string())
    }
}

impl From<ModelError> for NcError {
    fn from(e: ModelError) -> Self {
        NcError::Sequencing(e.to_string())
    }
}

impl From<BaselineError> for NcError {
    fn from(e: BaselineError) -> Self {
        match e {
            BaselineError::Solve(e) => NcError::Sequencing(e.to_string()),
            e => NcError::Solver(e.to_string()),
        }
    }
}

impl From<SolveError> for NcError {
    fn from(e: SolveError) -> Self {
        NcError::Sequencing(e.to_string())
    }
}
