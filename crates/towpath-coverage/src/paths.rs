//! Shortest paths in the travel graph from a set of source vertices: Floyd–Warshall (seed 004
//! §IV, §V) on small graphs, one Dijkstra search per source on larger ones. Both keep, for
//! each source, a shortest-path tree (the edge by which each vertex is reached) so connecting
//! paths can be written out vertex by vertex.

use std::cmp;
use std::collections::BinaryHeap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use towpath_seq::Clock;

use crate::instance::Edge;

/// Graphs with at most this many vertices use Floyd–Warshall (O(V³)); larger ones run
/// Dijkstra from each source (O(S · E log V)).
pub const FLOYD_WARSHALL_MAX_VERTICES: usize = 300;

/// Which algorithm computed the paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathAlgorithm {
    /// All pairs by Floyd–Warshall.
    FloydWarshall,
    /// One Dijkstra search per source.
    Dijkstra,
}

/// Shortest-path searches stopped before they were all done: by the clock, or because they
/// were seen to need more time than was left.
#[derive(Clone, Debug, PartialEq)]
pub struct Stopped {
    /// Searches done (one per source).
    pub done: usize,
    /// Searches needed.
    pub total: usize,
    /// Seconds spent.
    pub seconds: f64,
    /// Seconds all of them would take, projected from those done.
    pub estimate: f64,
    /// True when the run was cancelled rather than out of time.
    pub cancelled: bool,
}

/// Marks "no edge" in a shortest-path tree (the source itself, or unreachable).
pub const NO_EDGE: u32 = u32::MAX;

/// Shortest paths from each source vertex to every vertex.
#[derive(Clone, Debug)]
pub struct ShortestPaths {
    num_vertices: usize,
    sources: Vec<u32>,
    /// `row_of[v]` is the row of source `v`, or `u32::MAX`.
    row_of: Vec<u32>,
    /// `dist[row * V + v]`.
    dist: Vec<f64>,
    /// `pred[row * V + v]`: the edge by which `v` is reached on a shortest path from the source.
    pred: Vec<u32>,
    algorithm: PathAlgorithm,
}

impl ShortestPaths {
    /// Computes shortest paths from `sources` (duplicates are ignored) over an undirected graph,
    /// choosing the algorithm by size.
    pub fn compute(num_vertices: usize, edges: &[Edge], sources: &[u32]) -> Self {
        if num_vertices <= FLOYD_WARSHALL_MAX_VERTICES {
            Self::floyd_warshall(num_vertices, edges, sources)
        } else {
            Self::dijkstra(num_vertices, edges, sources)
        }
    }

    fn empty(num_vertices: usize, sources: &[u32], algorithm: PathAlgorithm) -> Self {
        let mut row_of = vec![u32::MAX; num_vertices];
        let mut uniq = Vec::new();
        for &s in sources {
            if row_of[s as usize] == u32::MAX {
                row_of[s as usize] = uniq.len() as u32;
                uniq.push(s);
            }
        }
        let cells = uniq.len() * num_vertices;
        ShortestPaths {
            num_vertices,
            sources: uniq,
            row_of,
            dist: vec![f64::INFINITY; cells],
            pred: vec![NO_EDGE; cells],
            algorithm,
        }
    }

    /// Floyd–Warshall over all pairs, keeping the rows of the sources.
    pub fn floyd_warshall(num_vertices: usize, edges: &[Edge], sources: &[u32]) -> Self {
        let n = num_vertices;
        let mut d = vec![f64::INFINITY; n * n];
        // pred[i * n + j]: the last edge on the best known path i → j.
        let mut p = vec![NO_EDGE; n * n];
        for i in 0..n {
            d[i * n + i] = 0.0;
        }
        for (k, e) in edges.iter().enumerate() {
            let (a, b) = (e.a as usize, e.b as usize);
            if a == b {
                continue;
            }
            if e.length < d[a * n + b] {
                d[a * n + b] = e.length;
                d[b * n + a] = e.length;
                p[a * n + b] = k as u32;
                p[b * n + a] = k as u32;
            }
        }
        for k in 0..n {
            for i in 0..n {
                let dik = d[i * n + k];
                if !dik.is_finite() {
                    continue;
                }
                for j in 0..n {
                    let via = dik + d[k * n + j];
                    if via < d[i * n + j] {
                        d[i * n + j] = via;
                        p[i * n + j] = p[k * n + j];
                    }
                }
            }
        }
        let mut sp = Self::empty(n, sources, PathAlgorithm::FloydWarshall);
        for (r, &s) in sp.sources.iter().enumerate() {
            let s = s as usize;
            sp.dist[r * n..(r + 1) * n].copy_from_slice(&d[s * n..(s + 1) * n]);
            sp.pred[r * n..(r + 1) * n].copy_from_slice(&p[s * n..(s + 1) * n]);
        }
        sp
    }

    /// One Dijkstra search from each source.
    pub fn dijkstra(num_vertices: usize, edges: &[Edge], sources: &[u32]) -> Self {
        let n = num_vertices;
        let adj = adjacency(n, edges);
        let mut sp = Self::empty(n, sources, PathAlgorithm::Dijkstra);
        let srcs = sp.sources.clone();
        search_rows(&adj, n, &srcs, &mut sp.dist, &mut sp.pred, &|| true);
        sp
    }

    /// Computes shortest paths like [`ShortestPaths::compute`], on up to `threads` threads, within
    /// the clock's time limit. The searches stop when the clock expires, or as soon as they are
    /// seen to need more than the time that was left when they began (projected from the searches
    /// done, once a twentieth of them or of that time has gone by).
    pub fn compute_within(
        num_vertices: usize,
        edges: &[Edge],
        sources: &[u32],
        clock: &Clock,
        threads: usize,
    ) -> Result<Self, Stopped> {
        if num_vertices <= FLOYD_WARSHALL_MAX_VERTICES {
            return Ok(Self::floyd_warshall(num_vertices, edges, sources));
        }
        let n = num_vertices;
        let adj = adjacency(n, edges);
        let mut sp = Self::empty(n, sources, PathAlgorithm::Dijkstra);
        let rows = sp.sources.len();
        if rows == 0 || n == 0 {
            return Ok(sp);
        }
        let t0 = Instant::now();
        let left = clock.remaining();
        let done = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        // After each search: stop on the clock, or when the searches will not fit the time left.
        let keep_going = || {
            let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
            if clock.expired() {
                stop.store(true, Ordering::Relaxed);
            } else if let Some(left) = left {
                let spent = t0.elapsed();
                if (finished * 20 >= rows || spent * 20 >= left)
                    && spent.as_secs_f64() * rows as f64 / finished as f64 > left.as_secs_f64()
                {
                    stop.store(true, Ordering::Relaxed);
                }
            }
            !stop.load(Ordering::Relaxed)
        };
        let per = rows.div_ceil(threads.clamp(1, rows));
        let srcs = sp.sources.clone();
        let parts = sp.dist.chunks_mut(per * n).zip(sp.pred.chunks_mut(per * n)).zip(srcs.chunks(per));
        std::thread::scope(|scope| {
            for ((dist, pred), part) in parts {
                let (adj, keep_going) = (&adj, &keep_going);
                scope.spawn(move || search_rows(adj, n, part, dist, pred, keep_going));
            }
        });
        if stop.load(Ordering::Relaxed) {
            let finished = done.load(Ordering::Relaxed).min(rows);
            let seconds = t0.elapsed().as_secs_f64();
            return Err(Stopped {
                done: finished,
                total: rows,
                seconds,
                estimate: seconds * rows as f64 / finished.max(1) as f64,
                cancelled: clock.cancelled(),
            });
        }
        Ok(sp)
    }

    /// The algorithm that computed these paths.
    pub fn algorithm(&self) -> PathAlgorithm {
        self.algorithm
    }

    /// The distinct source vertices, in the order given.
    pub fn sources(&self) -> &[u32] {
        &self.sources
    }

    /// Shortest distance from source `s` to vertex `v` (infinite if unreachable); `None` if `s`
    /// is not a source.
    pub fn dist(&self, s: u32, v: u32) -> Option<f64> {
        let r = *self.row_of.get(s as usize)?;
        if r == u32::MAX {
            return None;
        }
        self.dist.get(r as usize * self.num_vertices + v as usize).copied()
    }

    /// The edges of a shortest path from source `s` to `v`, in travel order; `None` if `s` is not
    /// a source or `v` cannot be reached.
    pub fn path_edges(&self, s: u32, v: u32, edges: &[Edge]) -> Option<Vec<u32>> {
        let r = *self.row_of.get(s as usize)?;
        if r == u32::MAX || v as usize >= self.num_vertices {
            return None;
        }
        let row = r as usize * self.num_vertices;
        if !self.dist[row + v as usize].is_finite() {
            return None;
        }
        let mut out = Vec::new();
        let mut cur = v;
        while cur != s {
            let k = self.pred[row + cur as usize];
            if k == NO_EDGE || out.len() > self.num_vertices {
                return None;
            }
            out.push(k);
            cur = edges[k as usize].other(cur);
        }
        out.reverse();
        Some(out)
    }
}

#[derive(PartialEq)]
struct Entry {
    d: f64,
    v: u32,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> cmp::Ordering {
        // min-heap on distance, ties by vertex for determinism
        other.d.total_cmp(&self.d).then_with(|| other.v.cmp(&self.v))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// One Dijkstra search per source, row after row of `dist` and `pred` (`n` entries each), as
/// long as `keep_going` (asked after each search) says so.
fn search_rows(
    adj: &Adjacency,
    n: usize,
    sources: &[u32],
    dist: &mut [f64],
    pred: &mut [u32],
    keep_going: &(dyn Fn() -> bool + Sync),
) {
    let mut heap = BinaryHeap::new();
    for ((&s, dist), pred) in sources.iter().zip(dist.chunks_mut(n)).zip(pred.chunks_mut(n)) {
        let s = s as usize;
        dist[s] = 0.0;
        heap.clear();
        heap.push(Entry { d: 0.0, v: s as u32 });
        while let Some(Entry { d, v }) = heap.pop() {
            if d > dist[v as usize] {
                continue;
            }
            for &(w, k, length) in adj.of(v) {
                let nd = d + length;
                if nd < dist[w as usize] {
                    dist[w as usize] = nd;
                    pred[w as usize] = k;
                    heap.push(Entry { d: nd, v: w });
                }
            }
        }
        if !keep_going() {
            return;
        }
    }
}

/// Adjacency lists in one array (loops left out): the neighbours of `v` are
/// `arcs[start[v]..start[v + 1]]`, each `(neighbour, edge index, length)`.
pub(crate) struct Adjacency {
    start: Vec<usize>,
    arcs: Vec<(u32, u32, f64)>,
}

impl Adjacency {
    #[inline]
    fn of(&self, v: u32) -> &[(u32, u32, f64)] {
        &self.arcs[self.start[v as usize]..self.start[v as usize + 1]]
    }
}

/// The adjacency of an undirected graph, each vertex's arcs in edge order.
pub(crate) fn adjacency(n: usize, edges: &[Edge]) -> Adjacency {
    let mut start = vec![0usize; n + 1];
    for e in edges.iter().filter(|e| e.a != e.b) {
        start[e.a as usize + 1] += 1;
        start[e.b as usize + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut arcs = vec![(0u32, 0u32, 0.0f64); start[n]];
    for (k, e) in edges.iter().enumerate().filter(|(_, e)| e.a != e.b) {
        arcs[fill[e.a as usize]] = (e.b, k as u32, e.length);
        fill[e.a as usize] += 1;
        arcs[fill[e.b as usize]] = (e.a, k as u32, e.length);
        fill[e.b as usize] += 1;
    }
    Adjacency { start, arcs }
}

/// Connected component label of each vertex.
pub(crate) fn connected_components(n: usize, edges: &[Edge]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for e in edges {
        let (ra, rb) = (find(&mut parent, e.a), find(&mut parent, e.b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    (0..n as u32).map(|v| find(&mut parent, v)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn random_graph(n: usize, raw: &[(u8, u8, u16)]) -> Vec<Edge> {
        raw.iter()
            .map(|&(a, b, l)| Edge { a: a as u32 % n as u32, b: b as u32 % n as u32, length: l as f64 / 8.0 })
            .collect()
    }

    proptest! {
        /// Floyd–Warshall and Dijkstra agree on distances, and every reconstructed path is a
        /// walk from the source to the target whose length is the distance.
        #[test]
        fn floyd_warshall_agrees_with_dijkstra(n in 1usize..20, raw in prop::collection::vec((0u8..255, 0u8..255, 0u16..400), 0..60)) {
            let edges = random_graph(n, &raw);
            let sources: Vec<u32> = (0..n as u32).collect();
            let fw = ShortestPaths::floyd_warshall(n, &edges, &sources);
            let dj = ShortestPaths::dijkstra(n, &edges, &sources);
            for s in 0..n as u32 {
                for v in 0..n as u32 {
                    let (a, b) = (fw.dist(s, v).unwrap(), dj.dist(s, v).unwrap());
                    prop_assert!(a == b || (a - b).abs() < 1e-9, "{s}->{v}: {a} vs {b}");
                    for sp in [&fw, &dj] {
                        match sp.path_edges(s, v, &edges) {
                            None => prop_assert!(!a.is_finite()),
                            Some(path) => {
                                let mut cur = s;
                                let mut len = 0.0;
                                for k in path {
                                    let e = edges[k as usize];
                                    prop_assert!(e.a == cur || e.b == cur);
                                    cur = e.other(cur);
                                    len += e.length;
                                }
                                prop_assert_eq!(cur, v);
                                prop_assert!((len - a).abs() < 1e-9);
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn components() {
        let edges = vec![Edge { a: 0, b: 1, length: 1.0 }, Edge { a: 2, b: 3, length: 1.0 }];
        let c = connected_components(5, &edges);
        assert_eq!(c[0], c[1]);
        assert_eq!(c[2], c[3]);
        assert_ne!(c[0], c[2]);
        assert_ne!(c[4], c[0]);
    }
}
