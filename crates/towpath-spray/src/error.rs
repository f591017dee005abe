//! What the spray planner refuses, in its own terms.

/// Why a spray plan cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SprayError {
    /// A parameter of the gun, the material or the plan is out of range.
    #[error("{what} must be {must}, got {got}")]
    BadParameter {
        /// The parameter, in words ("the standoff").
        what: &'static str,
        /// What it must be ("a positive length in mm").
        must: &'static str,
        /// The value given.
        got: f64,
    },
    /// A spray profile description could not be read.
    #[error("spray profile '{text}': {message}")]
    BadProfile {
        /// The description as given.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// The surface has nothing to spray.
    #[error("the surface has no area to spray")]
    NoArea,
    /// The plan would be unreasonably large.
    #[error("the plan would need {what}; use a larger spacing or spray radius")]
    TooLarge {
        /// What would be too large.
        what: String,
    },
    /// The sequencer could not order the passes.
    #[error("sequencing the passes failed: {0}")]
    Sequencing(String),
    /// A path given for simulation is not a valid path.
    #[error("pose {index}: {message}")]
    BadPath {
        /// Index of the offending pose.
        index: usize,
        /// What is wrong with it.
        message: String,
    },
}

/// Checks that `value` is finite and positive.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64, SprayError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(SprayError::BadParameter { what, must: "a positive finite number", got: value })
    }
}
