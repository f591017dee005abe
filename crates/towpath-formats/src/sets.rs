//! GTSP sets (`GTSP_SET_SECTION`), set precedence (`GTSP_SET_ORDERING`) and the start set
//! (`START_GROUP_SECTION`) of GTSP-LIB / GLNS / PCGLNS files.
//!
//! Sets and orderings are lists terminated by -1 and may run over several lines:
//! `set_id node node ... -1` and `a b c ... -1` (set a precedes sets b, c, …).

use std::path::Path;

use crate::error::{ErrorKind, FormatError};
use crate::matrix::parse_integer;
use crate::text::Section;

/// The sets of a GTSP file.
pub(crate) struct Sets {
    /// `members[k]`: the 1-based node numbers of set `k + 1`, in file order.
    pub members: Vec<Vec<u32>>,
}

/// One `-1`-terminated list: its head, its items, and the lines they were on.
struct List {
    head: i64,
    head_line: usize,
    items: Vec<(i64, usize)>,
}

/// Splits a section into `head item ... -1` lists.
fn lists(section: &Section<'_>, what: &str, path: &Path) -> Result<Vec<List>, FormatError> {
    let mut out = Vec::new();
    let mut current: Option<List> = None;
    for (line, tok) in section.tokens() {
        let v = parse_integer(tok, line, path)?;
        match current.as_mut() {
            None => {
                if v == -1 {
                    return Err(FormatError::at_line(
                        path,
                        line,
                        ErrorKind::BadValue {
                            key: section.name.into(),
                            value: tok.into(),
                            expected: format!("a {what} number"),
                        },
                    ));
                }
                current = Some(List { head: v, head_line: line, items: Vec::new() });
            }
            Some(list) => {
                if v == -1 {
                    out.extend(current.take());
                } else {
                    list.items.push((v, line));
                }
            }
        }
    }
    if let Some(list) = current {
        return Err(FormatError::at_line(
            path,
            section.last_line(),
            ErrorKind::Unterminated(format!("the list of {what} {}", list.head)),
        ));
    }
    Ok(out)
}

/// Checks a 1-based set number and returns its index.
fn set_index(set: i64, m: usize, line: usize, path: &Path) -> Result<usize, FormatError> {
    usize::try_from(set)
        .ok()
        .filter(|&s| (1..=m).contains(&s))
        .map(|s| s - 1)
        .ok_or_else(|| FormatError::at_line(path, line, ErrorKind::SetOutOfRange { set, sets: m }))
}

/// Reads the sets over `n` nodes; `declared` is `GTSP_SETS` (with its line) if given. Every
/// node must be in exactly one set.
pub(crate) fn read_sets(
    section: &Section<'_>,
    n: usize,
    declared: Option<(usize, usize)>,
    path: &Path,
) -> Result<Sets, FormatError> {
    let lists = lists(section, "set", path)?;
    let m = declared.map_or(lists.len(), |d| d.0);
    if let Some((d, line)) = declared {
        if d == 0 || d > n {
            return Err(FormatError::at_line(
                path,
                line,
                ErrorKind::BadValue {
                    key: "GTSP_SETS".into(),
                    value: d.to_string(),
                    expected: format!("a set count in 1..={n} (DIMENSION)"),
                },
            ));
        }
    }
    // `m` is at most DIMENSION (checked above) or the number of lists: small either way.
    let mut members: Vec<Option<(Vec<u32>, usize)>> = vec![None; m];
    let mut set_of: Vec<u32> = vec![0; n];
    for list in &lists {
        let k = set_index(list.head, m, list.head_line, path)?;
        let Some(slot) = members.get_mut(k) else { continue };
        if let Some((_, first_line)) = slot {
            return Err(FormatError::at_line(
                path,
                list.head_line,
                ErrorKind::DuplicateSet { set: list.head as u64, first_line: *first_line },
            ));
        }
        if list.items.is_empty() {
            return Err(FormatError::at_line(path, list.head_line, ErrorKind::EmptySet(list.head as u64)));
        }
        let mut nodes = Vec::with_capacity(list.items.len());
        for &(node, line) in &list.items {
            let idx = usize::try_from(node)
                .ok()
                .filter(|&v| (1..=n).contains(&v))
                .ok_or_else(|| FormatError::at_line(path, line, ErrorKind::NodeOutOfRange { node, dimension: n }))?;
            let owner = &mut set_of[idx - 1];
            if *owner != 0 {
                return Err(FormatError::at_line(
                    path,
                    line,
                    ErrorKind::NodeInTwoSets {
                        node: node as u64,
                        first_set: *owner as u64,
                        second_set: list.head as u64,
                    },
                ));
            }
            *owner = (k + 1) as u32;
            nodes.push(node as u32);
        }
        *slot = Some((nodes, list.head_line));
    }
    if lists.len() != m {
        let line = declared.map_or(section.line, |d| d.1);
        return Err(FormatError::at_line(
            path,
            line,
            ErrorKind::WrongCount {
                section: "GTSP_SET_SECTION".into(),
                expected: m,
                found: lists.len(),
                detail: "one list per set as GTSP_SETS says".into(),
            },
        ));
    }
    let unassigned = set_of.iter().filter(|&&s| s == 0).count();
    if let Some(first) = set_of.iter().position(|&s| s == 0) {
        return Err(FormatError::at_line(
            path,
            section.line,
            ErrorKind::NodeInNoSet { node: first as u64 + 1, count: unassigned },
        ));
    }
    Ok(Sets { members: members.into_iter().map(|s| s.map_or_else(Vec::new, |(v, _)| v)).collect() })
}

/// Reads `GTSP_SET_ORDERING` as `(before, after, line)` edges between 0-based set indices.
pub(crate) fn read_ordering(
    section: &Section<'_>,
    m: usize,
    path: &Path,
) -> Result<Vec<(u32, u32, usize)>, FormatError> {
    let mut edges = Vec::new();
    for list in lists(section, "set", path)? {
        let a = set_index(list.head, m, list.head_line, path)?;
        for &(b, line) in &list.items {
            let b = set_index(b, m, line, path)?;
            edges.push((a as u32, b as u32, line));
        }
    }
    Ok(edges)
}

/// Reads `START_GROUP_SECTION`: one set number, optionally followed by -1. Returns the 0-based
/// set index and its line.
pub(crate) fn read_start(section: &Section<'_>, m: usize, path: &Path) -> Result<(u32, usize), FormatError> {
    let mut toks: Vec<(usize, &str)> = section.tokens().collect();
    if toks.len() == 2 && toks.get(1).is_some_and(|t| t.1 == "-1") {
        toks.pop();
    }
    match toks.as_slice() {
        [(line, tok)] => {
            let s = parse_integer(tok, *line, path)?;
            Ok((set_index(s, m, *line, path)? as u32, *line))
        }
        _ => Err(FormatError::at_line(
            path,
            section.line,
            ErrorKind::WrongCount {
                section: section.name.into(),
                expected: 1,
                found: toks.len(),
                detail: "one set number".into(),
            },
        )),
    }
}
