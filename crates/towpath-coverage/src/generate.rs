//! A generator of open rural postman instances shaped like seed 004's sample data (Table I:
//! data sets of 6 vertices / 3 required edges up to 80 vertices / 40 required edges), so its
//! GA-versus-ACO comparison can be reproduced.
//!
//! The paper's sample graphs are hand-made and not published; what is known is their shape:
//! every vertex is an end point of exactly one required edge (|V| = 2|R|, as in its Fig. 7),
//! the required edges stand for the tool paths of flat patches (an edge joins the two ends of a
//! patch's path and weighs their straight-line distance, §III-C), other edges connect the
//! patches (data set #1 has 10 edges for 6 vertices), and lengths are in metres (route lengths
//! 16 m to 102 m). The generator builds graphs with that shape:
//!
//! - `r` patches on a jittered square grid of 2 m cells; each patch path is a segment through
//!   its cell's centre at a random angle, 0.6–0.9 cell long: its ends are two vertices and the
//!   segment is a required edge;
//! - each vertex is joined to its two nearest other vertices (not its own partner) by a
//!   non-required edge of straight-line length, and components are then joined by their
//!   closest pair of vertices until the graph is connected.
//!
//! The same `(required, seed)` always gives the same instance.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::instance::{Edge, Instance};
use crate::paths::connected_components;

/// The sizes of seed 004's Table I data sets: (vertices, required edges).
pub const TABLE_I_SIZES: [(usize, usize); 10] =
    [(6, 3), (10, 5), (20, 10), (30, 15), (40, 20), (50, 25), (60, 30), (64, 32), (70, 35), (80, 40)];

/// The most required edges [`tewolde_sheng_like`] generates: the largest instance whose sequencing
/// model fits [`crate::MODEL_MAX_BYTES`] (2R terminals over 2R vertices).
pub const MAX_GENERATED_REQUIRED: usize = 5000;

/// Side of a patch cell, metres.
const CELL: f64 = 2.0;

/// A size [`tewolde_sheng_like`] does not generate.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GenerateError {
    /// No required edge asked for.
    #[error("an instance needs at least 1 required edge")]
    Empty,
    /// More required edges than the model can take.
    #[error(
        "{0} required edges asked for; at most {MAX_GENERATED_REQUIRED} are generated (the sequencing model of R \
         required edges keeps shortest-path tables of 80·R² bytes)"
    )]
    TooLarge(usize),
}

/// Generates an instance with `required` required edges and `2 * required` vertices (see the
/// module docs), from 1 to [`MAX_GENERATED_REQUIRED`] required edges.
pub fn tewolde_sheng_like(required: usize, seed: u64) -> Result<Instance, GenerateError> {
    if required == 0 {
        return Err(GenerateError::Empty);
    }
    if required > MAX_GENERATED_REQUIRED {
        return Err(GenerateError::TooLarge(required));
    }
    let r = required;
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x5EED_0004_u64.wrapping_mul(r as u64 + 1));
    let cols = (r as f64).sqrt().ceil() as usize;
    let mut vertices = Vec::with_capacity(2 * r);
    let mut edges = Vec::new();
    let mut required_flags = Vec::new();
    for i in 0..r {
        let (c, row) = (i % cols, i / cols);
        let cx = (c as f64 + 0.5) * CELL + rng.gen_range(-0.2..0.2) * CELL;
        let cy = (row as f64 + 0.5) * CELL + rng.gen_range(-0.2..0.2) * CELL;
        let half = 0.5 * rng.gen_range(0.6..0.9) * CELL;
        let ang: f64 = rng.gen_range(0.0..std::f64::consts::PI);
        let (dx, dy) = (half * ang.cos(), half * ang.sin());
        vertices.push([round_mm(cx - dx), round_mm(cy - dy), 0.0]);
        vertices.push([round_mm(cx + dx), round_mm(cy + dy), 0.0]);
        let (a, b) = (2 * i as u32, 2 * i as u32 + 1);
        edges.push(Edge { a, b, length: dist(&vertices, a, b) });
        required_flags.push(true);
    }
    let n = vertices.len() as u32;
    // Each vertex to its two nearest others (not its partner), by distance then index.
    let grid = Grid::new(&vertices);
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for v in 0..n {
        for w in grid.two_nearest(&vertices, v) {
            pairs.push((v.min(w), v.max(w)));
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    for (a, b) in pairs {
        edges.push(Edge { a, b, length: dist(&vertices, a, b) });
        required_flags.push(false);
    }
    join_components(&vertices, &mut edges, &mut required_flags);
    let name = format!("seed004-like-{}v-{}re-s{}", 2 * r, r, seed);
    // Indices are in range, lengths finite and the graph connected by construction: the
    // generator's own output, not user input, so a failure here is a bug in this function.
    #[allow(clippy::expect_used)]
    Ok(Instance::new(Some(name), vertices, edges, &required_flags, None).expect("generated instance is valid"))
}

/// Joins the components of the graph until it is connected: each time by the closest pair
/// (vertex a in vertex 0's component, vertex b outside it; ties to the lowest a, then b). Kept
/// as Prim's algorithm over components: for every vertex outside, its nearest vertex inside.
fn join_components(vertices: &[[f64; 3]], edges: &mut Vec<Edge>, required: &mut Vec<bool>) {
    let n = vertices.len();
    let comp = connected_components(n, edges);
    let c0 = comp[0];
    let mut inside: Vec<bool> = comp.iter().map(|&c| c == c0).collect();
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (v, &c) in comp.iter().enumerate() {
        members[c as usize].push(v as u32);
    }
    // near[b] = (distance, a): the nearest inside vertex of an outside b.
    let mut near: Vec<(f64, u32)> = vec![(f64::INFINITY, u32::MAX); n];
    let update = |near: &mut Vec<(f64, u32)>, inside: &[bool], added: &[u32]| {
        for b in 0..n {
            if inside[b] {
                continue;
            }
            for &a in added {
                let d = dist(vertices, a, b as u32);
                if d < near[b].0 || (d == near[b].0 && a < near[b].1) {
                    near[b] = (d, a);
                }
            }
        }
    };
    update(&mut near, &inside, &members[c0 as usize]);
    loop {
        let mut best: Option<(f64, u32, u32)> = None;
        for b in 0..n {
            if inside[b] {
                continue;
            }
            let (d, a) = near[b];
            if best.is_none_or(|(bd, ba, _)| d < bd || (d == bd && a < ba)) {
                best = Some((d, a, b as u32));
            }
        }
        let Some((d, a, b)) = best else { break };
        edges.push(Edge { a, b, length: d });
        required.push(false);
        let joined = std::mem::take(&mut members[comp[b as usize] as usize]);
        for &v in &joined {
            inside[v as usize] = true;
        }
        update(&mut near, &inside, &joined);
    }
}

/// A bucket grid of cells [`CELL`] wide over the vertices, for exact nearest-vertex queries.
struct Grid {
    x0: f64,
    y0: f64,
    cols: usize,
    rows: usize,
    /// The vertices of each cell, ascending.
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(vertices: &[[f64; 3]]) -> Self {
        let x0 = vertices.iter().map(|v| v[0]).fold(f64::INFINITY, f64::min);
        let y0 = vertices.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min);
        let x1 = vertices.iter().map(|v| v[0]).fold(f64::NEG_INFINITY, f64::max);
        let y1 = vertices.iter().map(|v| v[1]).fold(f64::NEG_INFINITY, f64::max);
        let cols = ((x1 - x0) / CELL) as usize + 1;
        let rows = ((y1 - y0) / CELL) as usize + 1;
        let mut g = Grid { x0, y0, cols, rows, cells: vec![Vec::new(); cols * rows] };
        for (i, v) in vertices.iter().enumerate() {
            let (c, r) = g.cell(v);
            g.cells[r * cols + c].push(i as u32);
        }
        g
    }

    fn cell(&self, v: &[f64; 3]) -> (usize, usize) {
        let c = (((v[0] - self.x0) / CELL) as usize).min(self.cols - 1);
        let r = (((v[1] - self.y0) / CELL) as usize).min(self.rows - 1);
        (c, r)
    }

    /// The two nearest vertices to `v` other than `v` and its partner `v ^ 1`, ordered by
    /// distance then index. Rings of cells are searched outwards; once rings 0..=k are done,
    /// every vertex not yet seen is more than k cells away, so the search stops when the second
    /// is within k − 1 cells (a whole cell of margin against rounding).
    fn two_nearest(&self, vertices: &[[f64; 3]], v: u32) -> Vec<u32> {
        let (c, r) = self.cell(&vertices[v as usize]);
        let mut found: Vec<(f64, u32)> = Vec::new();
        let max_ring = self.cols.max(self.rows);
        for k in 0..=max_ring {
            let (c_lo, c_hi) = (c as isize - k as isize, c as isize + k as isize);
            let (r_lo, r_hi) = (r as isize - k as isize, r as isize + k as isize);
            for rr in r_lo..=r_hi {
                for cc in c_lo..=c_hi {
                    let on_ring = rr == r_lo || rr == r_hi || cc == c_lo || cc == c_hi;
                    if !on_ring || rr < 0 || cc < 0 || rr as usize >= self.rows || cc as usize >= self.cols {
                        continue;
                    }
                    for &w in &self.cells[rr as usize * self.cols + cc as usize] {
                        if w != v && w != (v ^ 1) {
                            found.push((dist(vertices, v, w), w));
                        }
                    }
                }
            }
            if found.len() >= 2 {
                found.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
                found.truncate(2);
                if k >= 1 && found[1].0 <= (k - 1) as f64 * CELL {
                    break;
                }
            }
        }
        found.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        found.into_iter().take(2).map(|(_, w)| w).collect()
    }
}

fn dist(v: &[[f64; 3]], a: u32, b: u32) -> f64 {
    let (p, q) = (v[a as usize], v[b as usize]);
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
}

fn round_mm(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_match_table_i() {
        for (v, r) in TABLE_I_SIZES {
            let i = tewolde_sheng_like(r, 1).unwrap();
            assert_eq!(i.vertices().len(), v);
            assert_eq!(i.required().len(), r);
            // every vertex is an end of exactly one required edge
            let mut deg = vec![0; v];
            for &e in i.required() {
                let e = i.edges()[e as usize];
                deg[e.a as usize] += 1;
                deg[e.b as usize] += 1;
            }
            assert!(deg.iter().all(|&d| d == 1));
            // connected
            let comp = connected_components(v, i.edges());
            assert!(comp.iter().all(|&c| c == comp[0]));
        }
        // data set #1 of the paper has 10 edges for 6 vertices; ours is of that order
        let e = tewolde_sheng_like(3, 1).unwrap().edges().len();
        assert!((6..=14).contains(&e), "{e} edges");
    }

    #[test]
    fn deterministic_by_seed() {
        assert_eq!(tewolde_sheng_like(20, 5), tewolde_sheng_like(20, 5));
        assert_ne!(tewolde_sheng_like(20, 5), tewolde_sheng_like(20, 6));
    }

    /// The generator as first written: every pair scanned (O(n²) per join). The fast one must
    /// give exactly its instances.
    fn tewolde_sheng_like_by_scanning(r: usize, seed: u64) -> Instance {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x5EED_0004_u64.wrapping_mul(r as u64 + 1));
        let cols = (r as f64).sqrt().ceil() as usize;
        let mut vertices = Vec::new();
        let mut edges = Vec::new();
        let mut flags = Vec::new();
        for i in 0..r {
            let (c, row) = (i % cols, i / cols);
            let cx = (c as f64 + 0.5) * CELL + rng.gen_range(-0.2..0.2) * CELL;
            let cy = (row as f64 + 0.5) * CELL + rng.gen_range(-0.2..0.2) * CELL;
            let half = 0.5 * rng.gen_range(0.6..0.9) * CELL;
            let ang: f64 = rng.gen_range(0.0..std::f64::consts::PI);
            let (dx, dy) = (half * ang.cos(), half * ang.sin());
            vertices.push([round_mm(cx - dx), round_mm(cy - dy), 0.0]);
            vertices.push([round_mm(cx + dx), round_mm(cy + dy), 0.0]);
            let (a, b) = (2 * i as u32, 2 * i as u32 + 1);
            edges.push(Edge { a, b, length: dist(&vertices, a, b) });
            flags.push(true);
        }
        let n = vertices.len() as u32;
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for v in 0..n {
            let mut others: Vec<u32> = (0..n).filter(|&w| w != v && w != (v ^ 1)).collect();
            others.sort_by(|&p, &q| dist(&vertices, v, p).total_cmp(&dist(&vertices, v, q)).then(p.cmp(&q)));
            for &w in others.iter().take(2) {
                pairs.push((v.min(w), v.max(w)));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        for (a, b) in pairs {
            edges.push(Edge { a, b, length: dist(&vertices, a, b) });
            flags.push(false);
        }
        loop {
            let comp = connected_components(n as usize, &edges);
            let c0 = comp[0];
            if comp.iter().all(|&c| c == c0) {
                break;
            }
            let mut best = (f64::INFINITY, 0u32, 0u32);
            for a in 0..n {
                for b in 0..n {
                    if comp[a as usize] == c0 && comp[b as usize] != c0 {
                        let d = dist(&vertices, a, b);
                        if d < best.0 {
                            best = (d, a, b);
                        }
                    }
                }
            }
            edges.push(Edge { a: best.1, b: best.2, length: best.0 });
            flags.push(false);
        }
        let name = format!("seed004-like-{}v-{}re-s{}", 2 * r, r, seed);
        Instance::new(Some(name), vertices, edges, &flags, None).unwrap()
    }

    #[test]
    fn same_instances_as_scanning_every_pair() {
        for (r, seeds) in [(1, 0..6u64), (2, 0..6), (3, 0..6), (7, 0..6), (40, 0..6), (150, 0..2), (400, 0..1)] {
            for seed in seeds {
                assert_eq!(
                    tewolde_sheng_like(r, seed).unwrap(),
                    tewolde_sheng_like_by_scanning(r, seed),
                    "r {r} seed {seed}"
                );
            }
        }
    }

    #[test]
    fn sizes_are_bounded() {
        assert_eq!(tewolde_sheng_like(0, 1), Err(GenerateError::Empty));
        assert_eq!(tewolde_sheng_like(4_294_967_296, 1), Err(GenerateError::TooLarge(4_294_967_296)));
        assert_eq!(
            tewolde_sheng_like(MAX_GENERATED_REQUIRED + 1, 1),
            Err(GenerateError::TooLarge(MAX_GENERATED_REQUIRED + 1))
        );
        let i = tewolde_sheng_like(MAX_GENERATED_REQUIRED, 1).unwrap();
        assert_eq!(i.required().len(), MAX_GENERATED_REQUIRED);
    }
}
