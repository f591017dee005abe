//! Quality figures and course methods where the answer is known in closed form on a plate:
//! gap/overlap widths and areas between diverging courses, and natural-path courses.

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::field::{DirectionField, Guides, Polyline};
use towpath_layup::ply::{plan, Method, PlySpec};

fn plate(a: f64, b: f64) -> Mesh {
    let s = Analytic::parse(&format!("plane:a={a},b={b}")).unwrap();
    Mesh::build(
        &tessellate_analytic(&s, &Tessellation::Chord { d_l2s: 0.1, l_seg: 20.0 }).unwrap(),
        &BuildOptions::default(),
    )
    .unwrap()
    .0
}

/// Fibers pointing away from a centre: every course is a ray from it.
struct Radial(DVec3);

impl DirectionField for Radial {
    fn direction(&self, p: DVec3, n: DVec3) -> Option<DVec3> {
        let v = p - self.0;
        (v - n * v.dot(n)).try_normalize()
    }
}

#[test]
fn gaps_and_overlaps_between_diverging_courses_match_the_rays() {
    // Rays from c = (−200, 300): two neighbouring courses at angle Δ are r·tan Δ apart, measured
    // perpendicular to the first at distance r from c, so the gap is r·tan Δ − w (an overlap where
    // negative). Areas are the integrals of the positive and negative parts along the courses.
    let mesh = plate(800.0, 600.0);
    let region = Region::whole(&mesh);
    let c = DVec3::new(-200.0, 300.0, 0.0);
    let field = Radial(c);
    let mut spec = PlySpec::new(6.35, 8);
    spec.start = Some(DVec3::new(400.0, 300.0, 0.0));
    let w = 6.35 * 8.0;
    let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    assert!(ply.courses.len() >= 9, "{}", ply.courses.len());
    let (mut gap_area, mut overlap_area, mut max_gap, mut max_overlap) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut samples = 0;
    for (i, q) in ply.quality.courses.iter().enumerate().take(ply.courses.len() - 1) {
        let (a, b) = (&ply.courses[i], &ply.courses[i + 1]);
        // Each course is a ray: its direction from its own end points.
        let da = (a.points[a.points.len() - 1].p - a.points[0].p).normalize();
        let db = (b.points[b.points.len() - 1].p - b.points[0].p).normalize();
        let tan = da.cross(db).z / da.dot(db);
        assert!(tan > 0.0, "course {} turns left of course {i}", i + 1);
        if q.gap_to_left.len() < 2 {
            continue;
        }
        let ds = q.gap_to_left[1][0] - q.gap_to_left[0][0];
        let g = |s: f64| (a.frame_at(s).0 - c).length() * tan - w;
        for &[s, width] in &q.gap_to_left {
            assert!((width - g(s)).abs() < 0.02, "courses {i}/{}: at s {s}: {width} vs {}", i + 1, g(s));
            samples += 1;
        }
        // Integrals of the linear width over the sampled stretch (each sample stands for ds).
        let (s0, s1) = (q.gap_to_left[0][0] - 0.5 * ds, q.gap_to_left[q.gap_to_left.len() - 1][0] + 0.5 * ds);
        let n = 20_000;
        for k in 0..n {
            let s = s0 + (s1 - s0) * (k as f64 + 0.5) / n as f64;
            let x = g(s) * (s1 - s0) / n as f64;
            if x > 0.0 {
                gap_area += x;
            } else {
                overlap_area -= x;
            }
        }
        max_gap = max_gap.max(g(q.gap_to_left[q.gap_to_left.len() - 1][0]).max(g(q.gap_to_left[0][0])));
        max_overlap = max_overlap.max(-g(q.gap_to_left[0][0]).min(g(q.gap_to_left[q.gap_to_left.len() - 1][0])));
    }
    assert!(samples > 500, "{samples}");
    let pq = &ply.quality;
    assert!(gap_area > 1000.0 && overlap_area > 1000.0, "{gap_area} {overlap_area}");
    assert!((pq.gap_area - gap_area).abs() < 0.01 * gap_area, "gap area {} vs {gap_area}", pq.gap_area);
    assert!(
        (pq.overlap_area - overlap_area).abs() < 0.01 * overlap_area,
        "overlap area {} vs {overlap_area}",
        pq.overlap_area
    );
    assert!((pq.max_gap - max_gap).abs() < 0.05, "{} vs {max_gap}", pq.max_gap);
    assert!((pq.max_overlap - max_overlap).abs() < 0.05, "{} vs {max_overlap}", pq.max_overlap);
    // Field courses follow the rays exactly and are straight.
    assert!(pq.max_angle_deviation_deg < 0.01, "{}", pq.max_angle_deviation_deg);
}

#[test]
fn natural_courses_are_geodesics_that_hold_the_angle_only_at_their_seed() {
    // A guide circle of radius 1000 about (−300, 300): field courses are concentric arcs; natural
    // courses are geodesics of the plate (straight lines) started in the design direction, so they
    // are straight, meet the design direction where they start and drift from it away from there.
    let mesh = plate(800.0, 600.0);
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
    spec.method = Method::Natural;
    let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    assert!(ply.courses.len() >= 10);
    for (course, q) in ply.courses.iter().zip(&ply.quality.courses) {
        let (a, b) = (course.points[0].p, course.points[course.points.len() - 1].p);
        let dir = (b - a).normalize();
        for p in &course.points {
            let off = (p.p - a) - dir * (p.p - a).dot(dir);
            assert!(off.length() < 1e-6, "course {}: {} mm off its chord", course.id, off.length());
        }
        // The angle to the field is zero at the seed and grows away from it: the arc of radius ρ
        // turns by s/ρ over a length s of the straight course.
        let min = q.angle_deviation_deg.iter().copied().fold(f64::INFINITY, f64::min);
        let max = q.angle_deviation_deg.iter().copied().fold(0.0, f64::max);
        assert!(min < 0.05, "course {}: smallest deviation {min}°", course.id);
        assert!(course.length() < 200.0 || max > 5.0, "course {}: {max}° over {} mm", course.id, course.length());
    }
    // No steering at all.
    assert!(ply.quality.min_steering_radius.is_none_or(|r| r > 1e6), "{:?}", ply.quality.min_steering_radius);
    // The same design as field courses: concentric arcs, exact angle, steered.
    spec.method = Method::Field;
    let steered = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    // On the plate the angle is exact (the straight run-outs beyond its edges, where trailing tows
    // are still laid, deviate and are reported in the ply figures).
    let mut on_plate = 0;
    for (course, q) in steered.courses.iter().zip(&steered.quality.courses) {
        for (dev, _) in q.angle_deviation_deg.iter().zip(&course.on_surface).filter(|(_, &on)| on) {
            assert!(*dev < 0.05, "course {}: {dev}°", course.id);
            on_plate += 1;
        }
    }
    assert!(on_plate > 500);
    assert!(steered.quality.min_steering_radius.is_some_and(|r| r < 1500.0));
}
