//! The part description (`towpath-part/1`, JSON, documented in `docs/machining.md`): 2.5D
//! pocket features as closed boundaries with islands at a depth, the feature hierarchy (a
//! parent is machined before its children), and the tools with the features each machines.

use serde::{Deserialize, Serialize};

use crate::error::CutError;
use crate::geom::{Path, P2};
use crate::io::json::path_from;

/// The format's name.
pub const FORMAT: &str = "towpath-part/1";

/// A closed loop as points with optional bulges.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum LoopJson {
    /// Just points.
    Points(Vec<[f64; 2]>),
    /// Points and bulges.
    Arcs {
        /// Points.
        points: Vec<[f64; 2]>,
        /// Bulge of the segment leaving each point.
        bulges: Vec<f64>,
    },
}

/// One pocket feature.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FeatureJson {
    /// Unique name.
    pub id: String,
    /// The outer boundary (closed).
    pub boundary: LoopJson,
    /// Islands left standing inside it (closed).
    #[serde(default)]
    pub islands: Vec<LoopJson>,
    /// Floor depth below the top of the stock (positive).
    pub depth: f64,
    /// The feature this one lies in (machined first).
    #[serde(default)]
    pub parent: Option<String>,
}

/// One tool.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ToolJson {
    /// Tool number (the `T` word).
    pub number: u32,
    /// Radius.
    pub radius: f64,
    /// Ids of the features it machines.
    pub features: Vec<String>,
    /// Distance between neighbouring contour-parallel passes (default: the radius).
    #[serde(default)]
    pub step_over: Option<f64>,
    /// Cutting feed (default 1000 units/min).
    #[serde(default)]
    pub feed: Option<f64>,
    /// Plunge feed (default: half the cutting feed).
    #[serde(default)]
    pub plunge_feed: Option<f64>,
    /// Spindle speed (default 10000).
    #[serde(default)]
    pub spindle: Option<f64>,
}

/// A whole part file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PartJson {
    /// Always [`FORMAT`].
    pub format: String,
    /// Name of the part.
    #[serde(default)]
    pub name: Option<String>,
    /// Units (informative; default mm).
    #[serde(default)]
    pub units: Option<String>,
    /// Where each tool starts and ends (default (0, 0)).
    #[serde(default)]
    pub origin: Option<[f64; 2]>,
    /// Clearance height above the stock for rapids between cells (default 5).
    #[serde(default)]
    pub clearance: Option<f64>,
    /// The features.
    pub features: Vec<FeatureJson>,
    /// The tools, in the order they are used.
    pub tools: Vec<ToolJson>,
}

/// A validated feature.
#[derive(Clone, Debug)]
pub struct Feature {
    /// Name.
    pub id: String,
    /// Outer boundary, counter-clockwise.
    pub boundary: Path,
    /// Islands, clockwise.
    pub islands: Vec<Path>,
    /// Floor depth (positive).
    pub depth: f64,
    /// Parent feature index.
    pub parent: Option<usize>,
}

/// A validated tool.
#[derive(Clone, Debug)]
pub struct Tool {
    /// T number.
    pub number: u32,
    /// Radius.
    pub radius: f64,
    /// Step-over.
    pub step_over: f64,
    /// Cutting feed.
    pub feed: f64,
    /// Plunge feed.
    pub plunge_feed: f64,
    /// Spindle speed.
    pub spindle: f64,
    /// Indices of the features it machines.
    pub features: Vec<usize>,
}

/// A validated part.
#[derive(Clone, Debug)]
pub struct Part {
    /// Name.
    pub name: String,
    /// Units.
    pub units: String,
    /// Tool start/end point.
    pub origin: P2,
    /// Clearance height.
    pub clearance: f64,
    /// Features.
    pub features: Vec<Feature>,
    /// Tools in order.
    pub tools: Vec<Tool>,
}

fn segments_cross(a: P2, b: P2, c: P2, d: P2) -> bool {
    let o = |p: P2, q: P2, r: P2| (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
}

/// The first pair of non-adjacent edges of a closed polygon that cross, if any.
pub fn self_crossing(poly: &[P2]) -> Option<(usize, usize)> {
    let n = poly.len();
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            if segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]) {
                return Some((i, j));
            }
        }
    }
    None
}

fn to_loop(l: &LoopJson, what: &str, ccw: bool) -> Result<Path, CutError> {
    let (pts, bul): (&[[f64; 2]], &[f64]) = match l {
        LoopJson::Points(p) => (p, &[]),
        LoopJson::Arcs { points, bulges } => (points, bulges),
    };
    let path = path_from(pts, bul, true, what)?;
    let flat = {
        let mut f = path.flatten(1e-3);
        f.pop();
        f
    };
    if let Some((i, j)) = self_crossing(&flat) {
        return Err(CutError::Part(format!(
            "{what}: the boundary crosses itself (near points {:?} and {:?})",
            flat[i], flat[j]
        )));
    }
    let area = crate::geom::signed_area(&flat);
    if area == 0.0 {
        return Err(CutError::Part(format!("{what}: the boundary encloses no area")));
    }
    Ok(if (area > 0.0) == ccw { path } else { path.reversed() })
}

/// Reads and validates a part file; `name` is used in messages.
pub fn read_part(text: &str, name: &str) -> Result<Part, CutError> {
    let p: PartJson =
        serde_json::from_str(text).map_err(|e| CutError::Input(format!("{name}:{}:{}: {e}", e.line(), e.column())))?;
    if p.format != FORMAT {
        return Err(CutError::Input(format!("{name}: format {:?} is not {FORMAT:?}", p.format)));
    }
    let mut ids = std::collections::HashMap::new();
    for (i, f) in p.features.iter().enumerate() {
        if ids.insert(f.id.clone(), i).is_some() {
            return Err(CutError::Part(format!("{name}: features[{i}]: id {:?} is used twice", f.id)));
        }
    }
    let mut features = Vec::new();
    for (i, f) in p.features.iter().enumerate() {
        let what = format!("{name}: features[{i}] (id {:?})", f.id);
        if !(f.depth > 0.0 && f.depth.is_finite()) {
            return Err(CutError::Part(format!("{what}: depth {} must be a positive number", f.depth)));
        }
        let boundary = to_loop(&f.boundary, &format!("{what} boundary"), true)?;
        let islands = f
            .islands
            .iter()
            .enumerate()
            .map(|(k, l)| to_loop(l, &format!("{what} islands[{k}]"), false))
            .collect::<Result<Vec<_>, _>>()?;
        let parent = match &f.parent {
            None => None,
            Some(pid) => Some(
                *ids.get(pid).ok_or_else(|| CutError::Part(format!("{what}: parent {pid:?} is no feature's id")))?,
            ),
        };
        features.push(Feature { id: f.id.clone(), boundary, islands, depth: f.depth, parent });
    }
    // The hierarchy must be a forest.
    for i in 0..features.len() {
        let mut at = features[i].parent;
        let mut steps = 0;
        while let Some(k) = at {
            steps += 1;
            if k == i || steps > features.len() {
                return Err(CutError::Part(format!(
                    "{name}: features[{i}] (id {:?}) is its own ancestor",
                    features[i].id
                )));
            }
            at = features[k].parent;
        }
    }
    if p.tools.is_empty() {
        return Err(CutError::Part(format!("{name}: no tools")));
    }
    let mut tools = Vec::new();
    for (i, t) in p.tools.iter().enumerate() {
        let what = format!("{name}: tools[{i}] (T{})", t.number);
        if !(t.radius > 0.0 && t.radius.is_finite()) {
            return Err(CutError::Part(format!("{what}: radius {} must be a positive number", t.radius)));
        }
        let step_over = t.step_over.unwrap_or(t.radius);
        if !(step_over > 0.0 && step_over <= 2.0 * t.radius) {
            return Err(CutError::Part(format!(
                "{what}: step-over {step_over} must be positive and at most the tool diameter {}",
                2.0 * t.radius
            )));
        }
        let feed = t.feed.unwrap_or(1000.0);
        let plunge_feed = t.plunge_feed.unwrap_or(feed / 2.0);
        let spindle = t.spindle.unwrap_or(10000.0);
        for (v, w) in [(feed, "feed"), (plunge_feed, "plunge_feed"), (spindle, "spindle")] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(CutError::Part(format!("{what}: {w} {v} must be a positive number")));
            }
        }
        let mut fs = Vec::new();
        for fid in &t.features {
            fs.push(
                *ids.get(fid).ok_or_else(|| CutError::Part(format!("{what}: feature {fid:?} is no feature's id")))?,
            );
        }
        tools.push(Tool { number: t.number, radius: t.radius, step_over, feed, plunge_feed, spindle, features: fs });
    }
    // A child may not be finished by a tool that runs before every tool of its parent.
    for (ti, t) in tools.iter().enumerate() {
        for &f in &t.features {
            if let Some(par) = features[f].parent {
                let parent_first = tools.iter().position(|u| u.features.contains(&par));
                if parent_first.is_some_and(|pf| pf > ti) {
                    return Err(CutError::Part(format!(
                        "{name}: feature {:?} is machined by T{} before its parent {:?} is started",
                        features[f].id, t.number, features[par].id
                    )));
                }
            }
        }
    }
    let origin = p.origin.unwrap_or([0.0, 0.0]);
    let clearance = p.clearance.unwrap_or(5.0);
    if !(clearance > 0.0 && clearance.is_finite()) || origin.iter().any(|v| !v.is_finite()) {
        return Err(CutError::Part(format!("{name}: clearance must be positive and the origin finite")));
    }
    Ok(Part {
        name: p.name.unwrap_or_else(|| "part".into()),
        units: p.units.unwrap_or_else(|| "mm".into()),
        origin,
        clearance,
        features,
        tools,
    })
}
