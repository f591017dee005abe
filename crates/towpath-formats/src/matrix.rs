//! TSPLIB `EDGE_WEIGHT_SECTION` layouts (`EDGE_WEIGHT_FORMAT`) turned into a full row-major
//! matrix.
//!
//! Every layout is described by the order in which it lists matrix positions
//! ([`WeightFormat::positions`]); triangular layouts are symmetric, so each entry fills both
//! `(i, j)` and `(j, i)`, and the diagonal of the layouts without one is 0.

use std::path::Path;

use crate::error::{ErrorKind, FormatError};
use crate::text::Section;

/// A TSPLIB `EDGE_WEIGHT_FORMAT` for explicit matrices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WeightFormat {
    /// Every entry, row by row.
    FullMatrix,
    /// Upper triangle without diagonal, row by row.
    UpperRow,
    /// Lower triangle without diagonal, row by row.
    LowerRow,
    /// Upper triangle with diagonal, row by row.
    UpperDiagRow,
    /// Lower triangle with diagonal, row by row.
    LowerDiagRow,
    /// Upper triangle without diagonal, column by column.
    UpperCol,
    /// Lower triangle without diagonal, column by column.
    LowerCol,
    /// Upper triangle with diagonal, column by column.
    UpperDiagCol,
    /// Lower triangle with diagonal, column by column.
    LowerDiagCol,
}

impl WeightFormat {
    /// All layouts.
    pub const ALL: [WeightFormat; 9] = [
        WeightFormat::FullMatrix,
        WeightFormat::UpperRow,
        WeightFormat::LowerRow,
        WeightFormat::UpperDiagRow,
        WeightFormat::LowerDiagRow,
        WeightFormat::UpperCol,
        WeightFormat::LowerCol,
        WeightFormat::UpperDiagCol,
        WeightFormat::LowerDiagCol,
    ];

    /// Parses a TSPLIB name such as `LOWER_DIAG_ROW`.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "FULL_MATRIX" => WeightFormat::FullMatrix,
            "UPPER_ROW" => WeightFormat::UpperRow,
            "LOWER_ROW" => WeightFormat::LowerRow,
            "UPPER_DIAG_ROW" => WeightFormat::UpperDiagRow,
            "LOWER_DIAG_ROW" => WeightFormat::LowerDiagRow,
            "UPPER_COL" => WeightFormat::UpperCol,
            "LOWER_COL" => WeightFormat::LowerCol,
            "UPPER_DIAG_COL" => WeightFormat::UpperDiagCol,
            "LOWER_DIAG_COL" => WeightFormat::LowerDiagCol,
            _ => return None,
        })
    }

    /// The TSPLIB name.
    pub fn name(self) -> &'static str {
        match self {
            WeightFormat::FullMatrix => "FULL_MATRIX",
            WeightFormat::UpperRow => "UPPER_ROW",
            WeightFormat::LowerRow => "LOWER_ROW",
            WeightFormat::UpperDiagRow => "UPPER_DIAG_ROW",
            WeightFormat::LowerDiagRow => "LOWER_DIAG_ROW",
            WeightFormat::UpperCol => "UPPER_COL",
            WeightFormat::LowerCol => "LOWER_COL",
            WeightFormat::UpperDiagCol => "UPPER_DIAG_COL",
            WeightFormat::LowerDiagCol => "LOWER_DIAG_COL",
        }
    }

    /// True for the triangular (symmetric) layouts.
    pub fn is_symmetric(self) -> bool {
        self != WeightFormat::FullMatrix
    }

    /// How many numbers the layout holds for `n` nodes (`None` on overflow).
    pub fn count(self, n: usize) -> Option<usize> {
        match self {
            WeightFormat::FullMatrix => n.checked_mul(n),
            WeightFormat::UpperRow | WeightFormat::LowerRow | WeightFormat::UpperCol | WeightFormat::LowerCol => {
                n.checked_mul(n.saturating_sub(1)).map(|x| x / 2)
            }
            _ => n.checked_mul(n.checked_add(1)?).map(|x| x / 2),
        }
    }

    /// The matrix positions `(row, column)` in the order the layout lists them.
    pub fn positions(self, n: usize) -> Box<dyn Iterator<Item = (usize, usize)>> {
        match self {
            WeightFormat::FullMatrix => Box::new((0..n).flat_map(move |i| (0..n).map(move |j| (i, j)))),
            WeightFormat::UpperRow => Box::new((0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)))),
            WeightFormat::LowerRow => Box::new((0..n).flat_map(|i| (0..i).map(move |j| (i, j)))),
            WeightFormat::UpperDiagRow => Box::new((0..n).flat_map(move |i| (i..n).map(move |j| (i, j)))),
            WeightFormat::LowerDiagRow => Box::new((0..n).flat_map(|i| (0..=i).map(move |j| (i, j)))),
            WeightFormat::UpperCol => Box::new((0..n).flat_map(|j| (0..j).map(move |i| (i, j)))),
            WeightFormat::LowerCol => Box::new((0..n).flat_map(move |j| (j + 1..n).map(move |i| (i, j)))),
            WeightFormat::UpperDiagCol => Box::new((0..n).flat_map(|j| (0..=j).map(move |i| (i, j)))),
            WeightFormat::LowerDiagCol => Box::new((0..n).flat_map(move |j| (j..n).map(move |i| (i, j)))),
        }
    }
}

/// A full matrix read from a section, with the line each entry came from.
pub(crate) struct ReadMatrix {
    /// Row-major `n * n` entries.
    pub data: Vec<f64>,
    /// Entries equal to -1, as `(row, column, line)`.
    pub minus_ones: Vec<(usize, usize, usize)>,
    /// The entry of largest magnitude, as `(value, row, column, line)` (the first of equals).
    pub largest: Option<(f64, usize, usize, usize)>,
}

/// Reads an `EDGE_WEIGHT_SECTION` in the given layout.
///
/// A SOP quirk is accepted for every layout: the section may begin with one extra number equal
/// to the dimension (TSPLIB's SOP files and SOPLIB do this); it is detected by the count
/// (`expected + 1`) and the value.
pub(crate) fn read_matrix(
    section: &Section<'_>,
    n: usize,
    format: WeightFormat,
    path: &Path,
) -> Result<ReadMatrix, FormatError> {
    let expected = format.count(n).ok_or_else(|| {
        FormatError::at_line(
            path,
            section.line,
            ErrorKind::Unsupported(format!("DIMENSION {n} is too large for an explicit matrix")),
        )
    })?;
    let mut values: Vec<(f64, usize)> = Vec::new();
    for (line, tok) in section.tokens() {
        values.push((parse_number(tok, line, path)?, line));
    }
    let skip = if values.len() == expected + 1 && values.first().is_some_and(|v| v.0 == n as f64) {
        1
    } else if values.len() == expected {
        0
    } else {
        let detail = format!("{} for DIMENSION {n}", format.name());
        let line = if values.len() > expected {
            values.get(expected).map_or(section.line, |v| v.1)
        } else {
            section.last_line()
        };
        return Err(FormatError::at_line(
            path,
            line,
            ErrorKind::WrongCount { section: section.name.into(), expected, found: values.len(), detail },
        ));
    };
    let mut data = vec![0.0; n * n];
    let mut minus_ones = Vec::new();
    let mut largest: Option<(f64, usize, usize, usize)> = None;
    for ((i, j), &(v, line)) in format.positions(n).zip(values.iter().skip(skip)) {
        if largest.is_none_or(|l| v.abs() > l.0.abs()) {
            largest = Some((v, i, j, line));
        }
        data[i * n + j] = v;
        if format.is_symmetric() {
            data[j * n + i] = v;
        }
        if v == -1.0 {
            minus_ones.push((i, j, line));
        }
    }
    Ok(ReadMatrix { data, minus_ones, largest })
}

/// Parses a finite number.
pub(crate) fn parse_number(tok: &str, line: usize, path: &Path) -> Result<f64, FormatError> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(FormatError::at_line(path, line, ErrorKind::NotFinite(short(tok)))),
        Err(_) => Err(FormatError::at_line(path, line, ErrorKind::NotANumber(short(tok)))),
    }
}

/// Parses an integer (node and set numbers, -1 terminators).
pub(crate) fn parse_integer(tok: &str, line: usize, path: &Path) -> Result<i64, FormatError> {
    tok.parse::<i64>().map_err(|_| FormatError::at_line(path, line, ErrorKind::NotAnInteger(short(tok))))
}

/// A token shortened for an error message.
pub(crate) fn short(tok: &str) -> String {
    let mut s: String = tok.chars().take(40).collect();
    if tok.chars().nth(40).is_some() {
        s.push('…');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_match_positions() {
        for f in WeightFormat::ALL {
            for n in 0..6 {
                assert_eq!(f.count(n), Some(f.positions(n).count()), "{f:?} n={n}");
                assert_eq!(WeightFormat::from_name(f.name()), Some(f));
            }
        }
    }

    #[test]
    fn triangular_layouts_cover_each_pair_once() {
        for f in WeightFormat::ALL.into_iter().filter(|f| f.is_symmetric()) {
            let n = 5;
            let mut seen = vec![0; n * n];
            for (i, j) in f.positions(n) {
                seen[i.min(j) * n + i.max(j)] += 1;
            }
            let diag = f.count(n) == Some(n * (n + 1) / 2);
            for i in 0..n {
                for j in i..n {
                    let want = if i == j && !diag { 0 } else { 1 };
                    assert_eq!(seen[i * n + j], want, "{f:?} ({i},{j})");
                }
            }
        }
    }
}
