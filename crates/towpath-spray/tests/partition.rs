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
