//! Surface partition (Tewolde & Sheng 2008 §III-A): topology first, then flatness.
//!
//! 1. **Pieces.** Each edge-connected component of the mesh is a piece. A piece is *projectable*
//!    when its area-weighted mean normal N is well defined (|Σ A n| ≥ 0.3 Σ A) and every
//!    triangle faces it (n·N > 0.1): then its projection on the plane normal to N (the plane of
//!    maximum projected area) shows its topology. Closed surfaces (a box, a tube) and surfaces
//!    whose normals cancel out are not projectable; they are first split by normal direction
//!    with the flatness growth below (every flat patch is projectable) instead of refused.
//! 2. **Topology** ([`topology`]): each projectable piece is split into hole-free, nearly convex
//!    cells by cuts through its reflex critical points, choosing among sweep directions by a
//!    weighted cost of turns, common border length and corners.
//! 3. **Flatness** ([`flatness`]): every cell is grown into flat patches, starting from the
//!    largest unassigned triangle and pulling in neighbours while the maximum deviation angle
//!    (MDA) of the patch's normals from its mean normal stays within β_th.
//!
//! The result is the flat-patch adjacency graph: patches with their area, mean normal, MDA,
//! border length and neighbours (shared border length and the crease angle across it).

pub mod flatness;
pub mod topology;

use glam::DVec3;
use serde::Serialize;
use towpath_geom::{Mesh, NO_FACE};

/// How to partition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartitionOptions {
    /// β_th: the largest deviation (degrees) of a triangle normal from its patch's mean normal.
    pub max_deviation_deg: f64,
    /// Split pieces into hole-free, nearly convex cells before the flatness growth.
    pub topology: bool,
    /// Length scale of the spray (the footprint radius): cells and corners smaller than this
    /// are not worth a split.
    pub scale: f64,
}

impl Default for PartitionOptions {
    fn default() -> Self {
        PartitionOptions { max_deviation_deg: 20.0, topology: true, scale: 50.0 }
    }
}

/// A neighbour of a patch in the adjacency graph.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Neighbor {
    /// The neighbouring patch.
    pub patch: u32,
    /// Length of the common border (mm).
    pub border: f64,
    /// Mean angle (degrees) between the face normals on either side of the common border.
    pub crease_deg: f64,
}

/// A flat patch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Patch {
    /// Index in [`Partition::patches`].
    pub id: u32,
    /// Its faces.
    #[serde(skip)]
    pub faces: Vec<u32>,
    /// Number of triangles.
    pub triangles: usize,
    /// Area (mm²).
    pub area: f64,
    /// Area-weighted mean normal (unit).
    pub normal: DVec3,
    /// Maximum deviation angle of a face normal from `normal` (degrees).
    pub mda_deg: f64,
    /// Total length of the patch's border (mm).
    pub border_length: f64,
    /// Length of its border on the mesh's own boundary (mm).
    pub free_border: f64,
    /// Neighbouring patches.
    pub neighbors: Vec<Neighbor>,
    /// The topology cell the patch came from.
    pub cell: u32,
}

/// The partition of a mesh into flat patches.
#[derive(Debug, Clone, PartialEq)]
pub struct Partition {
    /// The patches.
    pub patches: Vec<Patch>,
    /// The patch of every face.
    pub patch_of: Vec<u32>,
    /// Connected pieces of the mesh.
    pub pieces: usize,
    /// Pieces that were not projectable and were split by normal direction first.
    pub presplit_pieces: usize,
    /// Topology cells (before the flatness growth).
    pub cells: usize,
}

/// Partitions a mesh (see the module docs).
pub fn partition(mesh: &Mesh, opts: &PartitionOptions) -> Partition {
    let beta = opts.max_deviation_deg.to_radians();
    let nf = mesh.num_faces();
    let all: Vec<u32> = (0..nf as u32).collect();
    let pieces = components(mesh, &all, &|_, _| true);
    let mut cells: Vec<Vec<u32>> = Vec::new();
    let mut presplit = 0;
    for piece in &pieces {
        let parts = if projectable(mesh, piece) {
            vec![piece.clone()]
        } else {
            presplit += 1;
            flatness::grow(mesh, piece, beta)
        };
        for part in parts {
            if opts.topology {
                cells.extend(topology::split(mesh, &part, opts.scale));
            } else {
                cells.push(part);
            }
        }
    }
    let mut patch_faces: Vec<(Vec<u32>, u32)> = Vec::new();
    for (ci, cell) in cells.iter().enumerate() {
        for p in flatness::grow(mesh, cell, beta) {
            patch_faces.push((p, ci as u32));
        }
    }
    build(mesh, patch_faces, pieces.len(), presplit, cells.len())
}

/// The partition made of given face sets (each one patch).
pub(crate) fn build(
    mesh: &Mesh,
    patch_faces: Vec<(Vec<u32>, u32)>,
    pieces: usize,
    presplit: usize,
    cells: usize,
) -> Partition {
    let nf = mesh.num_faces();
    let mut patch_of = vec![u32::MAX; nf];
    for (i, (faces, _)) in patch_faces.iter().enumerate() {
        for &f in faces {
            patch_of[f as usize] = i as u32;
        }
    }
    let mut patches = Vec::with_capacity(patch_faces.len());
    for (i, (faces, cell)) in patch_faces.into_iter().enumerate() {
        let (normal, area) = mean_normal(mesh, &faces);
        let mda = faces
            .iter()
            .map(|&f| mesh.face_normal(f).dot(normal).clamp(-1.0, 1.0).acos())
            .fold(0.0f64, f64::max)
            .to_degrees();
        let mut border = 0.0;
        let mut free = 0.0;
        let mut nb: Vec<(u32, f64, f64)> = Vec::new();
        for &f in &faces {
            let c = mesh.corners(f);
            for k in 0..3 {
                let g = mesh.neighbor(f, k);
                if g != NO_FACE && patch_of[g as usize] == i as u32 {
                    continue;
                }
                let len = c[k].distance(c[(k + 1) % 3]);
                border += len;
                if g == NO_FACE {
                    free += len;
                    continue;
                }
                let q = patch_of[g as usize];
                let ang = mesh.face_normal(f).dot(mesh.face_normal(g)).clamp(-1.0, 1.0).acos().to_degrees();
                match nb.iter_mut().find(|e| e.0 == q) {
                    Some(e) => {
                        e.1 += len;
                        e.2 += len * ang;
                    }
                    None => nb.push((q, len, len * ang)),
                }
            }
        }
        nb.sort_by_key(|e| e.0);
        let neighbors = nb
            .into_iter()
            .map(|(patch, b, a)| Neighbor { patch, border: b, crease_deg: if b > 0.0 { a / b } else { 0.0 } })
            .collect();
        patches.push(Patch {
            id: i as u32,
            triangles: faces.len(),
            faces,
            area,
            normal,
            mda_deg: mda,
            border_length: border,
            free_border: free,
            neighbors,
            cell,
        });
    }
    Partition { patches, patch_of, pieces, presplit_pieces: presplit, cells }
}

/// Area-weighted mean normal (unit; +z if the normals cancel) and area of a face set.
pub(crate) fn mean_normal(mesh: &Mesh, faces: &[u32]) -> (DVec3, f64) {
    let mut s = DVec3::ZERO;
    let mut area = 0.0;
    for &f in faces {
        s += mesh.face_normal(f) * mesh.face_area(f);
        area += mesh.face_area(f);
    }
    (s.try_normalize().unwrap_or(DVec3::Z), area)
}

/// Whether a face set can be studied in projection on the plane of its mean normal.
pub(crate) fn projectable(mesh: &Mesh, faces: &[u32]) -> bool {
    let mut s = DVec3::ZERO;
    let mut area = 0.0;
    for &f in faces {
        s += mesh.face_normal(f) * mesh.face_area(f);
        area += mesh.face_area(f);
    }
    if !(s.length() >= 0.3 * area) {
        return false;
    }
    let n = s.normalize();
    faces.iter().all(|&f| mesh.face_normal(f).dot(n) > 0.1)
}

/// Connected components of a face set through shared edges, where `joined(f, g)` allows the
/// step from f to its neighbour g. Components are listed by their smallest face; faces in
/// ascending order.
pub(crate) fn components(mesh: &Mesh, faces: &[u32], joined: &dyn Fn(u32, u32) -> bool) -> Vec<Vec<u32>> {
    let mut member = std::collections::HashMap::with_capacity(faces.len());
    for (i, &f) in faces.iter().enumerate() {
        member.insert(f, i);
    }
    let mut seen = vec![false; faces.len()];
    let mut out = Vec::new();
    let mut order: Vec<u32> = faces.to_vec();
    order.sort_unstable();
    let mut stack = Vec::new();
    for &s in &order {
        let si = member[&s];
        if seen[si] {
            continue;
        }
        seen[si] = true;
        stack.push(s);
        let mut comp = Vec::new();
        while let Some(f) = stack.pop() {
            comp.push(f);
            for k in 0..3 {
                let g = mesh.neighbor(f, k);
                if g == NO_FACE {
                    continue;
                }
                if let Some(&gi) = member.get(&g) {
                    if !seen[gi] && joined(f, g) {
                        seen[gi] = true;
                        stack.push(g);
                    }
                }
            }
        }
        comp.sort_unstable();
        out.push(comp);
    }
    out
}
