//! Splits a TSPLIB-style text into keyword lines (`KEY : value`) and data sections.
//!
//! A *keyword line* starts with an upper-case name (`[A-Z][A-Z0-9_]*`), optionally followed by
//! `:` and a value; spacing around the colon is free. A section keyword (`..._SECTION`,
//! `GTSP_SET_ORDERING`) is followed by data lines up to the next keyword line; anything after
//! the section keyword on its own line counts as data too. `EOF` ends the file: what follows is
//! ignored (some GTSP-LIB files list city names there). This module knows the names of keywords
//! but not what they mean.

use std::path::Path;

use crate::error::{ErrorKind, FormatError};

/// Keywords with a value.
const KEYS: &[&str] = &[
    "NAME",
    "TYPE",
    "COMMENT",
    "DIMENSION",
    "CAPACITY",
    "EDGE_WEIGHT_TYPE",
    "EDGE_WEIGHT_FORMAT",
    "EDGE_DATA_FORMAT",
    "NODE_COORD_TYPE",
    "DISPLAY_DATA_TYPE",
    "GTSP_SETS",
];

/// Keywords followed by data lines.
const SECTIONS: &[&str] = &[
    "NODE_COORD_SECTION",
    "EDGE_WEIGHT_SECTION",
    "DISPLAY_DATA_SECTION",
    "TOUR_SECTION",
    "GTSP_SET_SECTION",
    "GTSP_SET_ORDERING",
    "START_GROUP_SECTION",
    "FIXED_EDGES_SECTION",
    "DEPOT_SECTION",
    "DEMAND_SECTION",
    "EDGE_DATA_SECTION",
];

/// One `KEY : value` line.
#[derive(Clone, Debug)]
pub(crate) struct Entry<'a> {
    /// The keyword.
    pub name: &'a str,
    /// The value, trimmed.
    pub value: &'a str,
    /// 1-based line number.
    pub line: usize,
}

/// A section keyword and its data lines.
#[derive(Clone, Debug)]
pub(crate) struct Section<'a> {
    /// The section keyword.
    pub name: &'a str,
    /// 1-based line number of the keyword.
    pub line: usize,
    /// Non-blank data lines with their line numbers, trimmed.
    pub lines: Vec<(usize, &'a str)>,
}

impl<'a> Section<'a> {
    /// Every whitespace-separated token with its line number.
    pub fn tokens(&self) -> impl Iterator<Item = (usize, &'a str)> + '_ {
        self.lines.iter().flat_map(|&(no, text)| text.split_whitespace().map(move |t| (no, t)))
    }

    /// The line where the section ends (its last data line, or its keyword line).
    pub fn last_line(&self) -> usize {
        self.lines.last().map_or(self.line, |l| l.0)
    }
}

/// A lexed file: keyword entries and sections in file order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Document<'a> {
    pub entries: Vec<Entry<'a>>,
    pub sections: Vec<Section<'a>>,
}

impl<'a> Document<'a> {
    /// The entry for a keyword, if given.
    pub fn entry(&self, name: &str) -> Option<&Entry<'a>> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// The section of that name, if given.
    pub fn section(&self, name: &str) -> Option<&Section<'a>> {
        self.sections.iter().find(|s| s.name == name)
    }
}

/// Splits a line into its leading keyword and the rest (after an optional `:`), if it starts
/// with one.
fn keyword(line: &str) -> Option<(&str, &str)> {
    let bytes = line.as_bytes();
    if !bytes.first().is_some_and(|b| b.is_ascii_uppercase()) {
        return None;
    }
    let end =
        bytes.iter().position(|b| !(b.is_ascii_uppercase() || b.is_ascii_digit() || *b == b'_')).unwrap_or(bytes.len());
    let (name, rest) = line.split_at(end);
    // The keyword must end at a space, a colon or the end of the line ("Infinity" is data).
    match rest.chars().next() {
        None => Some((name, "")),
        Some(c) if c == ':' || c.is_whitespace() => {
            let rest = rest.trim_start();
            let rest = rest.strip_prefix(':').unwrap_or(rest);
            Some((name, rest.trim()))
        }
        Some(_) => None,
    }
}

/// Lexes a TSPLIB-style text.
pub(crate) fn lex<'a>(text: &'a str, path: &Path) -> Result<Document<'a>, FormatError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut doc = Document::default();
    let mut in_section = false;
    for (i, raw) in text.lines().enumerate() {
        let no = i + 1;
        let line = raw.trim();
        if line.is_empty() {
            continue;
        }
        let Some((name, rest)) = keyword(line) else {
            if in_section {
                if let Some(s) = doc.sections.last_mut() {
                    s.lines.push((no, line));
                }
                continue;
            }
            return Err(FormatError::at_line(path, no, ErrorKind::ExpectedKeyword(first_word(line))));
        };
        in_section = false;
        if name == "EOF" {
            break;
        }
        if SECTIONS.contains(&name) {
            if let Some(prev) = doc.section(name) {
                let first_line = prev.line;
                return Err(FormatError::at_line(path, no, ErrorKind::DuplicateKey { key: name.into(), first_line }));
            }
            let mut s = Section { name, line: no, lines: Vec::new() };
            if !rest.is_empty() {
                s.lines.push((no, rest));
            }
            doc.sections.push(s);
            in_section = true;
        } else if KEYS.contains(&name) {
            if name != "COMMENT" {
                if let Some(prev) = doc.entry(name) {
                    let first_line = prev.line;
                    return Err(FormatError::at_line(
                        path,
                        no,
                        ErrorKind::DuplicateKey { key: name.into(), first_line },
                    ));
                }
            }
            doc.entries.push(Entry { name, value: rest, line: no });
        } else {
            return Err(FormatError::at_line(path, no, ErrorKind::UnknownKeyword(name.into())));
        }
    }
    Ok(doc)
}

/// The first word of a line, shortened for an error message.
fn first_word(line: &str) -> String {
    let w = line.split_whitespace().next().unwrap_or("");
    w.chars().take(40).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_with_any_spacing() {
        assert_eq!(keyword("DIMENSION : 14"), Some(("DIMENSION", "14")));
        assert_eq!(keyword("DIMENSION: 14"), Some(("DIMENSION", "14")));
        assert_eq!(keyword("DIMENSION :14 "), Some(("DIMENSION", "14")));
        assert_eq!(keyword("EDGE_WEIGHT_SECTION"), Some(("EDGE_WEIGHT_SECTION", "")));
        assert_eq!(keyword("Infinity"), None);
        assert_eq!(keyword("1 2 3"), None);
        assert_eq!(keyword("inf"), None);
    }

    #[test]
    fn sections_end_at_keywords_and_eof() {
        let t = "NAME: x\nNODE_COORD_SECTION\n1 0 0\n\n2 1 1\nEOF\ngarbage here\n";
        let d = lex(t, Path::new("t")).unwrap();
        assert_eq!(d.entry("NAME").unwrap().value, "x");
        let s = d.section("NODE_COORD_SECTION").unwrap();
        assert_eq!(s.lines, vec![(3, "1 0 0"), (5, "2 1 1")]);
    }
}
