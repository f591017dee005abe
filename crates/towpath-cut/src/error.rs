//! Errors of the cutting and machining crate.

/// Why a drawing or part could not be read, ordered or written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CutError {
    /// The input file is malformed; the message names the element or line.
    #[error("{0}")]
    Input(String),
    /// The hierarchy or precedence cannot be kept.
    #[error("precedence: {0}")]
    Hierarchy(String),
    /// The solver refused the problem.
    #[error("solver: {0}")]
    Solver(String),
    /// A part or tool description is invalid.
    #[error("{0}")]
    Part(String),
}
