//! TSPLIB tour files (`.tour`, `.opt.tour`): `TOUR_SECTION` lists node numbers, ended by -1.

use std::path::Path;

use crate::error::{ErrorKind, FormatError};
use crate::matrix::parse_integer;
use crate::text::lex;

/// A tour read from a file: 1-based node numbers in visiting order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tour {
    /// The `NAME` of the file, if given.
    pub name: Option<String>,
    /// The node numbers, in order.
    pub nodes: Vec<u32>,
}

/// Parses a TSPLIB tour. The first tour of `TOUR_SECTION` is read (up to its -1, or to the end
/// of the section). Node numbers must be positive and distinct; if `DIMENSION` is given the
/// tour must have that many entries (for a GTSP tour, one per set, so node numbers may exceed
/// it). Whether the nodes belong to a problem is checked by [`crate::Instance::steps_from_nodes`].
pub fn parse_tour(text: &str, path: &Path) -> Result<Tour, FormatError> {
    let doc = lex(text, path)?;
    if let Some(s) = doc.sections.iter().find(|s| s.name != "TOUR_SECTION") {
        return Err(FormatError::at_line(
            path,
            s.line,
            ErrorKind::Unsupported(format!("{} is not expected in a tour file", s.name)),
        ));
    }
    let dimension = match doc.entry("DIMENSION") {
        Some(e) => Some(e.value.parse::<usize>().map_err(|_| {
            FormatError::at_line(
                path,
                e.line,
                ErrorKind::BadValue { key: "DIMENSION".into(), value: e.value.into(), expected: "an integer".into() },
            )
        })?),
        None => None,
    };
    let section = doc
        .section("TOUR_SECTION")
        .ok_or_else(|| FormatError::in_file(path, ErrorKind::Missing("TOUR_SECTION".into())))?;
    let mut nodes = Vec::new();
    let mut first_line: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for (line, tok) in section.tokens() {
        let v = parse_integer(tok, line, path)?;
        if v == -1 {
            break;
        }
        let node = u32::try_from(v).ok().filter(|&x| x >= 1).ok_or_else(|| {
            FormatError::at_line(
                path,
                line,
                ErrorKind::BadValue {
                    key: "TOUR_SECTION".into(),
                    value: tok.into(),
                    expected: "a node number (1 or more) or -1".into(),
                },
            )
        })?;
        if let Some(&first) = first_line.get(&node) {
            return Err(FormatError::at_line(
                path,
                line,
                ErrorKind::DuplicateNode { node: node as u64, first_line: first },
            ));
        }
        first_line.insert(node, line);
        nodes.push(node);
    }
    if let Some(d) = dimension {
        if nodes.len() != d {
            return Err(FormatError::at_line(
                path,
                section.last_line(),
                ErrorKind::WrongCount {
                    section: "TOUR_SECTION".into(),
                    expected: d,
                    found: nodes.len(),
                    detail: "one entry per node as DIMENSION says".into(),
                },
            ));
        }
    }
    let name = doc.entry("NAME").map(|e| e.value.to_string());
    Ok(Tour { name, nodes })
}
