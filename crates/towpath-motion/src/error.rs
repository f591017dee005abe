//! Typed errors of the motion crate. Messages say what is wrong in the model's own terms (axes,
//! meshes, laid points), never in terms of a command line.

use towpath_geom::MeshError;

/// A mesh that cannot become part of a cell.
#[derive(Debug, thiserror::Error)]
pub enum CellError {
    /// Mesh `mesh` (0-based, in the order given) has bad indices or coordinates.
    #[error("obstacle mesh {}: {source}", mesh + 1)]
    Mesh {
        /// The mesh's position in the list, from 0.
        mesh: usize,
        /// What is wrong with it.
        source: MeshError,
    },
}

/// A set-up that would make the checks meaningless, refused before any move is checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetupError {
    /// A laid point is farther from every obstacle triangle than the allowed gap: the mold
    /// does not lie under (or around) the laid path, so it is the wrong mesh or in the wrong
    /// frame.
    #[error(
        "laid point {index} at ({:.3}, {:.3}, {:.3}) is {distance:.3} mm from the nearest mold triangle \
         (at most {max_gap} mm allowed): the mold does not lie under the laid path (wrong mesh, units or frame?)",
        point[0], point[1], point[2]
    )]
    OffMold {
        /// Index of the point in the list given.
        index: usize,
        /// The point, in the part frame.
        point: [f64; 3],
        /// Its distance to the nearest triangle (at least `max_gap`).
        distance: f64,
        /// The largest distance allowed.
        max_gap: f64,
    },
    /// The cell has no triangles, so the laid path cannot lie on it.
    #[error("the mold has no triangles")]
    EmptyMold,
    /// A laid point lies on (or within `min_radius` of) the mandrel's axis, where a course
    /// cannot be laid and where angles around the mandrel mean nothing.
    #[error(
        "laid point {index} is {radius:.4} mm from the mandrel axis (at least {min_radius} mm needed): \
         a course cannot be laid on the mandrel's axis (is the mandrel origin or direction wrong?)"
    )]
    OnMandrelAxis {
        /// Index of the point in the list given.
        index: usize,
        /// Its distance from the mandrel axis.
        radius: f64,
        /// The least distance accepted.
        min_radius: f64,
    },
    /// An axis value lies outside the axis's travel limits.
    #[error("axis {axis} at {value} is outside its travel limits [{}, {}]", fmt_limit(*min), fmt_limit(*max))]
    OutsideLimits {
        /// The axis label.
        axis: String,
        /// The value.
        value: f64,
        /// The lower limit, if any.
        min: Option<f64>,
        /// The upper limit, if any.
        max: Option<f64>,
    },
    /// A state does not have one finite value per axis.
    #[error("a state has {got} values but the machine has {expected} axes")]
    WrongDimension {
        /// Values given.
        got: usize,
        /// Axes of the machine.
        expected: usize,
    },
    /// A state value is not finite.
    #[error("a value of axis {axis} is not finite")]
    NotFinite {
        /// The axis label.
        axis: String,
    },
    /// The machine has no tool point (no DH chain and no X/Y/Z axes), so moves cannot be placed
    /// in the part frame.
    #[error("the machine has no kinematics (no DH chain and no X, Y or Z linear axis): moves cannot be checked")]
    NoKinematics,
    /// The head model is invalid.
    #[error(transparent)]
    Head(#[from] towpath_machine::MachineError),
}

fn fmt_limit(v: Option<f64>) -> String {
    v.map_or_else(|| "none".to_string(), |v| v.to_string())
}

/// Why no transit could be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The start or end state is unusable.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The machine cannot lift the tool the way asked (no such axis, or an axis that does not
    /// move the tool away from the part).
    #[error("cannot lift the tool: {0}")]
    NoLift(String),
    /// Neither a straight move nor any lift within the travel limits keeps the clearance.
    #[error("no safe transit: {0}")]
    NoSafeTransit(String),
}
