//! # towpath-formats: instance readers
//!
//! Turns files into [`towpath_seq::Problem`]s and answers back into the files' own numbering.
//! It reads, and never solves.
//!
//! - [`read_instance`] / [`parse_instance`]: any supported problem file, recognised by content
//!   (a JSON object, or TSPLIB keywords and `TYPE`), giving an [`Instance`]: name, [`Kind`],
//!   dimension, the problem as a [`LoadedProblem`] (matrix or point costs; run generic code on
//!   it with [`with_problem!`]) and the mapping back to the file's numbering
//!   ([`Instance::answer`], [`Instance::steps_from_nodes`]).
//! - [`parse_tsplib`]: TSPLIB TSP and ATSP (every coordinate type towpath's cost models know,
//!   and EXPLICIT matrices in all nine layouts), SOP, GTSP/AGTSP (GLNS format) and PCGLNS.
//! - [`parse_json`] / [`JsonProblem`]: towpath's own JSON format (tasks with modes, precedence,
//!   consecutive groups, route ends; states as points with a metric or as a matrix), described
//!   in `docs/json-format.md`; [`write_json`] writes it, and [`Instance::to_json`] turns any
//!   loaded instance into it (points or an explicit matrix, see [`CostsAs`]).
//! - [`read_tour`] / [`parse_tour`]: TSPLIB tours, to price known optimal tours.
//! - Every refusal is a [`FormatError`]: file, line (and column for JSON) and an [`ErrorKind`].
//!   No input makes a reader panic.

#![warn(missing_docs)]

mod coords;
mod error;
mod export;
mod instance;
mod json;
pub mod json_locate;
mod json_shape;
mod matrix;
mod metric;
mod sets;
mod text;
mod tour;
mod tsplib;

use std::path::Path;

pub use error::{ErrorKind, FormatError};
pub use export::{CostsAs, ExportError, MAX_MATRIX_ENTRIES};
pub use instance::{Answer, FixedEdge, Instance, Kind, LoadedProblem, TaskStep, UnknownNode};
pub use json::{
    parse_json, parse_json_problem, write_json, JsonEnd, JsonMetric, JsonMode, JsonProblem, JsonStates, JsonTask,
};
pub use matrix::WeightFormat;
pub use metric::FileMetric;
pub use tour::{parse_tour, Tour};
pub use tsplib::parse_tsplib;

/// Reads a file as text (invalid UTF-8 is replaced, not refused: TSPLIB comments are often
/// Latin-1).
fn read_text(path: &Path) -> Result<String, FormatError> {
    let bytes = std::fs::read(path).map_err(|e| FormatError::in_file(path, ErrorKind::Io(e)))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Reads a problem file of any supported format; see [`parse_instance`].
pub fn read_instance(path: &Path) -> Result<Instance, FormatError> {
    parse_instance(&read_text(path)?, path)
}

/// Parses a problem of any supported format: text whose first non-blank character is `{` (or a
/// `.json` file) is towpath's JSON format; anything else is read as TSPLIB-style keywords, its
/// kind given by `TYPE` and the sections present (a `GTSP_SET_SECTION` makes it a GTSP whatever
/// `TYPE` says). `path` names the input in error messages and gives the default name.
pub fn parse_instance(text: &str, path: &Path) -> Result<Instance, FormatError> {
    let is_json = text.trim_start_matches('\u{feff}').trim_start().starts_with('{')
        || path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        parse_json(text.trim_start_matches('\u{feff}'), path)
    } else {
        parse_tsplib(text, path)
    }
}

/// Reads a TSPLIB tour file; see [`parse_tour`].
pub fn read_tour(path: &Path) -> Result<Tour, FormatError> {
    parse_tour(&read_text(path)?, path)
}
