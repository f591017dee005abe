//! `NODE_COORD_SECTION`: one line per node, `node x y` (or `node x y z` for 3D types).
//!
//! Unlike matrix entries, coordinates are read line by line, so a short line is reported as
//! such (`expected 2 coordinates for node 55, found 1`).

use std::path::Path;

use crate::error::{ErrorKind, FormatError};
use crate::matrix::{parse_integer, parse_number};
use crate::text::Section;

/// Reads `n` nodes with `dims` coordinates each (the third coordinate is 0 for 2D data).
pub(crate) fn read_coords(
    section: &Section<'_>,
    n: usize,
    dims: usize,
    path: &Path,
) -> Result<Vec<[f64; 3]>, FormatError> {
    // One line per node: fewer lines than nodes can only be an error, and checking first keeps
    // a huge DIMENSION from allocating anything.
    if section.lines.len() < n {
        let missing = n - section.lines.len();
        return Err(FormatError::at_line(
            path,
            section.last_line(),
            ErrorKind::WrongCount {
                section: section.name.into(),
                expected: n,
                found: section.lines.len(),
                detail: format!("one line per node for DIMENSION {n}, {missing} missing"),
            },
        ));
    }
    let mut points: Vec<Option<([f64; 3], usize)>> = vec![None; n];
    for &(line, text) in &section.lines {
        let mut toks = text.split_whitespace();
        let Some(id_tok) = toks.next() else { continue };
        let id = parse_integer(id_tok, line, path)?;
        let slot =
            usize::try_from(id).ok().filter(|&i| i >= 1).and_then(|i| points.get_mut(i - 1)).ok_or_else(|| {
                FormatError::at_line(path, line, ErrorKind::NodeOutOfRange { node: id, dimension: n })
            })?;
        if let Some((_, first_line)) = slot {
            return Err(FormatError::at_line(
                path,
                line,
                ErrorKind::DuplicateNode { node: id as u64, first_line: *first_line },
            ));
        }
        let rest: Vec<&str> = toks.collect();
        if rest.len() != dims {
            return Err(FormatError::at_line(
                path,
                line,
                ErrorKind::CoordinateCount { node: id as u64, expected: dims, found: rest.len() },
            ));
        }
        let mut p = [0.0; 3];
        for (k, tok) in rest.iter().enumerate() {
            p[k] = parse_number(tok, line, path)?;
        }
        *slot = Some((p, line));
    }
    let missing = points.iter().filter(|p| p.is_none()).count();
    if let Some(first) = points.iter().position(|p| p.is_none()) {
        return Err(FormatError::at_line(
            path,
            section.line,
            ErrorKind::MissingNode { section: section.name.into(), node: first as u64 + 1, missing, dimension: n },
        ));
    }
    Ok(points.into_iter().map(|p| p.map_or([0.0; 3], |(x, _)| x)).collect())
}
