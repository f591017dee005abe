//! Full plies on a flat plate, where the exact answer is known: course count, spacing, coverage,
//! and tow restart/cut positions under each coverage rule.

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::field::Rosette;
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::{plan, Method, Ply, PlySpec};
use towpath_layup::section::{Band, Coverage};

fn plate(a: f64, b: f64) -> Mesh {
    let s = Analytic::parse(&format!("plane:a={a},b={b}")).unwrap();
    Mesh::build(
        &tessellate_analytic(&s, &Tessellation::Chord { d_l2s: 0.1, l_seg: 25.0 }).unwrap(),
        &BuildOptions::default(),
    )
    .unwrap()
    .0
}

fn run(mesh: &Mesh, region: &Region, angle: f64, tows: usize, coverage: Coverage, start: DVec3, method: Method) -> Ply {
    let field = Rosette { axis: DVec3::X, angle: angle.to_radians() };
    let mut spec = PlySpec::new(6.35, tows);
    spec.coverage = coverage;
    spec.start = Some(start);
    spec.method = method;
    plan(mesh, &field, region, &spec, &mut |_| {}).unwrap()
}

#[test]
fn zero_degree_ply_fills_a_plate_of_whole_courses_exactly() {
    // 12 courses of 8 × 6.35 mm = 50.8 mm fit a 609.6 mm wide plate exactly.
    let mesh = plate(1000.0, 609.6);
    let region = Region::whole(&mesh);
    for method in [Method::Field, Method::Parallel, Method::Natural] {
        let ply = run(&mesh, &region, 0.0, 8, Coverage::Half, DVec3::new(500.0, 279.4, 0.0), method);
        assert_eq!(ply.courses.len(), 12, "{method:?}");
        assert_eq!(ply.n1 + ply.n2 + 1, 12);
        // The reference at y = 279.4 has 330.2 mm of plate to its left and 279.4 mm to its right:
        // seed 002 eq. 9 (beyond the reference's own half width) gives 6 and 5 courses.
        assert_eq!((ply.n1, ply.n2), (6, 5), "{method:?}");
        assert_eq!(ply.n_estimate, [6, 5], "{method:?}");
        // Courses 50.8 mm apart, from y = 25.4 to 584.2, each along the full length.
        for (i, c) in ply.courses.iter().enumerate() {
            let y = 25.4 + 50.8 * i as f64;
            let (first, last) = (c.points[0].p.x, c.points[c.points.len() - 1].p.x);
            assert!(first.abs() < 1e-3 && (last - 1000.0).abs() < 1e-3, "{first} {last}");
            for p in &c.points {
                assert!((p.p.y - y).abs() < 1e-6, "{method:?} course {i}: y {} vs {y}", p.p.y);
            }
            // Cut positions are found by bisection to 1e-3 mm.
            assert!((c.length() - 1000.0).abs() < 2e-3, "{}", c.length());
            for ivs in &c.tows {
                assert_eq!(ivs.len(), 1);
                assert!(ivs[0][0].abs() < 1e-3 && (ivs[0][1] - c.length()).abs() < 1e-9, "{ivs:?}");
            }
        }
        let q = &ply.quality;
        assert!(q.coverage_percent > 99.999, "{method:?} {}", q.coverage_percent);
        assert!(q.max_gap < 1e-6 && q.max_overlap < 1e-6, "{method:?} {q:?}");
        assert!(q.max_angle_deviation_deg < 1e-6);
        assert!(q.min_steering_radius.is_none());
    }
}

/// Lateral tow edge positions at arc length s (extended straight beyond the course's ends).
fn tow_points(c: &towpath_layup::course::Course, band: Band, k: usize, s: f64) -> [DVec3; 3] {
    let sc = s.clamp(0.0, c.length());
    let (p, n, d) = c.frame_at(sc);
    let p = p + d * (s - sc);
    let b = n.cross(d);
    [p + b * band.edge(k), p + b * band.centre(k), p + b * band.edge(k + 1)]
}

/// Checks every tow end of a ply against an independent inside test of the boundary under the
/// coverage rule: just before a laid end the rule holds, just beyond it does not. Returns the
/// number of ends checked.
fn check_tow_ends(ply: &Ply, band: Band, rule: Coverage, inside: &dyn Fn(DVec3) -> bool, what: &str) -> usize {
    let eps = 0.05;
    let mut ends = 0;
    for c in &ply.courses {
        for (k, ivs) in c.tows.iter().enumerate() {
            for iv in ivs {
                for (s, outward) in [(iv[0], -1.0), (iv[1], 1.0)] {
                    let at = tow_points(c, band, k, s);
                    let just_out = tow_points(c, band, k, s + outward * eps);
                    let just_in = tow_points(c, band, k, s - outward * eps);
                    let where_ =
                        format!("{what} {rule:?} course {} tow {k} s {s} of {} {iv:?} at {at:?}", c.id, c.length());
                    match rule {
                        // All of the tow inside while laid; some part outside just beyond.
                        Coverage::Zero => {
                            assert!(just_in.iter().all(|&q| inside(q)), "{where_}: in {just_in:?}");
                            assert!(!just_out.iter().all(|&q| inside(q)), "{where_}: out {just_out:?}");
                        }
                        Coverage::Half => {
                            assert!(inside(just_in[1]) && !inside(just_out[1]), "{where_}");
                        }
                        Coverage::Full => {
                            assert!(just_in.iter().any(|&q| inside(q)), "{where_}: in {just_in:?}");
                            assert!(!just_out.iter().any(|&q| inside(q)), "{where_}: out {just_out:?}");
                        }
                    }
                    ends += 1;
                }
            }
        }
    }
    ends
}

#[test]
fn tows_are_cut_and_restarted_at_the_ply_boundary_under_each_rule() {
    // A 45° ply inside a square boundary 100..700 on a larger plate: every tow end must sit where
    // its rule says, checked against the boundary square directly.
    let mesh = plate(800.0, 800.0);
    let square = [
        DVec3::new(100.0, 100.0, 0.0),
        DVec3::new(700.0, 100.0, 0.0),
        DVec3::new(700.0, 700.0, 0.0),
        DVec3::new(100.0, 700.0, 0.0),
    ];
    let region = Region::curve(&mesh, &square, 3.0, Some(DVec3::new(400.0, 400.0, 0.0))).unwrap();
    let inside = |q: DVec3| q.x >= 100.0 - 1e-6 && q.x <= 700.0 + 1e-6 && q.y >= 100.0 - 1e-6 && q.y <= 700.0 + 1e-6;
    let band = Band { tow_width: 6.35, tows: 8 };
    for method in [Method::Field, Method::Parallel, Method::Natural] {
        let mut coverage_by_rule = Vec::new();
        for rule in [Coverage::Zero, Coverage::Half, Coverage::Full] {
            let ply = run(&mesh, &region, 45.0, 8, rule, DVec3::new(400.0, 400.0, 0.0), method);
            assert!(ply.courses.len() >= 10);
            assert!(check_tow_ends(&ply, band, rule, &inside, &format!("{method:?}")) > 100);
            coverage_by_rule.push(ply.quality.coverage_percent);
        }
        // Less material inside the boundary the earlier tows are cut.
        assert!(
            coverage_by_rule[0] < coverage_by_rule[1] && coverage_by_rule[1] < coverage_by_rule[2],
            "{method:?} {coverage_by_rule:?}"
        );
        assert!(coverage_by_rule[2] > 99.9, "{method:?} {coverage_by_rule:?}");
    }
}

#[test]
fn parallel_courses_are_extended_to_a_widening_boundary() {
    // A trapezoid 200 mm wide at y = 100 and 600 mm wide at y = 700: every 0° course is longer
    // than the one before it, so each geodesic offset stops short of the boundary and must be
    // extended along the surface until it leaves the ply (seed 002 §4).
    let mesh = plate(800.0, 800.0);
    let trapezoid = [
        DVec3::new(300.0, 100.0, 0.0),
        DVec3::new(500.0, 100.0, 0.0),
        DVec3::new(700.0, 700.0, 0.0),
        DVec3::new(100.0, 700.0, 0.0),
    ];
    let start = DVec3::new(400.0, 130.0, 0.0);
    let region = Region::curve(&mesh, &trapezoid, 3.0, Some(start)).unwrap();
    // Half-width of the trapezoid at height y about x = 400.
    let inside = |q: DVec3| {
        let half = 100.0 + (q.y - 100.0) / 3.0;
        (100.0 - 1e-6..=700.0 + 1e-6).contains(&q.y) && (q.x - 400.0).abs() <= half + 1e-6
    };
    let band = Band { tow_width: 6.35, tows: 8 };
    for rule in [Coverage::Zero, Coverage::Half, Coverage::Full] {
        let ply = run(&mesh, &region, 0.0, 8, rule, start, Method::Parallel);
        // 600 mm of height in courses of 50.8 mm.
        assert!(ply.courses.len() >= 12, "{}", ply.courses.len());
        assert!(check_tow_ends(&ply, band, rule, &inside, "parallel") > 100);
        // The last course on the wide side is as long as the trapezoid there.
        let top = ply.courses.iter().max_by(|a, b| a.points[0].p.y.total_cmp(&b.points[0].p.y)).unwrap();
        let y = top.points[0].p.y;
        let expect = 2.0 * (100.0 + (y - 100.0) / 3.0);
        let laid = top.laid_range().unwrap();
        assert!((laid[1] - laid[0]) > expect - band.width(), "{rule:?}: top course at y {y}: {laid:?} vs {expect}");
    }
}

#[test]
fn outputs_carry_the_courses_and_tow_events() {
    let mesh = plate(400.0, 300.0);
    let square = [
        DVec3::new(50.0, 50.0, 0.0),
        DVec3::new(350.0, 50.0, 0.0),
        DVec3::new(350.0, 250.0, 0.0),
        DVec3::new(50.0, 250.0, 0.0),
    ];
    let region = Region::curve(&mesh, &square, 3.0, None).unwrap();
    let ply = run(&mesh, &region, 30.0, 4, Coverage::Half, DVec3::new(200.0, 150.0, 0.0), Method::Field);
    let meta = Meta {
        surface: "plane:a=400,b=300".into(),
        angle_deg: 30.0,
        direction_source: "axis".into(),
        tow_width: 6.35,
        tows: 4,
        coverage_percent: 50,
        method: Method::Field,
        ply_number: 3,
        input_units: towpath_layup::units::Units::Mm,
    };
    let doc = output::to_json(&ply, &meta);
    let courses = doc["courses"].as_array().unwrap();
    assert_eq!(courses.len(), ply.courses.len());
    assert_eq!(courses[0]["points"].as_array().unwrap().len(), courses[0]["normals"].as_array().unwrap().len());
    let csv = output::to_csv(&ply);
    let rows = csv.lines().count() - 1;
    assert_eq!(rows, ply.courses.iter().map(|c| c.points.len()).sum::<usize>());
    let g = output::to_gcode(&ply, &meta, &Post::default());
    assert_eq!(g.matches("(COURSE ").count(), ply.courses.len());
    assert!(g.contains("(PLY 3 "));
    // Every tow restarted is cut again, course by course.
    let mut on = 0u64;
    for line in g.lines() {
        if let Some(m) = line.strip_prefix("M60 P") {
            let m: u64 = m.parse().unwrap();
            assert_eq!(on & m, 0, "restart of a running tow");
            on |= m;
        } else if let Some(m) = line.strip_prefix("M61 P") {
            let m: u64 = m.parse().unwrap();
            assert_eq!(on & m, m, "cut of a tow not running");
            on &= !m;
        } else if line.starts_with("M21") {
            assert_eq!(on, 0, "roller lifted with tows running");
        }
    }
    // G1 moves carry all six axis words.
    assert!(g
        .lines()
        .filter(|l| l.starts_with("G1 "))
        .all(|l| ["X", "Y", "Z", "A", "B", "C"].iter().all(|w| l.contains(w))));
}

/// The head frame of angles A, B, C (degrees): R = Rx(A)·Ry(B)·Rz(C).
fn frame_of(abc: [f64; 3]) -> glam::DMat3 {
    let [a, b, c] = abc.map(f64::to_radians);
    glam::DMat3::from_rotation_x(a) * glam::DMat3::from_rotation_y(b) * glam::DMat3::from_rotation_z(c)
}

fn check_abc(n: DVec3, d: DVec3) {
    let r = frame_of(output::abc(n, d));
    assert!((r.x_axis - d).length() < 1e-9, "x {} vs d {d} (n {n})", r.x_axis);
    assert!((r.z_axis - n).length() < 1e-9, "z {} vs n {n}", r.z_axis);
    // C is the heading: C + 180° lays the same point the other way round, A and B unchanged.
    let [a, b, c] = output::abc(n, d);
    let rev = frame_of([a, b, c + 180.0]);
    assert!((rev.x_axis + d).length() < 1e-9 && (rev.z_axis - n).length() < 1e-9);
    let [ra, rb, _] = output::abc(n, -d);
    assert!((ra - a).abs() < 1e-9 && (rb - b).abs() < 1e-9, "A/B change on reversal: {a} {b} vs {ra} {rb}");
}

#[test]
fn abc_angles_rebuild_the_frame_and_c_is_the_heading() {
    let n = DVec3::new(0.3, -0.2, 0.9).normalize();
    check_abc(n, n.any_orthonormal_vector());
    // Gimbal lock (normal along ±X) and the plain cases.
    check_abc(DVec3::X, DVec3::new(0.0, 0.6, 0.8));
    check_abc(-DVec3::X, DVec3::new(0.0, -0.8, 0.6));
    check_abc(DVec3::Z, DVec3::X);
    check_abc(-DVec3::Z, DVec3::Y);
}

proptest::proptest! {
    #[test]
    fn abc_angles_rebuild_any_frame(
        nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0, phi in 0.0f64..std::f64::consts::TAU
    ) {
        let Some(n) = DVec3::new(nx, ny, nz).try_normalize() else { return Ok(()) };
        let (u, v) = n.any_orthonormal_pair();
        check_abc(n, u * phi.cos() + v * phi.sin());
    }
}

/// A closed thin box [0, a] × [0, b] × [0, t] as a triangle soup, faces split every ~`h` mm,
/// outward orientation.
fn thin_box(a: f64, b: f64, t: f64, h: f64) -> Mesh {
    let mut tris: Vec<[DVec3; 3]> = Vec::new();
    // A rectangle from corner o along u and v (outward normal u × v), split into a grid.
    let mut rect = |o: DVec3, u: DVec3, v: DVec3| {
        let (nu, nv) = ((u.length() / h).ceil().max(1.0) as usize, (v.length() / h).ceil().max(1.0) as usize);
        for i in 0..nu {
            for j in 0..nv {
                let p = |ii: usize, jj: usize| o + u * (ii as f64 / nu as f64) + v * (jj as f64 / nv as f64);
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
    };
    let (x, y, z) = (DVec3::X * a, DVec3::Y * b, DVec3::Z * t);
    rect(DVec3::ZERO + z, x, y); // top, +z
    rect(DVec3::ZERO, y, x); // bottom, −z
    rect(DVec3::ZERO, x, z); // y = 0 side, −y
    rect(y, z, x); // y = b side, +y
    rect(DVec3::ZERO, z, y); // x = 0 side, −x
    rect(x, y, z); // x = a side, +x
    let soup = towpath_geom::Soup::from_triangles(tris);
    Mesh::build(&soup, &BuildOptions::default()).unwrap().0
}

#[test]
fn a_boundary_on_one_skin_of_a_thin_part_does_not_take_in_the_other_skin() {
    // A 4 mm thin closed box; the ply boundary is a square on the top skin. The bottom skin lies
    // 4 mm from the boundary in space but on the other side of the part: no tow may be laid there,
    // and the ply area is the square's.
    let mesh = thin_box(600.0, 400.0, 4.0, 20.0);
    assert!(mesh.boundary_loops().is_empty());
    let square = [
        DVec3::new(100.0, 100.0, 4.0),
        DVec3::new(500.0, 100.0, 4.0),
        DVec3::new(500.0, 300.0, 4.0),
        DVec3::new(100.0, 300.0, 4.0),
    ];
    let start = DVec3::new(300.0, 200.0, 4.0);
    let region = Region::curve(&mesh, &square, 3.0, Some(start)).unwrap();
    let inside = |q: DVec3| {
        q.z > 4.0 - 1e-6 && (100.0 - 1e-6..=500.0 + 1e-6).contains(&q.x) && (100.0 - 1e-6..=300.0 + 1e-6).contains(&q.y)
    };
    let band = Band { tow_width: 6.35, tows: 8 };
    for rule in [Coverage::Zero, Coverage::Half, Coverage::Full] {
        let ply = run(&mesh, &region, 30.0, 8, rule, start, Method::Field);
        for c in &ply.courses {
            for (k, ivs) in c.tows.iter().enumerate() {
                for iv in ivs {
                    for i in 0..=20 {
                        let s = iv[0] + (iv[1] - iv[0]) * i as f64 / 20.0;
                        let centre = tow_points(c, band, k, s)[1];
                        assert!(centre.z > 3.0, "{rule:?} course {} tow {k} laid at {centre} (bottom skin)", c.id);
                    }
                }
            }
        }
        assert!(check_tow_ends(&ply, band, rule, &inside, "thin box") > 50);
        let area = 400.0 * 200.0;
        assert!((ply.quality.ply_area - area).abs() < 0.02 * area, "{rule:?}: ply area {}", ply.quality.ply_area);
    }
}
