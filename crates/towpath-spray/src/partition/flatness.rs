//! Flat patches by region growing under a maximum deviation angle (Tewolde & Sheng 2008 §III-A,
//! after Sheng et al. 2000): start from the largest unassigned triangle, pull in neighbouring
//! triangles while the patch stays flat, repeat until every triangle has a patch. Among
//! triangles of equal area (to a millionth: a regular tessellation) the one whose normal is
//! farthest from the set's mean normal goes first, so patches grow in from the edges of the
//! normal range and tile it like a greedy interval cover.
//!
//! Growth keeps a cone (axis, angular radius) around the normals taken in; a neighbour is taken
//! when the smallest cone holding the old cone and its normal has a radius of at most β_th (the
//! cone is widened towards the new normal, as in Ritter's bounding sphere, on the unit sphere),
//! nearest normals first. A cone bound is what lets a patch reach its full width whichever side
//! it grows from: testing the current mean normal instead stops a patch that grows from one side
//! a step short, because the mean lags behind the side still filling. When growth ends the
//! patch's real MDA (from its area-weighted mean normal) is checked; triangles beyond β_th are
//! peeled off (keeping the part joined to the seed) until it holds. Last, patches smaller than a
//! hundredth of the largest are merged into the neighbour that keeps the union flattest, when
//! the union still holds β_th.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use glam::DVec3;
use towpath_geom::{Mesh, NO_FACE};

use super::mean_normal;

#[derive(PartialEq)]
struct Cand(f64, u32);
impl Eq for Cand {}
impl PartialOrd for Cand {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cand {
    // Smallest angle first (BinaryHeap is a max-heap), then smallest face.
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

fn angle(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// Splits a face set into flat patches of MDA ≤ `beta` (radians). Patches are returned in the
/// order they were grown, faces ascending.
pub fn grow(mesh: &Mesh, faces: &[u32], beta: f64) -> Vec<Vec<u32>> {
    let mut local: HashMap<u32, u32> = HashMap::with_capacity(faces.len());
    for (i, &f) in faces.iter().enumerate() {
        local.insert(f, i as u32);
    }
    let n = faces.len();
    let mut owner = vec![u32::MAX; n];
    // Seeds: largest area first; areas equal to a millionth (a regular tessellation) are
    // taken by the deviation of their normal from the whole set's mean normal, largest first,
    // so that patches grow in from the edges of the normal range and tile it without leaving
    // slivers between them.
    let (whole, _) = mean_normal(mesh, faces);
    let amax = faces.iter().map(|&f| mesh.face_area(f)).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let key: Vec<(i64, f64)> = faces
        .iter()
        .map(|&f| ((mesh.face_area(f) / amax * 1e6).round() as i64, angle(whole, mesh.face_normal(f))))
        .collect();
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key[a as usize], key[b as usize]);
        kb.0.cmp(&ka.0).then(kb.1.total_cmp(&ka.1)).then(faces[a as usize].cmp(&faces[b as usize]))
    });
    let mut patches: Vec<Vec<u32>> = Vec::new();
    let mut tried = vec![u32::MAX; n];
    let mut heap = BinaryHeap::new();
    for &seed in &order {
        if owner[seed as usize] != u32::MAX {
            continue;
        }
        let pid = patches.len() as u32;
        let mut members = vec![seed];
        owner[seed as usize] = pid;
        let mut axis = mesh.face_normal(faces[seed as usize]);
        let mut radius = 0.0f64;
        heap.clear();
        let push = |f: u32, axis: DVec3, heap: &mut BinaryHeap<Cand>, tried: &mut Vec<u32>, owner: &Vec<u32>| {
            let gf = faces[f as usize];
            for k in 0..3 {
                let g = mesh.neighbor(gf, k);
                if g == NO_FACE {
                    continue;
                }
                if let Some(&gl) = local.get(&g) {
                    if owner[gl as usize] == u32::MAX && tried[gl as usize] != pid {
                        tried[gl as usize] = pid;
                        heap.push(Cand(angle(axis, mesh.face_normal(g)), gl));
                    }
                }
            }
        };
        push(seed, axis, &mut heap, &mut tried, &owner);
        while let Some(Cand(_, c)) = heap.pop() {
            if owner[c as usize] != u32::MAX {
                continue;
            }
            let nc = mesh.face_normal(faces[c as usize]);
            let th = angle(axis, nc);
            if th > radius {
                let r2 = 0.5 * (radius + th);
                if r2 > beta {
                    continue;
                }
                // Rotate the axis towards nc by (th - radius)/2 on the great circle.
                let t = (th - radius) * 0.5;
                let perp = (nc - axis * axis.dot(nc)).try_normalize();
                if let Some(p) = perp {
                    axis = (axis * t.cos() + p * t.sin()).normalize();
                }
                radius = r2;
            }
            owner[c as usize] = pid;
            members.push(c);
            push(c, axis, &mut heap, &mut tried, &owner);
        }
        // The real MDA from the area-weighted mean; peel until it holds.
        for _ in 0..64 {
            let gl: Vec<u32> = members.iter().map(|&m| faces[m as usize]).collect();
            let (m, _) = mean_normal(mesh, &gl);
            let keep: Vec<u32> =
                members.iter().copied().filter(|&x| angle(m, mesh.face_normal(faces[x as usize])) <= beta).collect();
            if keep.len() == members.len() {
                break;
            }
            for &x in &members {
                owner[x as usize] = u32::MAX;
            }
            // Keep the part of `keep` joined to the seed (or its largest part if the seed went).
            let parts = joined_parts(mesh, faces, &local, &keep);
            let best = parts
                .iter()
                .position(|p| p.contains(&seed))
                .unwrap_or_else(|| (0..parts.len()).max_by_key(|&i| parts[i].len()).unwrap_or(0));
            members = parts.into_iter().nth(best).unwrap_or_default();
            if members.is_empty() {
                members = vec![seed];
            }
            for &x in &members {
                owner[x as usize] = pid;
            }
        }
        patches.push(members);
    }
    merge_small(mesh, faces, &local, &mut owner, &mut patches, beta);
    patches
        .into_iter()
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut g: Vec<u32> = p.iter().map(|&x| faces[x as usize]).collect();
            g.sort_unstable();
            g
        })
        .collect()
}

/// Connected parts of a subset (local indices) of `faces`.
fn joined_parts(mesh: &Mesh, faces: &[u32], local: &HashMap<u32, u32>, subset: &[u32]) -> Vec<Vec<u32>> {
    let inset: std::collections::HashSet<u32> = subset.iter().copied().collect();
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for &s in subset {
        if !seen.insert(s) {
            continue;
        }
        let mut stack = vec![s];
        let mut part = Vec::new();
        while let Some(x) = stack.pop() {
            part.push(x);
            for k in 0..3 {
                let g = mesh.neighbor(faces[x as usize], k);
                if g == NO_FACE {
                    continue;
                }
                if let Some(&gl) = local.get(&g) {
                    if inset.contains(&gl) && seen.insert(gl) {
                        stack.push(gl);
                    }
                }
            }
        }
        out.push(part);
    }
    out
}

/// Merges patches of less than 1 % of the largest patch's area into the neighbour that gives
/// the flattest union, when that union's MDA is within `beta`.
fn merge_small(
    mesh: &Mesh,
    faces: &[u32],
    local: &HashMap<u32, u32>,
    owner: &mut [u32],
    patches: &mut [Vec<u32>],
    beta: f64,
) {
    let area = |p: &Vec<u32>| p.iter().map(|&x| mesh.face_area(faces[x as usize])).sum::<f64>();
    let largest = patches.iter().map(area).fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..patches.len()).collect();
    order.sort_by(|&a, &b| area(&patches[a]).total_cmp(&area(&patches[b])).then(a.cmp(&b)));
    for i in order {
        if patches[i].is_empty() || area(&patches[i]) >= 0.01 * largest {
            continue;
        }
        let mut nbs: Vec<u32> = Vec::new();
        for &x in &patches[i] {
            for k in 0..3 {
                let g = mesh.neighbor(faces[x as usize], k);
                if g == NO_FACE {
                    continue;
                }
                if let Some(&gl) = local.get(&g) {
                    let o = owner[gl as usize];
                    if o != i as u32 && o != u32::MAX && !nbs.contains(&o) {
                        nbs.push(o);
                    }
                }
            }
        }
        nbs.sort_unstable();
        let mut best: Option<(f64, u32)> = None;
        for &j in &nbs {
            let union: Vec<u32> = patches[i].iter().chain(&patches[j as usize]).map(|&x| faces[x as usize]).collect();
            let (m, _) = mean_normal(mesh, &union);
            let mda = union.iter().map(|&f| angle(m, mesh.face_normal(f))).fold(0.0, f64::max);
            if mda <= beta && best.is_none_or(|b| mda < b.0) {
                best = Some((mda, j));
            }
        }
        if let Some((_, j)) = best {
            let moved = std::mem::take(&mut patches[i]);
            for &x in &moved {
                owner[x as usize] = j;
            }
            patches[j as usize].extend(moved);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
    use towpath_geom::BuildOptions;

    fn mesh_of(desc: &str, tris: usize) -> Mesh {
        let s = tessellate_analytic(&Analytic::parse(desc).unwrap(), &Tessellation::Triangles(tris)).unwrap();
        Mesh::build(&s, &BuildOptions::default()).unwrap().0
    }

    #[test]
    fn patches_cover_every_face_once_and_keep_the_bound() {
        let m = mesh_of("sphere:r=300,lat0=0,lat1=80", 6000);
        let all: Vec<u32> = (0..m.num_faces() as u32).collect();
        let beta = 15f64.to_radians();
        let patches = grow(&m, &all, beta);
        let mut seen = vec![0; m.num_faces()];
        for p in &patches {
            for &f in p {
                seen[f as usize] += 1;
            }
            let (n, _) = mean_normal(&m, p);
            let mda = p.iter().map(|&f| angle(n, m.face_normal(f))).fold(0.0, f64::max);
            assert!(mda <= beta + 1e-12, "{mda}");
        }
        assert!(seen.iter().all(|&c| c == 1));
    }
}
