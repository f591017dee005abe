//! The plain plane-slicer, for comparison: no partition, the whole part cut by parallel planes
//! one spacing apart, each cut (a polyline over the surface, split where the part is not) one
//! pass with the gun at the standoff along the smooth surface normal, run out straight past its
//! open ends. The planes contain the part's longest principal axis and its least one (for a
//! sheet, its normal), so passes run along the part.

use std::collections::HashMap;

use glam::DVec3;
use towpath_geom::Mesh;

use crate::passes::Geom;

/// Principal axes of a mesh's area (eigenvectors of the second-moment matrix of face centroids
/// weighted by area), largest variance first.
pub(crate) fn principal_axes(mesh: &Mesh) -> [DVec3; 3] {
    let mut c = DVec3::ZERO;
    let mut w = 0.0;
    for f in 0..mesh.num_faces() as u32 {
        let k = mesh.corners(f);
        let a = mesh.face_area(f);
        c += (k[0] + k[1] + k[2]) / 3.0 * a;
        w += a;
    }
    let c = if w > 0.0 { c / w } else { c };
    let mut m = [[0.0f64; 3]; 3];
    for f in 0..mesh.num_faces() as u32 {
        let k = mesh.corners(f);
        let a = mesh.face_area(f);
        for p in k {
            let d = (p - c).to_array();
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += a / 3.0 * d[i] * d[j];
                }
            }
        }
    }
    let (vals, vecs) = jacobi3(m);
    let mut idx = [0, 1, 2];
    idx.sort_by(|&a, &b| vals[b].total_cmp(&vals[a]));
    [vecs[idx[0]], vecs[idx[1]], vecs[idx[2]]]
}

/// Eigen-decomposition of a symmetric 3 × 3 matrix by Jacobi rotations.
fn jacobi3(mut a: [[f64; 3]; 3]) -> ([f64; 3], [DVec3; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off < 1e-15 * (a[0][0].abs() + a[1][1].abs() + a[2][2].abs()).max(1e-300) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vkp, vkq) = (row[p], row[q]);
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let vec = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]).normalize();
    ([a[0][0], a[1][1], a[2][2]], [vec(0), vec(1), vec(2)])
}

/// A point on a mesh edge: position and (unnormalised blend of) vertex normals.
#[derive(Clone, Copy)]
struct EdgePoint {
    p: DVec3,
    n: DVec3,
}

/// The slicer's passes: planes with normal `m` at `offsets`, poses at `standoff`, samples at most
/// `step` apart, run-outs of `overrun` at open ends.
pub(crate) fn slices(mesh: &Mesh, m: DVec3, offsets: &[f64], standoff: f64, step: f64, overrun: f64) -> Vec<Geom> {
    let x: Vec<f64> = mesh.positions().iter().map(|p| p.dot(m)).collect();
    let mut per_level: Vec<Vec<(u32, u32)>> = vec![Vec::new(); offsets.len()];
    for f in 0..mesh.num_faces() as u32 {
        let t = mesh.triangles()[f as usize];
        let xs = [x[t[0] as usize], x[t[1] as usize], x[t[2] as usize]];
        let (lo, hi) = (xs[0].min(xs[1]).min(xs[2]), xs[0].max(xs[1]).max(xs[2]));
        let k0 = offsets.partition_point(|&c| c < lo);
        let edges = mesh.face_edges(f);
        for (k, &c) in offsets.iter().enumerate().skip(k0) {
            if c > hi {
                break;
            }
            let mut crossed = [u32::MAX; 2];
            let mut n = 0;
            for e in 0..3 {
                let (a, b) = (xs[e] >= c, xs[(e + 1) % 3] >= c);
                if a != b && n < 2 {
                    crossed[n] = edges[e];
                    n += 1;
                }
            }
            if n == 2 {
                per_level[k].push((crossed[0], crossed[1]));
            }
        }
    }
    let edge_list: Vec<([u32; 2], [u32; 2])> = mesh.edges().collect();
    let mut out = Vec::new();
    for (k, segs) in per_level.iter().enumerate() {
        let c = offsets[k];
        let point = |e: u32| -> EdgePoint {
            let [a, b] = edge_list[e as usize].0;
            let (xa, xb) = (x[a as usize], x[b as usize]);
            let t = if xb != xa { ((c - xa) / (xb - xa)).clamp(0.0, 1.0) } else { 0.5 };
            let (pa, pb) = (mesh.positions()[a as usize], mesh.positions()[b as usize]);
            EdgePoint { p: pa.lerp(pb, t), n: mesh.vertex_normal(a).lerp(mesh.vertex_normal(b), t) }
        };
        for (chain, closed) in chain(segs) {
            let pts: Vec<EdgePoint> = chain.iter().map(|&e| point(e)).collect();
            let mut positions = Vec::new();
            let mut normals = Vec::new();
            for w in 0..pts.len().saturating_sub(1) {
                let (a, b) = (pts[w], pts[w + 1]);
                let n = ((a.p.distance(b.p) / step).ceil() as usize).max(1);
                for i in 0..n {
                    let s = i as f64 / n as f64;
                    positions.push(a.p.lerp(b.p, s));
                    normals.push(a.n.lerp(b.n, s).try_normalize().unwrap_or(m));
                }
            }
            if let Some(last) = pts.last() {
                positions.push(last.p);
                normals.push(last.n.try_normalize().unwrap_or(m));
            }
            if positions.len() < 2 {
                continue;
            }
            if !closed && overrun > 0.0 {
                let extend = |p: &[DVec3], nrm: DVec3, at_start: bool| -> Vec<(DVec3, DVec3)> {
                    let (end, inner) = if at_start { (p[0], p[1]) } else { (p[p.len() - 1], p[p.len() - 2]) };
                    let dir = (end - inner).try_normalize().unwrap_or(DVec3::X);
                    let n = ((overrun / step).ceil() as usize).max(1);
                    (1..=n).map(|i| (end + dir * overrun * i as f64 / n as f64, nrm)).collect()
                };
                let head = extend(&positions, normals[0], true);
                let tail = extend(&positions, normals[normals.len() - 1], false);
                let mut p2: Vec<DVec3> = head.iter().rev().map(|x| x.0).collect();
                let mut n2: Vec<DVec3> = head.iter().rev().map(|x| x.1).collect();
                p2.extend(positions);
                n2.extend(normals);
                p2.extend(tail.iter().map(|x| x.0));
                n2.extend(tail.iter().map(|x| x.1));
                positions = p2;
                normals = n2;
            }
            let geom = Geom {
                positions: positions.iter().zip(&normals).map(|(p, n)| *p + *n * standoff).collect(),
                axes: normals.iter().map(|n| -*n).collect(),
                targets: positions,
                closed,
            };
            out.push(geom);
        }
    }
    out
}

/// Chains segments (pairs of edge ids) into polylines of edge ids; closed ones flagged (their
/// first edge repeated at the end).
fn chain(segs: &[(u32, u32)]) -> Vec<(Vec<u32>, bool)> {
    let mut at: HashMap<u32, Vec<usize>> = HashMap::new();
    for (i, &(a, b)) in segs.iter().enumerate() {
        at.entry(a).or_default().push(i);
        at.entry(b).or_default().push(i);
    }
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    let mut ends: Vec<u32> = at.iter().filter(|(_, v)| v.len() == 1).map(|(&k, _)| k).collect();
    ends.sort_unstable();
    let mut all: Vec<u32> = at.keys().copied().collect();
    all.sort_unstable();
    for round in 0..2 {
        for &k0 in if round == 0 { &ends } else { &all } {
            let Some(&s0) = at[&k0].iter().find(|&&s| !used[s]) else { continue };
            let mut keys = vec![k0];
            let (mut s, mut k) = (s0, k0);
            loop {
                used[s] = true;
                let k2 = if segs[s].0 == k { segs[s].1 } else { segs[s].0 };
                keys.push(k2);
                k = k2;
                match at[&k].iter().find(|&&t| !used[t]) {
                    Some(&t) => s = t,
                    None => break,
                }
            }
            let closed = round == 1 && keys.first() == keys.last();
            out.push((keys, closed));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalises() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 1.0]];
        let (vals, vecs) = jacobi3(m);
        for j in 0..3 {
            let v = vecs[j].to_array();
            for i in 0..3 {
                let mv = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
                assert!((mv - vals[j] * v[i]).abs() < 1e-9);
            }
        }
    }
}
