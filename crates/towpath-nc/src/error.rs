//! Errors of the AFP program layer.

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
    /// The dialect file or settings are wrong.
    #[error("dialect: {0}")]
    Dialect(String),
    /// The machine does not fit the program or the request.
    #[error("machine: {0}")]
    Machine(String),
    /// The program needs a course width and none was given.
    #[error("{0}")]
    Width(String),
    /// The request cannot be met (for example, a tool cost on a machine without kinematics).
    #[error("{0}")]
    Request(String),
    /// The sequencing engine refused the problem.
    #[error("sequencing: {0}")]
    Sequencing(String),
    /// The optimizer's own output did not verify (a bug: the input is left untouched).
    #[error("the optimized program did not verify: {0}")]
    SelfCheck(String),
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

impl From<SolveError> for NcError {
    fn from(e: SolveError) -> Self {
        NcError::Sequencing(e.to_string())
    }
}
