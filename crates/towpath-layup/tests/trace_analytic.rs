//! Traced courses on meshes of analytic surfaces against their closed-form geodesics.

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Surface, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::accuracy::{deviation, Reference};
use towpath_layup::field::Rosette;
use towpath_layup::trace::{trace_both, Located, Steering, WalkOptions};

fn mesh_of(s: &Analytic, t: Tessellation) -> Mesh {
    let soup = tessellate_analytic(s, &t).unwrap();
    Mesh::build(&soup, &BuildOptions::default()).unwrap().0
}

fn start_on(mesh: &Mesh, p: DVec3) -> Located {
    Located::new(mesh, mesh.closest_point(p).unwrap())
}

#[test]
fn fixed_axis_course_on_a_cylinder_is_the_helix() {
    let cyl = Analytic::parse("cylinder:r=300,l=1000").unwrap();
    let mesh = mesh_of(&cyl, Tessellation::Chord { d_l2s: 0.2, l_seg: 20.0 });
    let start = start_on(&mesh, DVec3::new(300.0, 0.0, 500.0));
    let field = Rosette { axis: DVec3::Z, angle: 45f64.to_radians() };
    let path = trace_both(&mesh, start, DVec3::Z, Steering::Field(&field), &WalkOptions::default(), |_| false).unwrap();
    // Both ends on the tube's rims.
    let first = path.points.first().unwrap().p;
    let last = path.points.last().unwrap().p;
    assert!(first.z.abs() < 1e-6 || (first.z - 1000.0).abs() < 1e-6);
    assert!(last.z.abs() < 1e-6 || (last.z - 1000.0).abs() < 1e-6);
    // 45° helix over the full length: 1000·√2 long.
    assert!((path.length() - 1000.0 * 2f64.sqrt()).abs() < 1.0, "{}", path.length());
    let d0 = path.points[path.start_index].d;
    let reference = Reference::new(cyl, start.p, d0).unwrap();
    let dev = deviation(&reference, &path.points, path.points[path.start_index].s);
    // The mesh is inscribed: points lie inside the true surface by up to the chord deviation.
    assert!(dev.max_normal <= 0.2 + 1e-6, "{dev:?}");
    assert!(dev.max_geodesic < 0.1, "{dev:?}");
    assert!(dev.mean_angle_deg < 0.05, "{dev:?}");
}

#[test]
fn geodesic_on_a_sphere_is_a_great_circle() {
    let sph = Analytic::parse("sphere:r=500").unwrap();
    let mesh = mesh_of(&sph, Tessellation::Triangles(20 * 60 * 60));
    let p = DVec3::new(500.0, 0.0, 0.0);
    let start = start_on(&mesh, DVec3::new(400.0, 30.0, 200.0));
    let d = DVec3::new(0.0, 1.0, 0.3);
    let opts = WalkOptions { max_length: 500.0, ..WalkOptions::default() };
    let path = trace_both(&mesh, start, d, Steering::Geodesic, &opts, |_| false).unwrap();
    assert!((path.length() - 1000.0).abs() < 1e-6);
    let reference = Reference::new(sph, start.p, path.points[path.start_index].d).unwrap();
    let dev = deviation(&reference, &path.points, path.points[path.start_index].s);
    let _ = p;
    // Edge ≈ 30 mm, chord depth ≈ 0.25 mm.
    assert!(dev.max_normal < 0.3, "{dev:?}");
    assert!(dev.max_geodesic < 0.5, "{dev:?}");
}

#[test]
fn geodesic_on_a_cone_is_a_straight_line_of_the_development() {
    let cone = Analytic::parse("cone:r0=300,r1=150,l=600").unwrap();
    let mesh = mesh_of(&cone, Tessellation::Chord { d_l2s: 0.1, l_seg: 15.0 });
    let start = start_on(&mesh, cone.eval(0.3, 200.0));
    let path =
        trace_both(&mesh, start, DVec3::new(0.0, 1.0, 1.0), Steering::Geodesic, &WalkOptions::default(), |_| false)
            .unwrap();
    assert!(path.length() > 300.0);
    let reference = Reference::new(cone, start.p, path.points[path.start_index].d).unwrap();
    let dev = deviation(&reference, &path.points, path.points[path.start_index].s);
    assert!(dev.max_normal < 0.15, "{dev:?}");
    assert!(dev.max_geodesic < 0.2, "{dev:?}");
}
