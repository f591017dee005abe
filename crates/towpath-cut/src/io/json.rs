//! towpath's cut format, `towpath-cut/1` (JSON; documented in `docs/cut.md`): operations in
//! order and pieces as points with optional bulges (circular arcs, the DXF convention), closed
//! or open, with an optional explicit hierarchy (`after`: the ids of pieces that must be done
//! before this one).

use serde::{Deserialize, Serialize};

use crate::error::CutError;
use crate::geom::{seg_flatten, Path, Seg, P2};
use crate::model::{Drawing, Piece, Placement};

/// The format's name, written in every file.
pub const FORMAT: &str = "towpath-cut/1";

/// A path as points and bulges.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JsonPath {
    /// Points `[x, y]`.
    pub points: Vec<[f64; 2]>,
    /// Bulge of the segment leaving each point (tan(sweep/4), + counter-clockwise); missing or
    /// shorter lists mean straight lines.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bulges: Vec<f64>,
}

/// One piece.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JsonPiece {
    /// Unique name.
    pub id: String,
    /// Operation name (default: the first operation, or "cut").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operation: Option<String>,
    /// Closed contour (the last point joins the first).
    #[serde(default)]
    pub closed: bool,
    /// Points `[x, y]`.
    pub points: Vec<[f64; 2]>,
    /// Bulges, as in [`JsonPath`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bulges: Vec<f64>,
    /// Whether an open stroke may run backwards (default true).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub reversible: bool,
    /// Ids of pieces that must be done before this one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub after: Vec<String>,
    /// Written only: the lead-in before the piece.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead_in: Option<JsonPath>,
    /// Written only: whether the piece runs backwards against its input.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reversed: bool,
}

fn yes() -> bool {
    true
}
fn is_true(b: &bool) -> bool {
    *b
}

/// A whole file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JsonDrawing {
    /// Always [`FORMAT`].
    pub format: String,
    /// Units of the coordinates (informative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<String>,
    /// Operation names in order.
    #[serde(default)]
    pub operations: Vec<String>,
    /// The pieces.
    pub pieces: Vec<JsonPiece>,
}

/// What the JSON writer keeps of the input.
#[derive(Clone, Debug)]
pub struct JsonSource {
    units: Option<String>,
    after: Vec<Vec<String>>,
}

/// Builds a path from points and bulges; `what` names it in messages.
pub fn path_from(points: &[[f64; 2]], bulges: &[f64], closed: bool, what: &str) -> Result<Path, CutError> {
    if points.iter().flatten().any(|v| !v.is_finite()) || bulges.iter().any(|b| !b.is_finite()) {
        return Err(CutError::Input(format!("{what}: coordinates and bulges must be finite numbers")));
    }
    let mut pts: Vec<P2> = points.to_vec();
    let mut bul: Vec<f64> = bulges.to_vec();
    if closed && pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    let distinct = {
        let mut d = pts.clone();
        d.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        d.dedup();
        d.len()
    };
    if closed && distinct < 2 || closed && distinct < 3 && bul.iter().all(|&b| b == 0.0) {
        return Err(CutError::Input(format!(
            "{what}: marked closed but has {distinct} distinct point(s); a closed contour needs at least 3 (or 2 joined by arcs)"
        )));
    }
    if pts.len() < 2 {
        return Err(CutError::Input(format!("{what}: needs at least 2 points, has {}", pts.len())));
    }
    bul.resize(pts.len(), 0.0);
    let mut segs = Vec::with_capacity(pts.len());
    let n = pts.len();
    let last = if closed { n } else { n - 1 };
    for i in 0..last {
        let to = pts[(i + 1) % n];
        segs.push(if bul[i] == 0.0 { Seg::Line(to) } else { Seg::Arc { to, bulge: bul[i] } });
    }
    Ok(Path { start: pts[0], segs, closed })
}

/// A path as points and bulges (cubics flattened within 1e-3).
pub fn path_to(path: &Path) -> JsonPath {
    let mut points = vec![path.start];
    let mut bulges = Vec::new();
    let mut prev = path.start;
    for s in &path.segs {
        match *s {
            Seg::Line(p) => {
                bulges.push(0.0);
                points.push(p);
            }
            Seg::Arc { to, bulge } => {
                bulges.push(bulge);
                points.push(to);
            }
            Seg::Cubic { .. } => {
                let mut f = Vec::new();
                seg_flatten(prev, s, 1e-3, &mut f);
                for p in f {
                    bulges.push(0.0);
                    points.push(p);
                }
            }
        }
        prev = s.end();
    }
    if path.closed {
        points.pop();
    }
    if bulges.iter().all(|&b| b == 0.0) {
        bulges.clear();
    } else {
        bulges.resize(points.len(), 0.0);
    }
    JsonPath { points, bulges }
}

/// Reads a `towpath-cut/1` file.
pub fn read(text: &str, name: &str) -> Result<(Drawing, JsonSource), CutError> {
    let file: JsonDrawing =
        serde_json::from_str(text).map_err(|e| CutError::Input(format!("{name}:{}:{}: {e}", e.line(), e.column())))?;
    if file.format != FORMAT {
        return Err(CutError::Input(format!("{name}: format {:?} is not {FORMAT:?}", file.format)));
    }
    let mut d = Drawing { operations: file.operations.clone(), ..Drawing::default() };
    let mut ids = std::collections::HashMap::new();
    for (i, p) in file.pieces.iter().enumerate() {
        if ids.insert(p.id.clone(), i).is_some() {
            return Err(CutError::Input(format!("{name}: pieces[{i}]: id {:?} is used twice", p.id)));
        }
    }
    let mut after = Vec::new();
    for (i, p) in file.pieces.iter().enumerate() {
        let what = format!("{name}: pieces[{i}] (id {:?})", p.id);
        let op = match &p.operation {
            Some(o) => d.operation_index(o),
            None => {
                if d.operations.is_empty() {
                    d.operations.push("cut".into());
                }
                0
            }
        };
        let path = path_from(&p.points, &p.bulges, p.closed, &what)?;
        d.pieces.push(Piece { id: p.id.clone(), operation: op, path, reversible: p.reversible, fixed: false });
        for a in &p.after {
            let Some(&j) = ids.get(a) else {
                return Err(CutError::Input(format!("{what}: after names {a:?}, which is no piece's id")));
            };
            d.hierarchy.push((j, i));
        }
        after.push(p.after.clone());
    }
    Ok((d, JsonSource { units: file.units, after }))
}

/// Writes an ordering as a `towpath-cut/1` file.
pub fn write(source: &JsonSource, drawing: &Drawing, order: &[Placement]) -> String {
    let pieces = order
        .iter()
        .map(|pl| {
            let piece = &drawing.pieces[pl.piece];
            let jp = path_to(&pl.path);
            JsonPiece {
                id: piece.id.clone(),
                operation: drawing.operations.get(piece.operation).cloned(),
                closed: piece.path.closed,
                points: jp.points,
                bulges: jp.bulges,
                reversible: piece.reversible,
                after: source.after.get(pl.piece).cloned().unwrap_or_default(),
                lead_in: pl.lead_in.as_ref().map(path_to),
                reversed: pl.reversed,
            }
        })
        .collect();
    let out = JsonDrawing {
        format: FORMAT.into(),
        units: source.units.clone(),
        operations: drawing.operations.clone(),
        pieces,
    };
    serde_json::to_string_pretty(&out).unwrap_or_default() + "\n"
}
