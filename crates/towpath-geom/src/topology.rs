//! Topology reconstruction (seed 001 Algorithm 1 and Table 1): edges with their faces, the
//! neighbour of every face across each of its edges, consistent orientation, boundary loops.
//!
//! Edge `k` of a triangle `[v0, v1, v2]` runs from `v[k]` to `v[(k + 1) % 3]`.

/// Marker for "no face" (a boundary edge) in neighbour tables.
pub const NO_FACE: u32 = u32::MAX;

/// Edge records and face adjacency.
#[derive(Debug, Clone, Default)]
pub(crate) struct Topology {
    /// For each face and local edge, the face across it (or [`NO_FACE`]).
    pub neighbors: Vec<[u32; 3]>,
    /// Each undirected edge: its two vertices (smaller first) and up to two faces.
    pub edges: Vec<EdgeRec>,
    /// For each face, the global index of its three edges.
    pub face_edges: Vec<[u32; 3]>,
    /// Edges shared by more than two faces (left without neighbours, i.e. cut).
    pub non_manifold_edges: usize,
    /// Edges whose two faces disagree on orientation after orientation repair (cut as well).
    pub orientation_conflicts: usize,
}

/// An undirected edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeRec {
    /// End vertices, smaller index first.
    pub vertices: [u32; 2],
    /// Faces on the edge ([`NO_FACE`] where there is none; non-manifold edges keep the first two).
    pub faces: [u32; 2],
}

/// Half-edges grouped by undirected edge: (min vertex << 32 | max vertex, face · 3 + local edge),
/// sorted. Flipping a face (swapping its corners 1 and 2) keeps its undirected edges, so one
/// sorted list serves orientation and topology.
pub(crate) fn half_edges(tris: &[[u32; 3]]) -> Vec<(u64, u32)> {
    let mut half: Vec<(u64, u32)> = Vec::with_capacity(tris.len() * 3);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            half.push((((a.min(b) as u64) << 32) | a.max(b) as u64, (f as u32) * 3 + k as u32));
        }
    }
    rayon::slice::ParallelSliceMut::par_sort_unstable(&mut half[..]);
    half
}

/// Local edge index after a face flip ([v0, v1, v2] → [v0, v2, v1]): edge 0 ↔ edge 2.
#[inline]
fn flipped_edge(k: usize, flipped: bool) -> usize {
    if flipped {
        [2, 1, 0][k]
    } else {
        k
    }
}

/// Builds edges and neighbours of triangles that are already oriented as they should be, from
/// the half-edge list made before the faces in `flipped` were flipped.
pub(crate) fn build(tris: &[[u32; 3]], half_in: &[(u64, u32)], flipped: &[bool]) -> Topology {
    let half: Vec<(u32, u32, u32)> = half_in
        .iter()
        .map(|&(key, fk)| {
            let (f, k) = (fk / 3, (fk % 3) as usize);
            let k = flipped_edge(k, flipped.get(f as usize).copied().unwrap_or(false));
            ((key >> 32) as u32, key as u32, f * 3 + k as u32)
        })
        .collect();
    let mut topo = Topology {
        neighbors: vec![[NO_FACE; 3]; tris.len()],
        edges: Vec::with_capacity(tris.len() * 3 / 2 + 1),
        face_edges: vec![[0; 3]; tris.len()],
        ..Topology::default()
    };
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && half[j].0 == half[i].0 && half[j].1 == half[i].1 {
            j += 1;
        }
        let group = &half[i..j];
        let e = topo.edges.len() as u32;
        let mut rec = EdgeRec { vertices: [half[i].0, half[i].1], faces: [NO_FACE; 2] };
        for (slot, h) in group.iter().enumerate() {
            let (f, k) = ((h.2 / 3) as usize, (h.2 % 3) as usize);
            topo.face_edges[f][k] = e;
            if slot < 2 {
                rec.faces[slot] = f as u32;
            }
        }
        if group.len() == 2 {
            let (f0, k0) = ((group[0].2 / 3) as usize, (group[0].2 % 3) as usize);
            let (f1, k1) = ((group[1].2 / 3) as usize, (group[1].2 % 3) as usize);
            // Consistent orientation: the two faces run the edge in opposite directions.
            if tris[f0][k0] == tris[f1][(k1 + 1) % 3] {
                topo.neighbors[f0][k0] = f1 as u32;
                topo.neighbors[f1][k1] = f0 as u32;
            } else {
                topo.orientation_conflicts += 1;
            }
        } else if group.len() > 2 {
            topo.non_manifold_edges += 1;
        }
        topo.edges.push(rec);
        i = j;
    }
    topo
}

/// Makes orientation consistent within every edge-connected component (through manifold edges):
/// a breadth-first walk from the first face of each component flips every face that runs a
/// shared edge the same way as its already-visited neighbour. A component is then flipped as a
/// whole when the flipped faces outweigh the kept ones by area, so the input's majority
/// orientation is kept. Returns which faces were flipped.
pub(crate) fn orient(tris: &mut [[u32; 3]], areas: &[f64], half: &[(u64, u32)]) -> Vec<bool> {
    // Undirected adjacency through edges with exactly two faces.
    let mut adj_start = vec![0u32; tris.len() + 1];
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        let (fa, fb) = (half[i].1 / 3, half.get(i + 1).map_or(u32::MAX, |h| h.1 / 3));
        if j - i == 2 && fa != fb {
            pairs.push((fa, fb));
            pairs.push((fb, fa));
        }
        i = j;
    }
    rayon::slice::ParallelSliceMut::par_sort_unstable(&mut pairs[..]);
    for &(f, _) in &pairs {
        adj_start[f as usize + 1] += 1;
    }
    for f in 0..tris.len() {
        adj_start[f + 1] += adj_start[f];
    }
    let mut flip = vec![false; tris.len()];
    let mut seen = vec![false; tris.len()];
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..tris.len() {
        if seen[seed] {
            continue;
        }
        seen[seed] = true;
        queue.push_back(seed);
        let mut comp = Vec::new();
        while let Some(f) = queue.pop_front() {
            comp.push(f);
            for &(_, g) in &pairs[adj_start[f] as usize..adj_start[f + 1] as usize] {
                let g = g as usize;
                if seen[g] {
                    continue;
                }
                seen[g] = true;
                // Would f (as it will be oriented) and g (as given) run the shared edge the same way?
                let same = shares_same_direction(oriented(tris[f], flip[f]), tris[g]);
                flip[g] = same;
                queue.push_back(g);
            }
        }
        let (mut kept, mut flipped) = (0.0, 0.0);
        for &f in &comp {
            if flip[f] {
                flipped += areas[f];
            } else {
                kept += areas[f];
            }
        }
        if flipped > kept {
            for &f in &comp {
                flip[f] = !flip[f];
            }
        }
    }
    for (t, &fl) in tris.iter_mut().zip(&flip) {
        if fl {
            t.swap(1, 2);
        }
    }
    flip
}

fn oriented(t: [u32; 3], flip: bool) -> [u32; 3] {
    if flip {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

fn shares_same_direction(a: [u32; 3], b: [u32; 3]) -> bool {
    for k in 0..3 {
        for m in 0..3 {
            if a[k] == b[m] && a[(k + 1) % 3] == b[(m + 1) % 3] {
                return true;
            }
        }
    }
    false
}

/// Boundary loops: chains of boundary half-edges (edges without a neighbour), each closed where
/// possible, as vertex lists in the direction of the faces' orientation.
pub(crate) fn boundary_loops(tris: &[[u32; 3]], neighbors: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut out_edges: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
    let mut starts: Vec<u32> = Vec::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            if neighbors[f][k] == NO_FACE {
                out_edges.entry(t[k]).or_default().push(t[(k + 1) % 3]);
                starts.push(t[k]);
            }
        }
    }
    starts.sort_unstable();
    starts.dedup();
    let mut loops = Vec::new();
    for s in starts {
        while out_edges.get(&s).is_some_and(|v| !v.is_empty()) {
            let mut lp = vec![s];
            let mut cur = s;
            while let Some(next) = out_edges.get_mut(&cur).and_then(Vec::pop) {
                if next == s {
                    break;
                }
                lp.push(next);
                cur = next;
                if lp.len() > tris.len() * 3 {
                    break;
                }
            }
            loops.push(lp);
        }
    }
    loops
}
