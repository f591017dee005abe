//! Courses do not depend on how finely a surface is meshed: a square plate as two triangles and
//! as 20,000 give the same courses (the exact chord for the reference course), and a tube of a
//! few hundred triangles is covered like a fine one.

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::field::{Guides, Polyline, Rosette};
use towpath_layup::ply::{plan, Method, Ply, PlySpec};
use towpath_layup::section::Coverage;

fn mesh_of(desc: &str, triangles: usize) -> Mesh {
    let s = Analytic::parse(desc).unwrap();
    let (mesh, _) =
        Mesh::build(&tessellate_analytic(&s, &Tessellation::Triangles(triangles)).unwrap(), &BuildOptions::default())
            .unwrap();
    assert!(mesh.num_faces().abs_diff(triangles) <= triangles / 10 + 2, "{} faces", mesh.num_faces());
    mesh
}

fn plate_ply(triangles: usize, angle: f64, method: Method) -> Ply {
    let mesh = mesh_of("plane:a=100,b=100", triangles);
    let field = Rosette { axis: DVec3::X, angle: angle.to_radians() };
    let mut spec = PlySpec::new(6.35, 4);
    spec.coverage = Coverage::Full;
    spec.method = method;
    spec.start = Some(DVec3::new(50.0, 50.0, 0.0));
    plan(&mesh, &field, &Region::whole(&mesh), &spec, &mut |_| {}).unwrap()
}

/// Length of the chord of the square [0, 100]² through its centre in direction θ.
fn chord(angle_deg: f64) -> f64 {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let t = |v: f64| if v.abs() < 1e-12 { f64::INFINITY } else { 50.0 / v.abs() };
    2.0 * t(c).min(t(s))
}

/// The largest difference between two plies' courses: end points, lengths and laid intervals
/// (`None` when they differ in the number of courses or laid pieces).
fn difference(a: &Ply, b: &Ply) -> Option<f64> {
    if a.courses.len() != b.courses.len() {
        return None;
    }
    let mut worst = 0.0f64;
    for (x, y) in a.courses.iter().zip(&b.courses) {
        let (xf, xl) = (x.points.first()?.p, x.points.last()?.p);
        let (yf, yl) = (y.points.first()?.p, y.points.last()?.p);
        worst = worst.max(xf.distance(yf)).max(xl.distance(yl)).max((x.length() - y.length()).abs());
        for (tx, ty) in x.tows.iter().zip(&y.tows) {
            if tx.len() != ty.len() {
                return None;
            }
            for (i, j) in tx.iter().zip(ty) {
                worst = worst.max((i[0] - j[0]).abs()).max((i[1] - j[1]).abs());
            }
        }
    }
    Some(worst)
}

#[test]
fn a_plate_of_two_triangles_gets_the_courses_of_a_fine_mesh() {
    for angle in [0.0, 30.0, 45.0, -60.0, 90.0] {
        for method in [Method::Field, Method::Parallel, Method::Natural] {
            let coarse = plate_ply(2, angle, method);
            let fine = plate_ply(20_000, angle, method);
            let what = format!("{angle}° {method:?}");
            // The reference course runs along the whole chord through the centre (and on, where
            // the 100 % rule lays its trailing tows beyond the edge), not a point.
            let reference = coarse.courses.iter().find(|c| c.side == 0).expect("a reference course");
            let (first, last) = (reference.points[0].p, reference.points[reference.points.len() - 1].p);
            let dir = DVec3::new(angle.to_radians().cos(), angle.to_radians().sin(), 0.0);
            let centre = DVec3::new(50.0, 50.0, 0.0);
            assert!(
                (first - centre).cross(dir).length() < 1e-9 && (last - centre).cross(dir).length() < 1e-9,
                "{what}"
            );
            let (a, b) = ((first - centre).dot(dir), (last - centre).dot(dir));
            assert!(a <= -0.5 * chord(angle) + 1e-3 && b >= 0.5 * chord(angle) - 1e-3, "{what}: {first} → {last}");
            let d = difference(&coarse, &fine).unwrap_or_else(|| panic!("{what}: courses differ in number or pieces"));
            assert!(d < 2e-3, "{what}: coarse and fine courses differ by {d} mm");
            // Under the 100 % rule the plate is covered alike (at 45° two corner strips 7 mm
            // deep, 1 % of the plate, get no course on either mesh: no seed station lands there).
            let (cc, cf) = (coarse.quality.coverage_percent, fine.quality.coverage_percent);
            assert!(cc > 98.5 && (cc - cf).abs() < 0.5, "{what}: coverage {cc} (fine mesh {cf})");
            // Every laid tow has a length: no course restarts and cuts all its tows at one point.
            for c in &coarse.courses {
                for iv in c.tows.iter().flatten() {
                    assert!(iv[1] - iv[0] > 1.0, "{what}: course {} lays {iv:?}", c.id);
                }
            }
        }
    }
}

#[test]
fn a_steered_ply_on_two_triangles_follows_the_field_like_a_fine_mesh() {
    // Two guide curves bending across the plate: the field turns along every course, so a
    // triangle crossed in one straight step would miss it.
    let guides = || Guides {
        curves: vec![
            Polyline::new(vec![DVec3::new(0.0, 10.0, 0.0), DVec3::new(50.0, 20.0, 0.0), DVec3::new(100.0, 40.0, 0.0)])
                .unwrap(),
            Polyline::new(vec![DVec3::new(0.0, 80.0, 0.0), DVec3::new(50.0, 85.0, 0.0), DVec3::new(100.0, 95.0, 0.0)])
                .unwrap(),
        ],
        angle: 20f64.to_radians(),
    };
    let ply_on = |triangles: usize| {
        let mesh = mesh_of("plane:a=100,b=100", triangles);
        let mut spec = PlySpec::new(3.175, 4);
        spec.coverage = Coverage::Full;
        spec.start = Some(DVec3::new(50.0, 50.0, 0.0));
        plan(&mesh, &guides(), &Region::whole(&mesh), &spec, &mut |_| {}).unwrap()
    };
    let (coarse, fine) = (ply_on(2), ply_on(20_000));
    let d = difference(&coarse, &fine).expect("same courses and pieces");
    // Half-course steps (6.35 mm) against the fine mesh's 1 mm ones: the midpoint rule keeps the
    // paths within a fraction of a millimetre.
    assert!(d < 0.5, "coarse and fine courses differ by {d} mm");
    let (qc, qf) = (&coarse.quality, &fine.quality);
    assert!(qc.max_angle_deviation_deg < qf.max_angle_deviation_deg + 0.1, "{qc:?} {qf:?}");
    assert!((qc.coverage_percent - qf.coverage_percent).abs() < 1.0, "{qc:?} {qf:?}");
}

#[test]
fn a_coarse_tube_is_covered_once_like_a_fine_one() {
    let ply_on = |triangles: usize| {
        let mesh = mesh_of("cylinder:r=300,l=1000", triangles);
        let field = Rosette { axis: DVec3::Z, angle: 45f64.to_radians() };
        let spec = PlySpec::new(6.35, 16);
        plan(&mesh, &field, &Region::whole(&mesh), &spec, &mut |_| {}).unwrap()
    };
    let (coarse, fine) = (ply_on(200), ply_on(20_000));
    // 1885 mm × cos 45° / 101.6 mm = 13.1: 13 courses and a closing one, on either mesh.
    assert_eq!(coarse.courses.len(), 14);
    assert_eq!(fine.courses.len(), 14);
    assert!(coarse.quality.coverage_percent > 99.5, "{}", coarse.quality.coverage_percent);
}
