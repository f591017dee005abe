//! A whole job through [`towpath_layup::request::run`]: units, the checks in library terms, the
//! work bound and the deadline.

use std::time::{Duration, Instant};

use glam::DVec3;
use towpath_geom::surface::{Analytic, Tessellation};
use towpath_layup::ply::{Method, PlyError};
use towpath_layup::request::{
    run, DirectionSource, LayupError, LayupRequest, Limits, SurfaceRequest, SurfaceSource, Warning,
};
use towpath_layup::section::Coverage;
use towpath_layup::units::Units;

fn plate(a: f64, b: f64, units: Units, tow_width: f64) -> LayupRequest {
    LayupRequest {
        surface: SurfaceRequest {
            source: SurfaceSource::Analytic(Analytic::Plane { a, b }),
            tessellation: Tessellation::Triangles(2000),
            weld_tolerance: None,
        },
        units,
        angle_deg: 30.0,
        direction: DirectionSource::Axis(DVec3::X),
        method: Method::Field,
        tow_width,
        tows: 4,
        coverage: Coverage::Half,
        boundary: None,
        start: None,
        min_steering_radius: None,
        limits: Limits::default(),
    }
}

#[test]
fn a_job_in_inches_is_the_same_job_in_millimetres() {
    let mm = run(plate(254.0, 127.0, Units::Mm, 6.35), &mut |_| {}).unwrap();
    let mut inch = plate(10.0, 5.0, Units::In, 0.25);
    inch.start = Some(DVec3::new(5.0, 2.5, 0.0));
    inch.boundary = Some(vec![
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(9.5, 0.5, 0.0),
        DVec3::new(9.5, 4.5, 0.0),
        DVec3::new(0.5, 4.5, 0.0),
    ]);
    let mut mm_b = plate(254.0, 127.0, Units::Mm, 6.35);
    mm_b.start = inch.start.map(|p| p * 25.4);
    mm_b.boundary = inch.boundary.as_ref().map(|b| b.iter().map(|p| *p * 25.4).collect());
    let (a, b) = (run(inch, &mut |_| {}).unwrap(), run(mm_b, &mut |_| {}).unwrap());
    assert!((a.tow_width_mm - 6.35).abs() < 1e-12);
    assert_eq!(a.ply.courses.len(), b.ply.courses.len());
    for (x, y) in a.ply.courses.iter().zip(&b.ply.courses) {
        assert!((x.length() - y.length()).abs() < 1e-6, "{} vs {}", x.length(), y.length());
        assert!(x.points[0].p.distance(y.points[0].p) < 1e-6);
    }
    // The whole plate: 254 × 127 mm², read in either unit.
    assert!((mm.ply.quality.ply_area - 254.0 * 127.0).abs() < 1e-6);
    assert!(mm.warnings.is_empty(), "{:?}", mm.warnings);
}

#[test]
fn refusals_are_typed_and_say_what_is_wrong_in_library_terms() {
    let check = |edit: &dyn Fn(&mut LayupRequest), expect: &dyn Fn(&LayupError) -> bool| {
        let mut r = plate(200.0, 100.0, Units::Mm, 6.35);
        edit(&mut r);
        let e = run(r, &mut |_| {}).expect_err("refused");
        assert!(expect(&e), "{e:?}");
        assert!(!e.to_string().contains("--"), "no command-line flag in a library message: {e}");
    };
    check(&|r| r.tow_width = f64::NAN, &|e| matches!(e, LayupError::NotFinite("tow width")));
    check(&|r| r.tow_width = 1e9, &|e| matches!(e, LayupError::TowWidth { .. }));
    check(&|r| r.tows = 65, &|e| matches!(e, LayupError::Tows(65)));
    check(&|r| r.angle_deg = 1e300, &|e| matches!(e, LayupError::Angle { .. }));
    check(&|r| r.surface.weld_tolerance = Some(-1.0), &|e| matches!(e, LayupError::Negative { .. }));
    check(&|r| r.min_steering_radius = Some(f64::NAN), &|e| matches!(e, LayupError::NotFinite(_)));
    check(&|r| r.start = Some(DVec3::new(1e308, 0.0, 0.0)), &|e| matches!(e, LayupError::TooFar { .. }));
    check(&|r| r.start = Some(DVec3::new(0.0, 0.0, 5000.0)), &|e| matches!(e, LayupError::StartOffSurface { .. }));
    check(&|r| r.direction = DirectionSource::Axis(DVec3::ZERO), &|e| matches!(e, LayupError::Axis));
    check(&|r| r.direction = DirectionSource::Guides(vec![vec![DVec3::ONE; 3]]), &|e| {
        matches!(e, LayupError::Guide(1))
    });
    check(&|r| r.boundary = Some(vec![DVec3::ONE; 2]), &|e| matches!(e, LayupError::Boundary));
    // The surface ten kilometres square: too many courses, refused before any is traced.
    let t = Instant::now();
    check(&|r| r.surface.source = SurfaceSource::Analytic(Analytic::Plane { a: 1e7, b: 1e7 }), &|e| {
        matches!(e, LayupError::TooMuchWork { what: "courses", .. })
    });
    assert!(t.elapsed() < Duration::from_secs(5));
    // A deadline already passed.
    check(&|r| r.limits.deadline = Some(Instant::now()), &|e| matches!(e, LayupError::TimeLimit(_)));
    // A course limit below the ply's courses: refused, not cut short.
    check(&|r| r.limits.max_courses = 3, &|e| matches!(e, LayupError::Ply(PlyError::TooManyCourses(3))));
}

#[test]
fn warnings_say_when_the_ply_is_not_what_was_meant() {
    // A plate of 10 × 5 "mm" with 0.25 mm tows: an inch drawing read as millimetres.
    let r = run(plate(10.0, 5.0, Units::Mm, 0.25), &mut |_| {}).unwrap();
    assert!(r.warnings.iter().any(|w| matches!(w, Warning::SurfaceSize { .. })), "{:?}", r.warnings);
    assert!(r.warnings.iter().any(|w| matches!(w, Warning::TowWidth { .. })), "{:?}", r.warnings);
    // A strip narrower than one course.
    let r = run(plate(300.0, 10.0, Units::Mm, 6.35), &mut |_| {}).unwrap();
    assert!(
        r.warnings
            .iter()
            .any(|w| matches!(w, Warning::CourseWiderThanPly { course_mm, .. } if (*course_mm - 25.4).abs() < 1e-9)),
        "{:?}",
        r.warnings
    );
}
