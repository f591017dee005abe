//! Plies on curved surfaces and steered fields where the answer is known in closed form.

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::field::{Guides, Polyline, Rosette};
use towpath_layup::ply::{plan, Method, PlySpec};
use towpath_layup::section::Coverage;

fn mesh_of(desc: &str, t: Tessellation) -> Mesh {
    let s = Analytic::parse(desc).unwrap();
    Mesh::build(&tessellate_analytic(&s, &t).unwrap(), &BuildOptions::default()).unwrap().0
}

#[test]
fn geodesic_parallels_on_a_cylinder_panel_leave_no_gaps() {
    // Half tube: helices at 30° are geodesics and stay one course width apart.
    let mesh = mesh_of("cylinder:r=300,l=800,a0=0,a1=180", Tessellation::Chord { d_l2s: 0.05, l_seg: 15.0 });
    let region = Region::whole(&mesh);
    let field = Rosette { axis: DVec3::Z, angle: 30f64.to_radians() };
    for method in [Method::Parallel, Method::Field, Method::Natural] {
        let mut spec = PlySpec::new(6.35, 8);
        spec.method = method;
        spec.start = Some(DVec3::new(0.0, 300.0, 400.0));
        let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
        let q = &ply.quality;
        assert!(ply.courses.len() >= 10, "{method:?}");
        // Between inner courses: no gap or overlap. The outermost courses are shifted onto the
        // panel (the panel is not a whole number of courses wide) and overlap their neighbour by
        // less than half a course.
        let last = ply.courses.len() - 1;
        for (i, cq) in q.courses.iter().enumerate() {
            for &[s, width] in &cq.gap_to_left {
                if i == 0 || i + 1 == last {
                    assert!(width > -25.4 && width < 0.1, "{method:?} edge course {i} at {s}: {width}");
                } else if i < last {
                    assert!(width.abs() < 0.1, "{method:?} course {i} at {s}: {width}");
                }
            }
        }
        assert!(q.max_gap < 0.1, "{method:?}: gap {}", q.max_gap);
        assert!(q.max_angle_deviation_deg < 0.2, "{method:?}: {}", q.max_angle_deviation_deg);
        assert!(q.points_below_min_radius == 0, "{method:?}");
        assert!(q.coverage_percent > 99.5, "{method:?}: {}", q.coverage_percent);
    }
}

#[test]
fn concentric_guide_steers_courses_to_the_guide_radius() {
    // A guide circle of radius 1000 about (−300, 300); on the plate courses follow concentric arcs,
    // so the steering radius at a point is its distance from the centre.
    let mesh = mesh_of("plane:a=800,b=600", Tessellation::Chord { d_l2s: 0.1, l_seg: 10.0 });
    let region = Region::whole(&mesh);
    let c = DVec3::new(-300.0, 300.0, 0.0);
    let guide: Vec<DVec3> = (0..=720)
        .map(|i| {
            let a = std::f64::consts::PI * (i as f64 / 720.0 - 0.5);
            c + DVec3::new(a.cos(), a.sin(), 0.0) * 1000.0
        })
        .collect();
    let field = Guides { curves: vec![Polyline::new(guide).unwrap()], angle: 0.0 };
    let mut spec = PlySpec::new(6.35, 8);
    spec.start = Some(DVec3::new(400.0, 300.0, 0.0));
    spec.min_steering_radius = 635.0;
    let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    let mut checked = 0;
    for (course, q) in ply.courses.iter().zip(&ply.quality.courses) {
        // The on-surface part (run-outs beyond the plate edge are straight by construction).
        let on: Vec<f64> = course.points.iter().zip(&course.on_surface).filter(|(_, &o)| o).map(|(p, _)| p.s).collect();
        let (s0, s1) = (on[0], on[on.len() - 1]);
        for (p, r) in course.points.iter().zip(&q.steering_radius) {
            // Away from the ends (the curvature window is one-sided there).
            if p.s < s0 + 20.0 || p.s > s1 - 20.0 {
                continue;
            }
            let expect = (p.p - c).length();
            let r = r.expect("curved");
            if (r - expect).abs() / expect >= 0.02 {
                eprintln!(
                    "course {} s {} of {} (on {s0}..{s1}) pts {}",
                    course.id,
                    p.s,
                    course.length(),
                    course.points.len()
                );
                for x in course.points.iter().filter(|x| (x.s - p.s).abs() < 20.0) {
                    eprintln!(
                        "  s {:.2} rad {:.2} ang {:.3}",
                        x.s,
                        (x.p - c).length(),
                        x.d.y.atan2(x.d.x).to_degrees()
                    );
                }
            }
            assert!((r - expect).abs() / expect < 0.02, "radius {r} vs {expect}");
            checked += 1;
        }
    }
    assert!(checked > 500);
    // Courses nearer the centre than 635 mm are flagged.
    assert!(ply.quality.points_below_min_radius > 0);
    let min = ply.quality.min_steering_radius.unwrap();
    let nearest =
        ply.courses.iter().flat_map(|c| c.points.iter()).map(|p| (p.p - c).length()).fold(f64::INFINITY, f64::min);
    assert!((min - nearest).abs() / nearest < 0.05, "{min} vs {nearest}");
}

#[test]
fn a_ply_on_a_real_aircraft_mesh() {
    // Unwelded binary STL of a swept wing with tail surfaces (feet-scale units; tows scaled to
    // match: 16 × 0.02).
    let bytes =
        include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/../towpath-geom/tests/data/swept_wing_and_tail.stl"));
    let soup = towpath_geom::io::read_bytes(bytes, towpath_geom::io::Format::Stl).unwrap();
    let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
    let region = Region::whole(&mesh);
    let field = Rosette { axis: DVec3::X, angle: 0.0 };
    let spec = PlySpec::new(0.02, 16);
    let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    assert!(ply.courses.len() > 10);
    assert_eq!(ply.courses.len(), ply.n1 + ply.n2 + 1);
    // Field courses follow the design direction exactly, whatever the surface does.
    assert!(ply.quality.max_angle_deviation_deg < 0.01);
    assert!(ply.quality.coverage_percent > 90.0, "{}", ply.quality.coverage_percent);
    for c in &ply.courses {
        for p in &c.points {
            assert!(p.p.is_finite() && (p.n.length() - 1.0).abs() < 1e-9 && (p.d.length() - 1.0).abs() < 1e-9);
        }
        for ivs in &c.tows {
            assert!(ivs.windows(2).all(|w| w[0][1] < w[1][0]), "tow intervals ordered and disjoint");
        }
    }
}

#[test]
fn hoop_courses_close_on_themselves() {
    // 90° to the axis of a tube: every course is a closed hoop of length 2πR.
    let mesh = mesh_of("cylinder:r=300,l=500", Tessellation::Chord { d_l2s: 0.05, l_seg: 15.0 });
    let region = Region::whole(&mesh);
    let field = Rosette { axis: DVec3::Z, angle: 90f64.to_radians() };
    for method in [Method::Field, Method::Parallel, Method::Natural] {
        let mut spec = PlySpec::new(6.35, 16);
        spec.method = method;
        let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
        // 500 / 101.6 = 4.9: five courses.
        assert_eq!(ply.courses.len(), 5, "{method:?}");
        for c in &ply.courses {
            let (a, b) = (c.points[0].p, c.points[c.points.len() - 1].p);
            assert!(a.distance(b) < 1e-6, "{method:?}: open loop {a} {b}");
            let circumference = std::f64::consts::TAU * 300.0;
            assert!((c.length() - circumference).abs() < 0.01 * circumference, "{method:?}: {}", c.length());
        }
    }
}

/// Laid tow bands across the fibers where a 45° course crosses the height `z` of a tube of radius
/// `r` about the z axis, as intervals of the lateral coordinate of the unrolled tube (where the
/// helices are parallel straight lines), taken modulo its period.
fn laid_bands_at(ply: &towpath_layup::ply::Ply, r: f64, z: f64, tow_width: f64, tows: usize) -> (Vec<[f64; 2]>, f64) {
    let t = DVec3::new(1.0, 1.0, 0.0).normalize(); // (u, z) direction of the fibers, up to sign
    let period = std::f64::consts::TAU * r * t.y.abs();
    let mut bands = Vec::new();
    for c in &ply.courses {
        let Some(i) = c.points.windows(2).position(|w| (w[0].p.z - z) * (w[1].p.z - z) <= 0.0) else { continue };
        let (a, b) = (c.points[i], c.points[i + 1]);
        let f = (z - a.p.z) / (b.p.z - a.p.z);
        let s = a.s + f * (b.s - a.s);
        let (p, n, d) = c.frame_at(s);
        let phi = p.y.atan2(p.x);
        let e_phi = DVec3::new(-phi.sin(), phi.cos(), 0.0);
        // Fiber direction and lateral (left) direction in (u, z) coordinates.
        let du = DVec3::new(d.dot(e_phi), d.z, 0.0).normalize();
        let m = DVec3::new(-du.y, du.x, 0.0);
        let left = n.cross(d);
        let sigma = m.dot(DVec3::new(left.dot(e_phi), left.z, 0.0)).signum();
        let l0 = m.dot(DVec3::new(r * phi, p.z, 0.0));
        for k in 0..tows {
            if !c.laid(k, s) {
                continue;
            }
            let (e0, e1) = ((k as f64) * tow_width, (k + 1) as f64 * tow_width);
            let half = 0.5 * tow_width * tows as f64;
            let (x0, x1) = (l0 + sigma * (e0 - half), l0 + sigma * (e1 - half));
            bands.push([x0.min(x1).rem_euclid(period), x0.min(x1).rem_euclid(period) + tow_width]);
        }
    }
    (bands, period)
}

/// (widest uncovered stretch, total overlap) of bands on a circle of length `period`.
fn gaps_and_overlap(bands: &[[f64; 2]], period: f64) -> (f64, f64) {
    let mut iv: Vec<[f64; 2]> = Vec::new();
    for b in bands {
        if b[1] > period {
            iv.push([b[0], period]);
            iv.push([0.0, b[1] - period]);
        } else {
            iv.push(*b);
        }
    }
    iv.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let total: f64 = iv.iter().map(|b| b[1] - b[0]).sum();
    let (mut union, mut widest, mut end) = (0.0, 0.0f64, 0.0f64);
    let first = iv.first().map_or(0.0, |b| b[0]);
    for b in &iv {
        if b[0] > end {
            widest = widest.max(b[0] - end);
            union += b[1] - b[0];
            end = b[1];
        } else if b[1] > end {
            union += b[1] - end;
            end = b[1];
        }
    }
    widest = widest.max(period - end + first);
    (widest, total - union)
}

#[test]
fn helical_ply_on_a_tube_is_closed_by_a_course_trimmed_against_the_laid_ones() {
    // 45° on a closed tube R 300: the lateral period is 2π·300·cos 45° = 1332.9 mm = 13.12 courses
    // of 101.6 mm. Thirteen whole courses leave a 12.2 mm strip; the closing course lays only the
    // tows the coverage rule gives to the strip: two (12.7 mm) at 50 % and 100 %, one whole tow
    // at 0 % (it must not overlap).
    let mesh = mesh_of("cylinder:r=300,l=600", Tessellation::Chord { d_l2s: 0.05, l_seg: 15.0 });
    let region = Region::whole(&mesh);
    let field = Rosette { axis: DVec3::Z, angle: 45f64.to_radians() };
    let (tw, tows) = (6.35, 16);
    for method in [Method::Field, Method::Parallel] {
        for rule in [Coverage::Zero, Coverage::Half, Coverage::Full] {
            let mut spec = PlySpec::new(tw, tows);
            spec.method = method;
            spec.coverage = rule;
            spec.start = Some(DVec3::new(300.0, 0.0, 300.0));
            let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
            assert_eq!(ply.courses.len(), 14, "{method:?} {rule:?}");
            assert_eq!(ply.n1 + ply.n2 + 1, 14);
            for z in [150.0, 300.0, 450.0] {
                let (bands, period) = laid_bands_at(&ply, 300.0, z, tw, tows);
                let (gap, overlap) = gaps_and_overlap(&bands, period);
                let what = format!("{method:?} {rule:?} z {z}: {} bands, gap {gap}, overlap {overlap}", bands.len());
                match rule {
                    Coverage::Zero => {
                        assert_eq!(bands.len(), 13 * tows + 1, "{what}");
                        // Abutting edges are free within 0.05 tow widths (the tangent-plane offsets
                        // of the laid-tow test).
                        assert!(overlap < 0.05 * tw, "{what}");
                        assert!(gap < tw, "{what}");
                    }
                    Coverage::Half | Coverage::Full => {
                        assert_eq!(bands.len(), 13 * tows + 2, "{what}");
                        assert!(gap < 0.1, "{what}");
                        assert!(overlap < tw, "{what}");
                    }
                }
            }
            // The closing course lays only whole pieces along the strip.
            let closing = &ply.courses[0];
            let laid: Vec<usize> = (0..tows).filter(|&k| !closing.tows[k].is_empty()).collect();
            assert_eq!(laid.len(), if rule == Coverage::Zero { 1 } else { 2 }, "{method:?} {rule:?}: {laid:?}");
            for &k in &laid {
                assert!(
                    closing.tows[k].iter().all(|iv| iv[1] - iv[0] > 500.0),
                    "{method:?} {rule:?}: {:?}",
                    closing.tows[k]
                );
            }
            if rule != Coverage::Zero {
                assert!(ply.quality.coverage_percent > 99.5, "{method:?} {rule:?}: {}", ply.quality.coverage_percent);
            }
        }
    }
}
