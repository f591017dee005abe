//! Machines and dialects: reading and writing their TOML, the built-in ones, and the tool
//! point for given axis values (the machine module's live preview).

use serde::Serialize;
use towpath_machine::Machine;
use towpath_nc::Dialect;

use crate::error::ApiError;

pub use towpath_machine::Machine as MachineModel;
pub use towpath_nc::Dialect as DialectModel;

/// Name of the reference dialect (the one used when none is named).
pub const REFERENCE_DIALECT: &str = "reference";

/// The machines every server has: the demo parts' gantry and mandrel machines.
pub fn builtin_machines() -> Vec<Machine> {
    vec![towpath_nc::demo::gantry(), towpath_nc::demo::mandrel_machine()]
}

/// Reads a machine file; errors name the file and line (or the key).
pub fn parse_machine(file: &str, text: &str) -> Result<Machine, ApiError> {
    Machine::from_toml_str(text).map_err(|e| match e {
        towpath_machine::MachineError::Syntax { line, message } => {
            ApiError::in_file(file, (line > 0).then_some(line), message)
        }
        other => ApiError::in_file(file, None, other.to_string()),
    })
}

/// Checks a machine given as JSON (the machine editor's form) and returns it with its TOML.
pub fn machine_from_json(value: serde_json::Value) -> Result<(Machine, String), ApiError> {
    let m: Machine = serde_json::from_value(value).map_err(|e| ApiError::bad(format!("machine: {e}")))?;
    m.validate().map_err(|e| ApiError::bad(format!("machine: {e}")))?;
    let toml = m.to_toml_string();
    Ok((m, toml))
}

/// A machine's TOML text.
pub fn machine_toml(m: &Machine) -> String {
    m.to_toml_string()
}

/// Reads a dialect file; errors name the file and line.
pub fn parse_dialect(file: &str, text: &str) -> Result<Dialect, ApiError> {
    Dialect::from_toml_str(text).map_err(|e| {
        let msg = e.to_string();
        let msg = msg.strip_prefix("dialect: ").unwrap_or(&msg);
        let (line, rest) = super::split_line(msg);
        ApiError::in_file(file, line, rest)
    })
}

/// The reference dialect's TOML.
pub fn reference_dialect_toml() -> String {
    Dialect::default().to_toml_string()
}

/// Checks that a machine and a dialect fit each other (axis words, clearance axis).
pub fn check_pair(machine: &Machine, dialect: &Dialect, names: &str) -> Result<(), ApiError> {
    towpath_nc::Interp::new(dialect, machine).map(|_| ()).map_err(|e| ApiError::bad(format!("{names}: {e}")))
}

/// The tool point for some axis values.
#[derive(Clone, Debug, Serialize)]
pub struct ToolPoint {
    /// In the machine frame.
    pub machine: [f64; 3],
    /// In the part frame (turned back by the mandrel angle).
    pub part: [f64; 3],
    /// The mandrel's axis (a point and a unit direction), if any.
    pub mandrel_axis: Option<([f64; 3], [f64; 3])>,
}

/// Forward kinematics for the preview; `None` when the machine has no kinematics.
pub fn tool_point(m: &Machine, values: &[f64]) -> Result<Option<ToolPoint>, ApiError> {
    if values.len() != m.axes.len() {
        return Err(ApiError::bad(format!(
            "the machine has {} axes, {} values were given",
            m.axes.len(),
            values.len()
        )));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(ApiError::bad(format!("axis {}: the value is not a number", m.axes[i].label)));
    }
    Ok(m.kinematics().map(|k| ToolPoint {
        machine: k.world_point(values),
        part: k.part_point(values),
        mandrel_axis: k.mandrel_axis(),
    }))
}
