//! The JSON format of open rural postman instances and routes.
//!
//! An instance:
//!
//! ```json
//! {
//!   "format": "towpath-rpp/1",
//!   "name": "door panel",
//!   "vertices": [[0.0, 0.0], [1.0, 0.0], [1.0, 2.0, 0.5]],
//!   "edges": [
//!     {"a": 0, "b": 1, "required": true},
//!     {"a": 1, "b": 2, "length": 2.5}
//!   ],
//!   "start": 0
//! }
//! ```
//!
//! - `vertices`: coordinates `[x, y]` or `[x, y, z]`, numbered from 0 in order.
//! - `edges`: undirected; `length` defaults to the straight-line distance between the ends;
//!   `required` (default `false`) marks the edges the tool must traverse (a patch path of seed
//!   004, with its end points as the edge's ends).
//! - `format`, `name` and `start` (the vertex the tool starts from) are optional. Unknown
//!   fields are refused, so a misspelt key is not silently ignored.
//!
//! Every error names the line and column of the offending value.

use serde::{Deserialize, Serialize};

use crate::instance::{Edge, Instance, InstanceErrorKind, Item};
use crate::model::Route;
use towpath_formats::json_locate::{locate, Seg};

/// The value of the optional `format` field.
pub const FORMAT: &str = "towpath-rpp/1";
/// The value of the `format` field of a route.
pub const ROUTE_FORMAT: &str = "towpath-rpp-route/1";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstance {
    #[serde(default)]
    format: Option<String>,
    #[serde(default)]
    name: Option<String>,
    vertices: Vec<Vec<f64>>,
    edges: Vec<RawEdge>,
    #[serde(default)]
    start: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEdge {
    a: u64,
    b: u64,
    #[serde(default)]
    length: Option<f64>,
    #[serde(default)]
    required: bool,
}

/// What is wrong with a JSON input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReadErrorKind {
    /// Not valid JSON, or not the expected shape.
    #[error("{0}")]
    Syntax(String),
    /// The `format` field names another format.
    #[error("unknown format {0:?} (expected {FORMAT:?})")]
    Format(String),
    /// The instance is not valid.
    #[error("{0}")]
    Invalid(#[from] InstanceErrorKind),
}

/// A JSON input was refused: where and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("line {line}, column {column}{}: {kind}", if what.is_empty() { String::new() } else { format!(" ({what})") })]
pub struct ReadError {
    /// 1-based line of the offending value.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// Which value, as a path such as `edges[3].b` (empty if unknown).
    pub what: String,
    /// What is wrong.
    pub kind: ReadErrorKind,
}

/// Reads an instance from JSON text.
pub fn read_instance(text: &str) -> Result<Instance, ReadError> {
    let raw: RawInstance = serde_json::from_str(text).map_err(|e| {
        let msg = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        let msg = msg.strip_suffix(&suffix).unwrap_or(&msg).to_string();
        ReadError {
            line: e.line().max(1),
            column: e.column().max(1),
            what: String::new(),
            kind: ReadErrorKind::Syntax(msg),
        }
    })?;
    let at = |path: &[Seg<'_>], what: String, kind: ReadErrorKind| {
        let (line, column) = locate(text, path).unwrap_or((1, 1));
        ReadError { line, column, what, kind }
    };
    if let Some(f) = &raw.format {
        if f != FORMAT {
            return Err(at(&[Seg::Key("format")], "format".into(), ReadErrorKind::Format(f.clone())));
        }
    }
    let mut vertices = Vec::with_capacity(raw.vertices.len());
    for (i, v) in raw.vertices.iter().enumerate() {
        let p = match v.as_slice() {
            [x, y] => [*x, *y, 0.0],
            [x, y, z] => [*x, *y, *z],
            _ => {
                return Err(at(
                    &[Seg::Key("vertices"), Seg::Index(i)],
                    format!("vertices[{i}]"),
                    InstanceErrorKind::BadDimension(v.len()).into(),
                ))
            }
        };
        vertices.push(p);
    }
    let nv = vertices.len();
    let mut edges = Vec::with_capacity(raw.edges.len());
    let mut required = Vec::with_capacity(raw.edges.len());
    for (i, e) in raw.edges.iter().enumerate() {
        for (key, v) in [("a", e.a), ("b", e.b)] {
            if v >= nv as u64 {
                return Err(at(
                    &[Seg::Key("edges"), Seg::Index(i), Seg::Key(key)],
                    format!("edges[{i}].{key}"),
                    InstanceErrorKind::NoSuchVertex { vertex: v, num_vertices: nv }.into(),
                ));
            }
        }
        let (a, b) = (e.a as u32, e.b as u32);
        let length = match e.length {
            Some(l) => l,
            None => {
                let (p, q) = (vertices[a as usize], vertices[b as usize]);
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            }
        };
        edges.push(Edge { a, b, length });
        required.push(e.required);
    }
    if let Some(s) = raw.start {
        if s >= nv as u64 {
            return Err(at(
                &[Seg::Key("start")],
                "start".into(),
                InstanceErrorKind::NoSuchVertex { vertex: s, num_vertices: nv }.into(),
            ));
        }
    }
    Instance::new(raw.name, vertices, edges, &required, raw.start.map(|s| s as u32)).map_err(|err| {
        let (path, what): (Vec<Seg<'_>>, String) = match err.item {
            Item::Vertex(i) => (vec![Seg::Key("vertices"), Seg::Index(i)], format!("vertices[{i}]")),
            Item::Edge(i) => {
                let key = if matches!(err.kind, InstanceErrorKind::BadLength(_)) { Some("length") } else { None };
                let mut p = vec![Seg::Key("edges"), Seg::Index(i)];
                let mut w = format!("edges[{i}]");
                if let Some(k) = key {
                    if raw.edges.get(i).is_some_and(|e| e.length.is_some()) {
                        p.push(Seg::Key(k));
                        w = format!("{w}.{k}");
                    }
                }
                (p, w)
            }
            Item::Start => (vec![Seg::Key("start")], "start".into()),
            Item::Whole => (vec![Seg::Key("edges")], "edges".into()),
        };
        at(&path, what, err.kind.into())
    })
}

/// Writes an instance as JSON, one vertex and one edge per line. Reading the text back gives the
/// same instance.
pub fn write_instance(instance: &Instance) -> String {
    let num = |x: f64| serde_json::to_string(&x).unwrap_or_else(|_| "0".into());
    let three_d = instance.vertices().iter().any(|v| v[2] != 0.0);
    let mut s = String::new();
    s.push_str("{\n");
    s.push_str(&format!("  \"format\": \"{FORMAT}\",\n"));
    if let Some(n) = instance.name() {
        s.push_str(&format!("  \"name\": {},\n", serde_json::Value::from(n)));
    }
    s.push_str("  \"vertices\": [\n");
    let nv = instance.vertices().len();
    for (i, v) in instance.vertices().iter().enumerate() {
        let sep = if i + 1 < nv { "," } else { "" };
        if three_d {
            s.push_str(&format!("    [{}, {}, {}]{sep}\n", num(v[0]), num(v[1]), num(v[2])));
        } else {
            s.push_str(&format!("    [{}, {}]{sep}\n", num(v[0]), num(v[1])));
        }
    }
    s.push_str("  ],\n  \"edges\": [\n");
    let ne = instance.edges().len();
    for (i, e) in instance.edges().iter().enumerate() {
        let sep = if i + 1 < ne { "," } else { "" };
        let req = if instance.is_required(i as u32) { ", \"required\": true" } else { "" };
        s.push_str(&format!("    {{\"a\": {}, \"b\": {}, \"length\": {}{req}}}{sep}\n", e.a, e.b, num(e.length)));
    }
    s.push_str("  ]");
    if let Some(st) = instance.start() {
        s.push_str(&format!(",\n  \"start\": {st}"));
    }
    s.push_str("\n}\n");
    s
}

/// A route as written by `towpath route`: the full vertex walk and the services.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RouteJson {
    /// Always [`ROUTE_FORMAT`].
    pub format: String,
    /// The instance's name, if it has one.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub instance: Option<String>,
    /// The solver that found the route.
    pub solver: String,
    /// Total path length.
    pub length: f64,
    /// Length of the required edges.
    pub required_length: f64,
    /// Length of the connecting paths (`length - required_length`).
    pub deadhead_length: f64,
    /// Every vertex visited, in order.
    pub walk: Vec<u32>,
    /// The edge taken between consecutive vertices of the walk.
    pub walk_edges: Vec<u32>,
    /// The required edges in the order served, with the direction.
    pub services: Vec<ServiceJson>,
    /// Solver wall time in seconds.
    pub seconds: f64,
}

/// One served required edge.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServiceJson {
    /// Index of the edge in the instance's `edges`.
    pub edge: u32,
    /// The vertex the tool enters the edge at.
    pub from: u32,
    /// The vertex it leaves at.
    pub to: u32,
}

impl RouteJson {
    /// Builds the JSON form of a route.
    pub fn new(instance: &Instance, route: &Route, solver: &str, seconds: f64) -> Self {
        let required_length = instance.required_length();
        RouteJson {
            format: ROUTE_FORMAT.into(),
            instance: instance.name().map(str::to_string),
            solver: solver.into(),
            length: route.length,
            required_length,
            deadhead_length: route.length - required_length,
            walk: route.vertices.clone(),
            walk_edges: route.edges.clone(),
            services: route.services.iter().map(|s| ServiceJson { edge: s.edge, from: s.from, to: s.to }).collect(),
            seconds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{
  "name": "t",
  "vertices": [[0, 0], [3, 4], [3, 0, 0]],
  "edges": [
    {"a": 0, "b": 1, "required": true},
    {"a": 1, "b": 2, "length": 2.5}
  ],
  "start": 2
}"#;

    #[test]
    fn reads_and_round_trips() {
        let i = read_instance(GOOD).unwrap();
        assert_eq!(i.edges()[0].length, 5.0);
        assert_eq!(i.edges()[1].length, 2.5);
        assert_eq!(i.required(), &[0]);
        assert_eq!(i.start(), Some(2));
        assert_eq!(i.name(), Some("t"));
        let back = read_instance(&write_instance(&i)).unwrap();
        assert_eq!(back, i);
    }

    /// Regression (found by fuzzing): numbers given with more digits than an f64 holds must
    /// parse to the nearest f64, so that writing and reading again gives the same instance.
    #[test]
    fn long_numbers_round_trip() {
        for len in ["1.0072030579778834", "1.0072030579778834999", "0.10000000000000000555"] {
            let text = format!(
                r#"{{"vertices": [[0, 0]], "edges": [{{"a": 0, "b": 0, "length": {len}, "required": true}}]}}"#
            );
            let i = read_instance(&text).unwrap();
            assert_eq!(i.edges()[0].length, len.parse::<f64>().unwrap(), "{len}");
            assert_eq!(read_instance(&write_instance(&i)).unwrap(), i, "{len}");
        }
    }

    #[test]
    fn errors_name_line_and_column() {
        let bad = GOOD.replace("\"b\": 2,", "\"b\": 9,");
        let e = read_instance(&bad).unwrap_err();
        assert_eq!((e.line, e.column), (6, 19), "{e}");
        assert!(e.to_string().contains("edges[1].b"), "{e}");
        assert!(e.to_string().contains("vertex 9 does not exist"), "{e}");

        let bad = GOOD.replace("\"length\": 2.5", "\"length\": -1");
        let e = read_instance(&bad).unwrap_err();
        assert_eq!(e.line, 6, "{e}");
        assert!(e.to_string().contains("edges[1].length"), "{e}");

        let bad = GOOD.replace("[3, 4]", "[3]");
        let e = read_instance(&bad).unwrap_err();
        assert_eq!((e.line, e.column), (3, 24), "{e}");

        let bad = GOOD.replace("\"required\": true", "\"requird\": true");
        let e = read_instance(&bad).unwrap_err();
        assert_eq!(e.line, 5, "{e}");
        assert!(matches!(e.kind, ReadErrorKind::Syntax(_)));
        assert!(e.to_string().contains("requird"), "{e}");

        let bad = GOOD.replace("\"required\": true", "\"required\": false");
        let e = read_instance(&bad).unwrap_err();
        assert!(e.to_string().contains("no edge is required"), "{e}");

        let e = read_instance("{\"vertices\": [], \"edges\": [}").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(matches!(e.kind, ReadErrorKind::Syntax(_)));
    }
}
