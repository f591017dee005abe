//! The partition: a box is six patches, a cylinder as many as its β_th implies, patches are flat
//! and cover every triangle once.

mod common;

use common::*;
use glam::DVec3;
use towpath_spray::{partition, PartitionOptions};

fn opts(beta: f64) -> PartitionOptions {
    PartitionOptions { max_deviation_deg: beta, topology: true, scale: 50.0 }
}

#[test]
fn a_box_is_six_patches() {
    let mesh = box_mesh(400.0, 300.0, 200.0, 6);
    let p = partition(&mesh, &opts(20.0));
    assert_eq!(p.patches.len(), 6);
    assert_eq!(p.presplit_pieces, 1, "a closed box is not projectable: split by normals first");
    let mut normals: Vec<DVec3> = p.patches.iter().map(|q| q.normal).collect();
    for axis in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z] {
        let k = normals.iter().position(|n| n.distance(axis) < 1e-9).expect("one patch per face");
        normals.remove(k);
    }
    for q in &p.patches {
        assert!(q.mda_deg < 1e-6);
        assert_eq!(q.triangles, 72);
        // Four neighbours across 90° creases.
        assert_eq!(q.neighbors.len(), 4);
        assert!(q.neighbors.iter().all(|n| (n.crease_deg - 90.0).abs() < 1e-6));
    }
}

#[test]
fn a_cylinder_section_gives_the_patch_count_its_threshold_implies() {
    // A 120° section, r = 300: facets in columns of equal normal. A patch can hold normals
    // spanning 2 β_th, i.e. k = ⌊2 β_th / w⌋ + 1 columns of angular width w; the section needs
    // ⌈columns / k⌉ patches, which for fine facets is ⌈120° / (2 β_th)⌉.
    let mesh = analytic("cylinder:r=300,l=500,a0=0,a1=120", 20000);
    // Columns: distinct facet directions around the axis.
    let mut angles: Vec<f64> = (0..mesh.num_faces() as u32)
        .map(|f| {
            let n = mesh.face_normal(f);
            n.y.atan2(n.x).to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let columns = angles.len();
    let w = 120.0 / columns as f64;
    // (β_th chosen so that 2 β_th / w is not a whole number: no ties at the limit.)
    for beta in [10.0, 14.0, 25.0, 35.0] {
        let p = partition(&mesh, &opts(beta));
        let k = (2.0 * beta / w).floor() as usize + 1;
        let expected = columns.div_ceil(k);
        assert_eq!(p.patches.len(), expected, "β_th {beta}: {columns} columns of {w}°, {k} per patch");
        assert_eq!(expected, (120.0 / (2.0 * beta)).ceil() as usize);
        for q in &p.patches {
            assert!(q.mda_deg <= beta + 1e-9);
        }
    }
}

#[test]
fn patches_cover_every_triangle_once_with_symmetric_neighbours() {
    let mesh = analytic("sphere:r=400,lat0=20,lat1=90", 8000);
    let p = partition(&mesh, &opts(12.0));
    let mut count = vec![0; mesh.num_faces()];
    for q in &p.patches {
        for &f in &q.faces {
            count[f as usize] += 1;
            assert_eq!(p.patch_of[f as usize], q.id);
        }
        assert!(q.mda_deg <= 12.0 + 1e-9);
        for n in &q.neighbors {
            let back = p.patches[n.patch as usize].neighbors.iter().find(|m| m.patch == q.id).expect("symmetric");
            assert!((back.border - n.border).abs() < 1e-6);
        }
    }
    assert!(count.iter().all(|&c| c == 1));
}

/// Number of boundary loops of a face set (mesh boundary or other patches).
fn loops_of(mesh: &towpath_geom::Mesh, faces: &[u32]) -> usize {
    let set: std::collections::HashSet<u32> = faces.iter().copied().collect();
    let mut next: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for &f in faces {
        let t = mesh.triangles()[f as usize];
        for k in 0..3 {
            let g = mesh.neighbor(f, k);
            if g == towpath_geom::NO_FACE || !set.contains(&g) {
                assert!(next.insert(t[k], t[(k + 1) % 3]).is_none(), "a pinched border");
            }
        }
    }
    let mut seen = std::collections::HashSet::new();
    let mut loops = 0;
    let mut keys: Vec<u32> = next.keys().copied().collect();
    keys.sort_unstable();
    for s in keys {
        if seen.contains(&s) {
            continue;
        }
        loops += 1;
        let mut v = s;
        while seen.insert(v) {
            v = next[&v];
        }
    }
    loops
}

#[test]
fn a_plate_with_a_hole_is_split_into_hole_free_cells() {
    let mesh = plate_with_hole(600.0, 400.0, [200.0, 400.0, 100.0, 300.0], 10.0);
    assert_eq!(loops_of(&mesh, &(0..mesh.num_faces() as u32).collect::<Vec<_>>()), 2);
    let p = partition(&mesh, &opts(20.0));
    assert!(p.patches.len() >= 2, "a hole needs at least two cells");
    assert_eq!(p.cells, p.patches.len(), "flat cells stay whole");
    let mut count = vec![0; mesh.num_faces()];
    for q in &p.patches {
        assert_eq!(loops_of(&mesh, &q.faces), 1, "patch {} has a hole", q.id);
        for &f in &q.faces {
            count[f as usize] += 1;
        }
    }
    assert!(count.iter().all(|&c| c == 1));
    // Without the topology split the plate is one (holed) patch.
    let one = partition(&mesh, &PartitionOptions { topology: false, ..opts(20.0) });
    assert_eq!(one.patches.len(), 1);
}

#[test]
fn a_notched_plate_is_split_and_a_convex_one_is_not() {
    // An L shape (a 300 × 300 plate without its 150 × 150 top-right quarter) has a reflex
    // corner; a rectangle has none.
    let l = plate_with_hole(300.0, 300.0, [150.0, 301.0, 150.0, 301.0], 10.0);
    assert_eq!(partition(&l, &opts(20.0)).cells, 2);
    let r = analytic("plane:a=300,b=200", 500);
    assert_eq!(partition(&r, &opts(20.0)).cells, 1);
}

#[test]
fn a_closed_tube_is_split_not_refused() {
    // A full tube: its normals cancel out, so it is not projectable; it is split by normal
    // direction first. Around the ring, columns of facets can be grouped k to a patch, so the
    // count is ⌈columns / k⌉ or one more where the last group wraps round to the first.
    let mesh = analytic("cylinder:r=300,l=500", 20000);
    let mut angles: Vec<f64> = (0..mesh.num_faces() as u32)
        .map(|f| {
            let n = mesh.face_normal(f);
            n.y.atan2(n.x).to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let columns = angles.len();
    let w = 360.0 / columns as f64;
    let beta = 25.0;
    let p = partition(&mesh, &opts(beta));
    assert_eq!(p.pieces, 1);
    assert_eq!(p.presplit_pieces, 1, "a tube is not projectable");
    let k = (2.0 * beta / w).floor() as usize + 1;
    let n = p.patches.len();
    assert!(n == columns.div_ceil(k) || n == columns.div_ceil(k) + 1, "{n} patches, {columns} columns, {k} per patch");
    for q in &p.patches {
        assert!(q.mda_deg <= beta + 1e-9);
        assert_eq!(loops_of(&mesh, &q.faces), 1, "patch {} is not a simple strip", q.id);
    }
}
