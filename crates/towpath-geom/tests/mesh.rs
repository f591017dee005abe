//! Welding, repair, topology, normals, closest points and file round trips.

use glam::DVec3;
use proptest::prelude::*;
use towpath_geom::io::{self, Format};
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh, MeshError, Soup, NO_FACE};

/// A grid of (nx × ny) unit squares, two triangles each, as an unwelded STL-like soup, over
/// x in [x0, x0 + nx], y in [0, ny]; `jitter` moves vertices on x = x0 by that much in z.
fn plate_soup(x0: f64, nx: usize, ny: usize, jitter: f64) -> Soup {
    let p = |i: usize, j: usize| {
        let x = x0 + i as f64;
        DVec3::new(x, j as f64, if i == 0 { jitter } else { 0.0 })
    };
    let mut tris = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    Soup::from_triangles(tris)
}

fn build(soup: &Soup) -> (Mesh, towpath_geom::RepairReport) {
    Mesh::build(soup, &BuildOptions::default()).expect("mesh")
}

fn euler(m: &Mesh) -> i64 {
    m.positions().len() as i64 - m.num_edges() as i64 + m.num_faces() as i64
}

fn check_neighbours_symmetric(m: &Mesh) {
    for f in 0..m.num_faces() as u32 {
        for k in 0..3 {
            let g = m.neighbor(f, k);
            if g != NO_FACE {
                assert!((0..3).any(|j| m.neighbor(g, j) == f), "face {f} -> {g} not mutual");
            }
        }
    }
}

#[test]
fn two_patches_weld_across_their_seam() {
    // Patch A over x in [0, 4], patch B over [4, 8]; B's seam vertices are off by 1e-9.
    let mut soup = plate_soup(0.0, 4, 3, 0.0);
    let b = plate_soup(4.0, 4, 3, 1e-9);
    let base = soup.positions.len() as u32;
    soup.positions.extend(b.positions);
    soup.triangles.extend(b.triangles.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    let (m, rep) = build(&soup);
    assert_eq!(rep.vertices_in, 2 * 4 * 3 * 2 * 3);
    assert_eq!(m.positions().len(), 9 * 4, "one vertex per grid point after welding");
    assert_eq!(m.boundary_loops().len(), 1, "the seam is interior");
    assert_eq!(m.boundary_loops()[0].len(), 2 * (8 + 3));
    assert_eq!(euler(&m), 1, "a disk");
    check_neighbours_symmetric(&m);
}

#[test]
fn a_hole_makes_a_second_boundary_loop() {
    // 5 × 5 plate without its middle square.
    let full = plate_soup(0.0, 5, 5, 0.0);
    let mut soup = Soup { positions: full.positions.clone(), triangles: Vec::new() };
    for (k, t) in full.triangles.iter().enumerate() {
        let (i, j) = ((k / 2) / 5, (k / 2) % 5);
        if !(i == 2 && j == 2) {
            soup.triangles.push(*t);
        }
    }
    let (m, _) = build(&soup);
    let mut lens: Vec<usize> = m.boundary_loops().iter().map(Vec::len).collect();
    lens.sort_unstable();
    assert_eq!(lens, vec![4, 20]);
    assert_eq!(euler(&m), 0, "an annulus");
    assert!((m.area() - 24.0).abs() < 1e-12);
}

#[test]
fn degenerate_duplicate_and_flipped_triangles_are_repaired_and_reported() {
    let mut soup = plate_soup(0.0, 3, 3, 0.0);
    // A duplicate, a zero-area sliver, and a flipped copy orientation for one face.
    let t0 = soup.triangles[0];
    soup.triangles.push(t0);
    let i = soup.positions.len() as u32;
    soup.positions.extend([DVec3::ZERO, DVec3::X, DVec3::X * 2.0]);
    soup.triangles.push([i, i + 1, i + 2]);
    soup.triangles[5].swap(1, 2);
    let (m, rep) = build(&soup);
    assert_eq!(rep.duplicates_removed, 1);
    assert_eq!(rep.degenerate_removed, 1);
    assert_eq!(rep.flipped, 1);
    assert_eq!(m.num_faces(), 18);
    for f in 0..m.num_faces() as u32 {
        assert!((m.face_normal(f) - DVec3::Z).length() < 1e-12, "all faces oriented alike");
    }
}

#[test]
fn non_manifold_edges_are_cut_not_a_panic() {
    // Three triangles on one edge (a "book" with three pages).
    let soup = Soup::from_triangles([
        [DVec3::ZERO, DVec3::X, DVec3::Y],
        [DVec3::X, DVec3::ZERO, DVec3::new(0.0, -1.0, 0.0)],
        [DVec3::ZERO, DVec3::X, DVec3::Z],
    ]);
    let (m, rep) = build(&soup);
    assert_eq!(rep.non_manifold_edges, 1);
    for f in 0..3 {
        for k in 0..3 {
            assert_eq!(m.neighbor(f, k), NO_FACE);
        }
    }
}

#[test]
fn a_moebius_strip_is_reported_as_non_orientable() {
    let n = 24;
    let mut tris = Vec::new();
    let at = |i: usize, s: f64| {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        let (c, sn) = (t.cos(), t.sin());
        let (hc, hs) = ((t / 2.0).cos(), (t / 2.0).sin());
        DVec3::new((3.0 + s * hc) * c, (3.0 + s * hc) * sn, s * hs)
    };
    for i in 0..n {
        let (a0, a1) = (at(i, -1.0), at(i, 1.0));
        let (b0, b1) = if i + 1 == n { (at(0, 1.0), at(0, -1.0)) } else { (at(i + 1, -1.0), at(i + 1, 1.0)) };
        tris.push([a0, b0, b1]);
        tris.push([a0, b1, a1]);
    }
    let (m, rep) = build(&Soup::from_triangles(tris));
    assert!(rep.orientation_conflicts >= 1, "{rep:?}");
    check_neighbours_symmetric(&m);
}

#[test]
fn bad_input_is_refused_with_a_reason() {
    let soup = Soup { positions: vec![DVec3::ZERO, DVec3::X], triangles: vec![[0, 1, 2]] };
    assert!(matches!(Mesh::build(&soup, &BuildOptions::default()), Err(MeshError::BadIndex { vertex: 2, .. })));
    let soup =
        Soup { positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)], triangles: vec![[0, 1, 2]] };
    assert!(matches!(Mesh::build(&soup, &BuildOptions::default()), Err(MeshError::NonFinite { index: 2 })));
    let soup = Soup::from_triangles([[DVec3::ZERO, DVec3::X, DVec3::X * 2.0]]);
    assert!(matches!(Mesh::build(&soup, &BuildOptions::default()), Err(MeshError::Empty { .. })));
}

#[test]
fn vertex_normals_of_an_inscribed_sphere_are_radial() {
    let s = Analytic::parse("sphere:r=100").unwrap();
    let (m, _) = build(&tessellate_analytic(&s, &Tessellation::Triangles(5000)).unwrap());
    let worst = (0..m.positions().len() as u32)
        .map(|v| m.vertex_normal(v).angle_between(m.positions()[v as usize].normalize()))
        .fold(0.0f64, f64::max);
    assert!(worst.to_degrees() < 0.5, "{}", worst.to_degrees());
}

#[test]
fn real_aircraft_mesh_welds_into_a_consistent_surface() {
    let bytes = include_bytes!("data/swept_wing_and_tail.stl");
    let soup = io::read_bytes(bytes, Format::Stl).unwrap();
    assert_eq!(soup.triangles.len(), 11_040);
    let (m, rep) = build(&soup);
    // Unwelded STL: every vertex is shared by several triangles once welded.
    assert!(m.positions().len() * 4 < rep.vertices_in, "{rep:?}");
    check_neighbours_symmetric(&m);
    // Each interior edge has two faces, each boundary loop is closed on boundary edges.
    let boundary_edges: usize = m.edges().filter(|(_, f)| f[1] == NO_FACE).count();
    let loop_len: usize = m.boundary_loops().iter().map(Vec::len).sum();
    assert_eq!(boundary_edges, loop_len);
    assert!((m.area() - soup.area()).abs() / soup.area() < 1e-6);
}

#[test]
fn readers_round_trip_through_writers() {
    let cyl = Analytic::parse("cylinder:r=30,l=100,a0=0,a1=90").unwrap();
    let soup = tessellate_analytic(&cyl, &Tessellation::Triangles(400)).unwrap();
    for format in [Format::Obj, Format::Ply, Format::Stl] {
        let mut bytes = Vec::new();
        match format {
            Format::Stl => io::write_stl(&mut bytes, &soup),
            Format::Obj => io::write_obj(&mut bytes, &soup),
            Format::Ply => io::write_ply(&mut bytes, &soup),
        }
        .unwrap();
        let back = io::read_bytes(&bytes, format).unwrap();
        let (a, _) = build(&soup);
        let (b, _) = build(&back);
        assert_eq!(a.num_faces(), b.num_faces(), "{format:?}");
        assert_eq!(a.positions().len(), b.positions().len(), "{format:?}");
        let tol = if format == Format::Stl { 1e-5 } else { 0.0 };
        for (p, q) in a.positions().iter().zip(b.positions()) {
            assert!(p.distance(*q) <= tol * 100.0, "{format:?}: {p} vs {q}");
        }
    }
    // Ascii STL through stl_io.
    let ascii = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n";
    assert_eq!(io::read_bytes(ascii, Format::Stl).unwrap().triangles.len(), 1);
}

#[test]
fn obj_polygons_are_fanned_and_bad_indices_refused() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let s = io::read_bytes(obj, Format::Obj).unwrap();
    assert_eq!(s.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert!(io::read_bytes(b"v 0 0 0\nf 1 2 3\n", Format::Obj).is_err());
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n";
    let e = io::read_bytes(ply, Format::Ply).unwrap_err().to_string();
    assert!(e.contains("out of range"), "{e}");
    // Found by fuzzing: a header number too long for u64 made the PLY grammar panic.
    let crash = b"ply\nformat ascii 9999999999999999999999999999999999999990.0\nelement vertex 1\nproperty float x\nend_header\n0\n";
    assert!(io::read_bytes(crash, Format::Ply).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
    /// The indexed closest point equals a brute-force scan.
    #[test]
    fn closest_point_matches_a_scan(x in -400.0f64..400.0, y in -400.0f64..400.0, z in -100.0f64..1100.0) {
        let cyl = Analytic::parse("cylinder:r=300,l=1000").unwrap();
        let (m, _) = build(&tessellate_analytic(&cyl, &Tessellation::Triangles(3000)).unwrap());
        m.prepare_index();
        let p = DVec3::new(x, y, z);
        let a = m.closest_point(p).unwrap();
        let b = m.closest_point_scan(p).unwrap();
        prop_assert!((m.point(a).distance(p) - m.point(b).distance(p)).abs() < 1e-9);
    }

    /// Welding is idempotent and never merges points farther apart than the tolerance.
    #[test]
    fn weld_respects_the_tolerance(pts in prop::collection::vec(prop::array::uniform3(-5i32..5), 1..200), tol in 0.1f64..2.0) {
        let pts: Vec<DVec3> = pts.iter().map(|a| DVec3::new(a[0] as f64 * 0.7, a[1] as f64 * 0.7, a[2] as f64 * 0.7)).collect();
        let (reps, map) = towpath_geom::weld(&pts, tol);
        for (p, &r) in pts.iter().zip(&map) {
            prop_assert!(p.distance(reps[r as usize]) <= tol + 1e-12);
        }
        let (again, _) = towpath_geom::weld(&reps, 0.0);
        prop_assert_eq!(again.len(), reps.len());
    }
}
