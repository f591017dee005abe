//! The drawing model: pieces (closed contours and open strokes) grouped into operations, with
//! an optional explicit hierarchy. Readers build a [`Drawing`]; writers take one back.

use crate::geom::{Path, P2};

/// One piece of productive motion: a closed contour or an open stroke.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The piece's name in its file (an SVG id, a DXF handle, a JSON id, "line 12" in G-code).
    pub id: String,
    /// Index into [`Drawing::operations`].
    pub operation: usize,
    /// The geometry.
    pub path: Path,
    /// Whether an open stroke may be drawn backwards (ignored for closed contours).
    pub reversible: bool,
    /// Done exactly as drawn: not reversed, a closed contour not started elsewhere (G-code
    /// pieces whose moves carry other axes, say).
    pub fixed: bool,
}

/// What the ordering and the writers work on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawing {
    /// Operation names in their listed order (SVG layers, DXF layers, JSON operations).
    pub operations: Vec<String>,
    /// The pieces in input order.
    pub pieces: Vec<Piece>,
    /// Explicit precedence: `(before, after)` piece indices (JSON `after` lists).
    pub hierarchy: Vec<(usize, usize)>,
}

impl Drawing {
    /// The index of the operation named `name`, added at the end if new.
    pub fn operation_index(&mut self, name: &str) -> usize {
        if let Some(i) = self.operations.iter().position(|o| o == name) {
            return i;
        }
        self.operations.push(name.to_string());
        self.operations.len() - 1
    }
}

/// How a piece is done in an ordering.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// Index into [`Drawing::pieces`].
    pub piece: usize,
    /// The piece's geometry as it is done: started at the entry, reversed if so.
    pub path: Path,
    /// Whether an open stroke runs backwards.
    pub reversed: bool,
    /// A lead-in ending where `path` starts (closed contours with a lead-in length).
    pub lead_in: Option<Path>,
}

impl Placement {
    /// Where the tool goes down: the lead-in's start, else the path's.
    pub fn entry(&self) -> P2 {
        self.lead_in.as_ref().map_or(self.path.start, |l| l.start)
    }

    /// Where the tool comes up.
    pub fn exit(&self) -> P2 {
        self.path.end()
    }
}

/// Rapid (pen-up) length of doing placements in order from `start` (if any).
pub fn travel(start: Option<P2>, order: &[Placement]) -> f64 {
    let mut at = start;
    let mut total = 0.0;
    for p in order {
        if let Some(a) = at {
            total += crate::geom::dist(a, p.entry());
        }
        at = Some(p.exit());
    }
    total
}

/// The pieces in input order, as drawn: the "before" of every report.
pub fn as_drawn(drawing: &Drawing) -> Vec<Placement> {
    drawing
        .pieces
        .iter()
        .enumerate()
        .map(|(i, p)| Placement { piece: i, path: p.path.clone(), reversed: false, lead_in: None })
        .collect()
}
