//! An open rural postman instance (seed 004 §III-C): an undirected travel graph whose vertices
//! have coordinates and whose edges have lengths, a subset of *required* edges that the tool must
//! traverse, and optionally the vertex the tool starts from.

use towpath_seq::MAX_ROUTE_COST;

use crate::paths::connected_components;

/// One edge of the travel graph.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// One end vertex.
    pub a: u32,
    /// The other end vertex.
    pub b: u32,
    /// Length (travel cost) of the edge, finite and ≥ 0.
    pub length: f64,
}

impl Edge {
    /// The end of the edge opposite `v` (`v` must be an end).
    #[inline]
    pub fn other(&self, v: u32) -> u32 {
        if v == self.a {
            self.b
        } else {
            self.a
        }
    }
}

/// Which part of an instance a validation error is about (used by readers to point at the line
/// of the input that holds it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// The vertex with this index.
    Vertex(usize),
    /// The edge with this index.
    Edge(usize),
    /// The start vertex.
    Start,
    /// The instance as a whole.
    Whole,
}

/// What is wrong with an instance.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InstanceErrorKind {
    /// A coordinate is not finite.
    #[error("coordinate {0} is not a finite number")]
    BadCoordinate(f64),
    /// A vertex does not have 2 or 3 coordinates.
    #[error("a vertex needs 2 or 3 coordinates, this one has {0}")]
    BadDimension(usize),
    /// An edge names a vertex that does not exist.
    #[error("vertex {vertex} does not exist (there are {num_vertices} vertices, numbered from 0)")]
    NoSuchVertex {
        /// The vertex named.
        vertex: u64,
        /// How many vertices there are.
        num_vertices: usize,
    },
    /// An edge length is negative or not finite.
    #[error("edge length {0} must be a finite number ≥ 0")]
    BadLength(f64),
    /// No edge is required.
    #[error("no edge is required: mark at least one edge \"required\": true")]
    NothingRequired,
    /// Two required edges cannot reach each other.
    #[error("required edges {a} and {b} are in different connected parts of the graph: no route can serve both")]
    Disconnected {
        /// A required edge.
        a: usize,
        /// A required edge that `a` cannot reach.
        b: usize,
    },
    /// The start vertex cannot reach a required edge.
    #[error("the start vertex cannot reach required edge {0}: the graph is not connected")]
    StartDisconnected(usize),
    /// The edges are so long that route lengths could not be added up.
    #[error(
        "the edges' lengths add up to {total:e}: a route serving {required} required edges could be longer than \
         the {MAX_ROUTE_COST:e} towpath adds up; scale the lengths down"
    )]
    TooLong {
        /// The sum of every edge's length.
        total: f64,
        /// Required edges.
        required: usize,
    },
}

/// A validation error: what is wrong and where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{kind}")]
pub struct InstanceError {
    /// The part of the instance the error is about.
    pub item: Item,
    /// What is wrong.
    pub kind: InstanceErrorKind,
}

/// A validated open rural postman instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    name: Option<String>,
    vertices: Vec<[f64; 3]>,
    edges: Vec<Edge>,
    required: Vec<u32>,
    start: Option<u32>,
}

impl Instance {
    /// Validates and builds an instance. `required[i]` says whether edge `i` must be traversed
    /// (missing entries are `false`). Coordinates of 2D data have a zero third coordinate.
    pub fn new(
        name: Option<String>,
        vertices: Vec<[f64; 3]>,
        edges: Vec<Edge>,
        required: &[bool],
        start: Option<u32>,
    ) -> Result<Self, InstanceError> {
        let nv = vertices.len();
        for (i, v) in vertices.iter().enumerate() {
            if let Some(c) = v.iter().find(|c| !c.is_finite()) {
                return Err(InstanceError { item: Item::Vertex(i), kind: InstanceErrorKind::BadCoordinate(*c) });
            }
        }
        for (i, e) in edges.iter().enumerate() {
            for v in [e.a, e.b] {
                if v as usize >= nv {
                    return Err(InstanceError {
                        item: Item::Edge(i),
                        kind: InstanceErrorKind::NoSuchVertex { vertex: v as u64, num_vertices: nv },
                    });
                }
            }
            if !(e.length.is_finite() && e.length >= 0.0) {
                return Err(InstanceError { item: Item::Edge(i), kind: InstanceErrorKind::BadLength(e.length) });
            }
        }
        if let Some(s) = start {
            if s as usize >= nv {
                return Err(InstanceError {
                    item: Item::Start,
                    kind: InstanceErrorKind::NoSuchVertex { vertex: s as u64, num_vertices: nv },
                });
            }
        }
        let required: Vec<u32> =
            (0..edges.len()).filter(|&i| required.get(i).copied().unwrap_or(false)).map(|i| i as u32).collect();
        let Some(&first) = required.first() else {
            return Err(InstanceError { item: Item::Whole, kind: InstanceErrorKind::NothingRequired });
        };
        // A route is the required edges and a shortest path before each: at most
        // (required + 1) times every edge.
        let total: f64 = edges.iter().map(|e| e.length).sum();
        if total * (required.len() + 1) as f64 > MAX_ROUTE_COST {
            return Err(InstanceError {
                item: Item::Whole,
                kind: InstanceErrorKind::TooLong { total, required: required.len() },
            });
        }
        let comp = connected_components(nv, &edges);
        let c0 = comp[edges[first as usize].a as usize];
        for &r in &required {
            if comp[edges[r as usize].a as usize] != c0 {
                return Err(InstanceError {
                    item: Item::Edge(r as usize),
                    kind: InstanceErrorKind::Disconnected { a: first as usize, b: r as usize },
                });
            }
        }
        if let Some(s) = start {
            if comp[s as usize] != c0 {
                return Err(InstanceError {
                    item: Item::Start,
                    kind: InstanceErrorKind::StartDisconnected(first as usize),
                });
            }
        }
        Ok(Instance { name, vertices, edges, required, start })
    }

    /// The instance's name, if it has one.
    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }

    /// Vertex coordinates.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// All edges of the travel graph.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Indices (into [`Instance::edges`]) of the required edges, ascending.
    pub fn required(&self) -> &[u32] {
        &self.required
    }

    /// Whether edge `e` is required.
    pub fn is_required(&self, e: u32) -> bool {
        self.required.binary_search(&e).is_ok()
    }

    /// The start vertex, if the route must start at one.
    pub fn start(&self) -> Option<u32> {
        self.start
    }

    /// Total length of the required edges (a lower bound on any route).
    pub fn required_length(&self) -> f64 {
        self.required.iter().map(|&e| self.edges[e as usize].length).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(a: u32, b: u32, length: f64) -> Edge {
        Edge { a, b, length }
    }

    #[test]
    fn refuses_bad_input_with_the_item() {
        let v = vec![[0.0; 3]; 3];
        let err = Instance::new(None, v.clone(), vec![e(0, 1, 1.0), e(1, 5, 1.0)], &[true], None).unwrap_err();
        assert_eq!(err.item, Item::Edge(1));
        let err = Instance::new(None, v.clone(), vec![e(0, 1, -1.0)], &[true], None).unwrap_err();
        assert_eq!(err.kind, InstanceErrorKind::BadLength(-1.0));
        let err = Instance::new(None, v.clone(), vec![e(0, 1, 1.0)], &[false], None).unwrap_err();
        assert_eq!(err.kind, InstanceErrorKind::NothingRequired);
        // vertex 2 is isolated: a required loop on it cannot be reached from edge 0
        let err = Instance::new(None, v.clone(), vec![e(0, 1, 1.0), e(2, 2, 0.0)], &[true, true], None).unwrap_err();
        assert_eq!(err.item, Item::Edge(1));
        let err = Instance::new(None, v, vec![e(0, 1, 1.0)], &[true], Some(2)).unwrap_err();
        assert_eq!(err.item, Item::Start);
        // Lengths a route could not add up.
        let err = Instance::new(None, vec![[0.0; 3]; 2], vec![e(0, 1, 1e300)], &[true], None).unwrap_err();
        assert!(matches!(err.kind, InstanceErrorKind::TooLong { required: 1, .. }), "{err}");
    }
}
