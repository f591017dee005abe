//! The open rural postman problem as a sequencing problem, and routes back as vertex walks.
//!
//! Seed 004 §IV replaces the travel graph by a complete graph on the required edges' end points
//! whose weights are shortest-path distances (its Fig. 7). [`RppModel`] builds exactly that as a
//! [`towpath_seq::Problem`]:
//!
//! - **tasks** are the required edges, each with two **modes**: mode 0 traverses the edge from
//!   its first end `a` to `b`, mode 1 from `b` to `a`; the mode cost is the edge length, so a
//!   route's cost is the full path length (required edges plus connecting paths);
//! - **states** are the *terminals*: the distinct end points of required edges, plus the start
//!   vertex if there is one. Other vertices of the graph only ever lie on connecting paths, so
//!   they need no state; this keeps the cost matrix at terminals², not vertices²;
//! - the **cost** between states is the shortest-path distance in the travel graph
//!   ([`ShortestPaths`]);
//! - the route is an **open path** ([`End::Free`]), from the start vertex if one is given,
//!   otherwise from wherever the first required edge begins.
//!
//! [`RppModel::route`] expands a solution back into the full walk through the graph, and
//! [`verify_route`] checks such a walk against the instance without using the model.

use towpath_seq::{Clock, CostModel, End, Mode, ModelError, Problem, StateId, Step, TaskId};

use crate::instance::Instance;
use crate::paths::{ShortestPaths, Stopped, FLOYD_WARSHALL_MAX_VERTICES};

/// Most memory the model's tables may take: shortest-path trees and distances from every
/// terminal to every vertex (12 bytes a pair), the terminals' distance matrix (8 bytes a pair)
/// and, on small graphs, the Floyd–Warshall tables.
pub const MODEL_MAX_BYTES: u64 = 1 << 31;

/// The memory [`RppModel`] takes for its tables on a graph of `vertices` vertices with
/// `terminals` terminals (see [`MODEL_MAX_BYTES`]).
pub fn model_bytes(vertices: usize, terminals: usize) -> u64 {
    let (v, t) = (vertices as u64, terminals as u64);
    let floyd = if vertices <= FLOYD_WARSHALL_MAX_VERTICES { 12 * v * v } else { 0 };
    12u64.saturating_mul(t).saturating_mul(v).saturating_add(8u64.saturating_mul(t).saturating_mul(t)) + floyd
}

/// Why an instance could not be turned into a sequencing problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// The instance is too large for the model's tables.
    #[error(
        "{terminals} terminals (ends of required edges) over {vertices} vertices need {} of shortest-path \
         tables; towpath takes at most {}",
        gigabytes(*bytes),
        gigabytes(MODEL_MAX_BYTES)
    )]
    TooLarge {
        /// Terminals of the instance.
        terminals: usize,
        /// Vertices of the travel graph.
        vertices: usize,
        /// Bytes the tables would take.
        bytes: u64,
    },
    /// The shortest paths were not done within the time limit (or the run was cancelled).
    #[error(
        "{}the shortest paths between the {} terminals were not done within the time limit: {} of {} searches in \
         {:.2} s, about {:.1} s for all of them",
        if .0.cancelled { "cancelled: " } else { "" },
        .0.total,
        .0.done,
        .0.total,
        .0.seconds,
        .0.estimate
    )]
    OutOfTime(Stopped),
    /// The sequencing model refused the problem.
    #[error(transparent)]
    Model(#[from] ModelError),
}

fn gigabytes(b: u64) -> String {
    format!("{:.2} GB", b as f64 / 1e9)
}

/// Shortest-path distances between terminals: the cost model of the open rural postman problem.
#[derive(Clone, Debug)]
pub struct PathCost {
    n: usize,
    dist: Vec<f64>,
    positions: Vec<[f64; 3]>,
}

impl CostModel for PathCost {
    fn num_states(&self) -> usize {
        self.n
    }
    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> f64 {
        self.dist[from.index() * self.n + to.index()]
    }
    fn is_symmetric(&self) -> bool {
        true
    }
    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        self.positions.get(state.index()).copied()
    }
    fn cost_bound(&self) -> Option<f64> {
        Some(self.dist.iter().filter(|d| d.is_finite()).fold(0.0, |m: f64, d| m.max(d.abs())))
    }
}

/// One traversal of a required edge on a route.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Service {
    /// The required edge (an index into [`Instance::edges`]).
    pub edge: u32,
    /// The vertex the traversal starts from.
    pub from: u32,
    /// The vertex it ends at.
    pub to: u32,
    /// Index of the traversal in [`Route::edges`].
    pub position: usize,
}

/// A route through the travel graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// Every vertex visited, in order, including those of connecting paths.
    pub vertices: Vec<u32>,
    /// The edge taken between `vertices[i]` and `vertices[i + 1]`.
    pub edges: Vec<u32>,
    /// The traversals that serve the required edges, in route order.
    pub services: Vec<Service>,
    /// Total length of the walk.
    pub length: f64,
}

/// Why a route could not be built or does not verify.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RouteError {
    /// The steps do not name every required edge once with a valid mode.
    #[error("the solution is not a route over the required edges: {0}")]
    BadSteps(#[from] towpath_seq::Violation),
    /// Two consecutive vertices of the walk are not joined by the edge given.
    #[error("step {0} of the walk does not follow an edge of the graph")]
    NotAWalk(usize),
    /// An edge index is out of range.
    #[error("step {0} of the walk names an edge that does not exist")]
    NoSuchEdge(usize),
    /// A required edge is not served, or served twice.
    #[error("required edge {edge} is served {times} times (must be exactly once)")]
    ServedWrongly {
        /// The edge.
        edge: u32,
        /// How many times it is served.
        times: usize,
    },
    /// A service does not match the walk.
    #[error("service {0} does not match the walk")]
    ServiceMismatch(usize),
    /// The route does not start at the start vertex.
    #[error("the route does not begin at the start vertex {0}")]
    WrongStart(u32),
    /// The stated length is not the walk's length.
    #[error("the route's stated length {stated} differs from its walk's length {actual}")]
    WrongLength {
        /// The length the route states.
        stated: f64,
        /// The length of its walk.
        actual: f64,
    },
    /// A connecting path does not exist (cannot happen for a validated instance).
    #[error("no path from vertex {0} to vertex {1}")]
    NoPath(u32, u32),
}

/// An open rural postman instance turned into a sequencing problem.
#[derive(Clone, Debug)]
pub struct RppModel {
    instance: Instance,
    paths: ShortestPaths,
    /// State index → graph vertex.
    terminals: Vec<u32>,
    problem: Problem<PathCost>,
}

impl RppModel {
    /// Computes shortest paths between terminals (on all cores, without a time limit) and builds
    /// the problem.
    pub fn new(instance: Instance) -> Result<Self, BuildError> {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        Self::build(instance, &Clock::unlimited(), threads)
    }

    /// Builds the model within the clock's time limit, on up to `threads` threads. Refuses
    /// before allocating when its tables would exceed [`MODEL_MAX_BYTES`], and stops when the
    /// shortest paths cannot be done in the time left.
    pub fn build(instance: Instance, clock: &Clock, threads: usize) -> Result<Self, BuildError> {
        let edges = instance.edges();
        let mut terminals: Vec<u32> = Vec::new();
        let mut state_of = vec![u32::MAX; instance.vertices().len()];
        let mut add = |v: u32, terminals: &mut Vec<u32>| {
            if state_of[v as usize] == u32::MAX {
                state_of[v as usize] = terminals.len() as u32;
                terminals.push(v);
            }
            state_of[v as usize]
        };
        let start_state = instance.start().map(|s| add(s, &mut terminals));
        let mut task_states = Vec::with_capacity(instance.required().len());
        for &r in instance.required() {
            let e = edges[r as usize];
            let a = add(e.a, &mut terminals);
            let b = add(e.b, &mut terminals);
            task_states.push((a, b, e.length));
        }
        let vertices = instance.vertices().len();
        let bytes = model_bytes(vertices, terminals.len());
        if bytes > MODEL_MAX_BYTES {
            return Err(BuildError::TooLarge { terminals: terminals.len(), vertices, bytes });
        }
        let paths = ShortestPaths::compute_within(vertices, edges, &terminals, clock, threads)
            .map_err(BuildError::OutOfTime)?;
        let t = terminals.len();
        let mut dist = vec![0.0; t * t];
        for i in 0..t {
            for j in 0..t {
                dist[i * t + j] = paths.dist(terminals[i], terminals[j]).unwrap_or(f64::INFINITY);
            }
        }
        // The graph is undirected: make the matrix exactly symmetric (sums taken in different
        // orders may differ in the last bit).
        for i in 0..t {
            for j in 0..i {
                let m = dist[i * t + j].min(dist[j * t + i]);
                dist[i * t + j] = m;
                dist[j * t + i] = m;
            }
        }
        let positions = terminals.iter().map(|&v| instance.vertices()[v as usize]).collect();
        let cost = PathCost { n: t, dist, positions };
        let mut b = Problem::builder(cost);
        for &(a, e, len) in &task_states {
            let (sa, sb) = (StateId(a), StateId(e));
            b.task(vec![Mode { entry: sa, exit: sb, cost: len }, Mode { entry: sb, exit: sa, cost: len }]);
        }
        if let Some(s) = start_state {
            b.start(StateId(s));
        }
        b.end(End::Free);
        let problem = b.build()?;
        Ok(RppModel { instance, paths, terminals, problem })
    }

    /// The sequencing problem: one task per required edge (see the module docs).
    pub fn problem(&self) -> &Problem<PathCost> {
        &self.problem
    }

    /// The instance.
    pub fn instance(&self) -> &Instance {
        &self.instance
    }

    /// The shortest paths between terminals.
    pub fn paths(&self) -> &ShortestPaths {
        &self.paths
    }

    /// The graph vertex of a state of the problem.
    pub fn vertex_of(&self, s: StateId) -> Option<u32> {
        self.terminals.get(s.index()).copied()
    }

    /// The required edge a task stands for.
    pub fn edge_of(&self, t: TaskId) -> Option<u32> {
        self.instance.required().get(t.index()).copied()
    }

    /// Expands a solution of [`RppModel::problem`] into the full walk through the graph.
    pub fn route(&self, steps: &[Step]) -> Result<Route, RouteError> {
        towpath_seq::check(&self.problem, steps)?;
        let edges = self.instance.edges();
        let mut route = Route { vertices: Vec::new(), edges: Vec::new(), services: Vec::new(), length: 0.0 };
        let mut cur = self.instance.start();
        if let Some(s) = cur {
            route.vertices.push(s);
        }
        for step in steps {
            let e_idx = self.instance.required()[step.task.index()];
            let e = edges[e_idx as usize];
            let (from, to) = if step.mode == 0 { (e.a, e.b) } else { (e.b, e.a) };
            match cur {
                None => route.vertices.push(from),
                Some(c) => {
                    let path = self.paths.path_edges(c, from, edges).ok_or(RouteError::NoPath(c, from))?;
                    let mut v = c;
                    for k in path {
                        v = edges[k as usize].other(v);
                        route.edges.push(k);
                        route.vertices.push(v);
                        route.length += edges[k as usize].length;
                    }
                }
            }
            route.services.push(Service { edge: e_idx, from, to, position: route.edges.len() });
            route.edges.push(e_idx);
            route.vertices.push(to);
            route.length += e.length;
            cur = Some(to);
        }
        Ok(route)
    }
}

/// Checks a route against an instance, sharing no code with the model: the walk follows edges of
/// the graph, starts at the start vertex if there is one, serves every required edge exactly
/// once, and has the length it states (to a relative 1e-9). Returns the walk's length.
pub fn verify_route(instance: &Instance, route: &Route) -> Result<f64, RouteError> {
    let edges = instance.edges();
    if route.vertices.len() != route.edges.len() + 1 && !(route.vertices.is_empty() && route.edges.is_empty()) {
        return Err(RouteError::NotAWalk(route.edges.len()));
    }
    if let (Some(s), Some(&v0)) = (instance.start(), route.vertices.first()) {
        if v0 != s {
            return Err(RouteError::WrongStart(s));
        }
    }
    let mut length = 0.0;
    for (i, &k) in route.edges.iter().enumerate() {
        let e = edges.get(k as usize).ok_or(RouteError::NoSuchEdge(i))?;
        let (u, v) = (route.vertices[i], route.vertices[i + 1]);
        if !((e.a == u && e.b == v) || (e.a == v && e.b == u)) {
            return Err(RouteError::NotAWalk(i));
        }
        length += e.length;
    }
    let mut served = vec![0usize; edges.len()];
    for (i, s) in route.services.iter().enumerate() {
        let ok = route.edges.get(s.position) == Some(&s.edge)
            && route.vertices.get(s.position) == Some(&s.from)
            && route.vertices.get(s.position + 1) == Some(&s.to)
            && instance.is_required(s.edge);
        if !ok {
            return Err(RouteError::ServiceMismatch(i));
        }
        served[s.edge as usize] += 1;
    }
    for &r in instance.required() {
        if served[r as usize] != 1 {
            return Err(RouteError::ServedWrongly { edge: r, times: served[r as usize] });
        }
    }
    if (length - route.length).abs() > 1e-9 * length.abs().max(1.0) {
        return Err(RouteError::WrongLength { stated: route.length, actual: length });
    }
    Ok(length)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instance::Edge;

    /// A path graph 0–1–2–3–4 with required edges (0,1) and (3,4): the best open route serves
    /// one, walks 2 edges, serves the other: length 1 + 2·2 + 1 = 6 with the middle edges of
    /// length 2.
    fn line() -> Instance {
        let v = (0..5).map(|i| [i as f64, 0.0, 0.0]).collect();
        let edges = vec![
            Edge { a: 0, b: 1, length: 1.0 },
            Edge { a: 1, b: 2, length: 2.0 },
            Edge { a: 2, b: 3, length: 2.0 },
            Edge { a: 3, b: 4, length: 1.0 },
        ];
        Instance::new(None, v, edges, &[true, false, false, true], None).unwrap()
    }

    #[test]
    fn route_expands_connecting_paths() {
        let m = RppModel::new(line()).unwrap();
        let steps = [Step { task: TaskId(0), mode: 0 }, Step { task: TaskId(1), mode: 0 }];
        let cost = towpath_seq::check(m.problem(), &steps).unwrap();
        assert_eq!(cost, 6.0);
        let r = m.route(&steps).unwrap();
        assert_eq!(r.vertices, vec![0, 1, 2, 3, 4]);
        assert_eq!(r.length, 6.0);
        assert_eq!(verify_route(m.instance(), &r).unwrap(), 6.0);
        // the wrong direction on the first edge walks it back: 1 + (1 + 2 + 2) + 1
        let steps = [Step { task: TaskId(0), mode: 1 }, Step { task: TaskId(1), mode: 0 }];
        assert_eq!(towpath_seq::check(m.problem(), &steps).unwrap(), 7.0);
        let r = m.route(&steps).unwrap();
        assert_eq!(r.vertices, vec![1, 0, 1, 2, 3, 4]);
        assert_eq!(verify_route(m.instance(), &r).unwrap(), 7.0);
    }

    #[test]
    fn verifier_catches_broken_routes() {
        let m = RppModel::new(line()).unwrap();
        let steps = [Step { task: TaskId(0), mode: 0 }, Step { task: TaskId(1), mode: 0 }];
        let good = m.route(&steps).unwrap();
        let mut r = good.clone();
        r.vertices[2] = 4;
        assert!(matches!(verify_route(m.instance(), &r), Err(RouteError::NotAWalk(_))));
        let mut r = good.clone();
        r.services.pop();
        assert!(matches!(verify_route(m.instance(), &r), Err(RouteError::ServedWrongly { edge: 3, times: 0 })));
        let mut r = good.clone();
        r.length = 5.0;
        assert!(matches!(verify_route(m.instance(), &r), Err(RouteError::WrongLength { .. })));
        let mut r = good;
        r.services[0].position = 1;
        assert!(matches!(verify_route(m.instance(), &r), Err(RouteError::ServiceMismatch(0))));
    }

    /// A path graph of `2r` vertices whose every other edge is required: 2r terminals.
    fn ladder(r: usize) -> Instance {
        let v: Vec<[f64; 3]> = (0..2 * r).map(|i| [i as f64, 0.0, 0.0]).collect();
        let edges: Vec<Edge> = (0..2 * r as u32 - 1).map(|i| Edge { a: i, b: i + 1, length: 1.0 }).collect();
        let req: Vec<bool> = (0..edges.len()).map(|i| i % 2 == 0).collect();
        Instance::new(None, v, edges, &req, None).unwrap()
    }

    #[test]
    fn tables_too_large_are_refused_before_they_are_made() {
        // 12,000 terminals over 12,000 vertices: 12·t·V + 8·t² = 2.9 GB.
        let e = RppModel::new(ladder(6000)).unwrap_err();
        let BuildError::TooLarge { terminals, vertices, bytes } = e.clone() else { panic!("{e}") };
        assert_eq!((terminals, vertices), (12_000, 12_000));
        assert_eq!(bytes, 12 * 12_000 * 12_000 + 8 * 12_000 * 12_000);
        assert!(e.to_string().contains("2.88 GB"), "{e}");
        // Within the budget it builds, and the bound is what the tables take.
        let m = RppModel::new(ladder(400)).unwrap();
        let t = m.problem().cost_model().num_states() as u64;
        assert_eq!(model_bytes(800, t as usize), 12 * t * 800 + 8 * t * t);
    }

    #[test]
    fn shortest_paths_stop_at_the_time_limit_and_say_what_they_need() {
        let i = crate::tewolde_sheng_like(600, 1).unwrap();
        // No time at all: stopped after the first search of each thread.
        let clock = Clock::start(Some(std::time::Duration::ZERO), None);
        let e = RppModel::build(i.clone(), &clock, 2).unwrap_err();
        let BuildError::OutOfTime(stop) = &e else { panic!("{e}") };
        assert!(stop.done < stop.total && stop.total == 1200 && !stop.cancelled, "{e}");
        assert!(e.to_string().contains("of 1200 searches"), "{e}");
        // Cancelled.
        let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
        let e = RppModel::build(i.clone(), &Clock::start(None, Some(flag)), 1).unwrap_err();
        assert!(matches!(&e, BuildError::OutOfTime(s) if s.cancelled), "{e}");
        // With time enough, the same model on any number of threads.
        let a = RppModel::build(i.clone(), &Clock::start(Some(std::time::Duration::from_secs(600)), None), 1).unwrap();
        let b = RppModel::build(i, &Clock::unlimited(), 3).unwrap();
        assert_eq!(a.paths().sources(), b.paths().sources());
        let n = a.problem().cost_model().num_states() as u32;
        for x in (0..n).step_by(97) {
            for y in (0..n).step_by(89) {
                assert_eq!(
                    a.problem().transition(StateId(x), StateId(y)),
                    b.problem().transition(StateId(x), StateId(y))
                );
            }
        }
    }

    #[test]
    fn start_vertex_prices_the_way_in() {
        let i = line();
        let i = Instance::new(None, i.vertices().to_vec(), i.edges().to_vec(), &[true, false, false, true], Some(2))
            .unwrap();
        let m = RppModel::new(i).unwrap();
        let best = towpath_seq::solve_exact(m.problem()).unwrap().unwrap();
        // from 2: to 3 (2), serve 3→4 (1), back to 1 (2+2+1... ) or to 1 (2), serve 1→0 (1),
        // back to 3 (1+2+2), serve (1) = 2+1+5+1 = 9 either way
        assert_eq!(best.cost, 9.0);
        let r = m.route(&best.steps).unwrap();
        assert_eq!(r.vertices[0], 2);
        assert_eq!(verify_route(m.instance(), &r).unwrap(), 9.0);
    }
}
