//! Fuzz the designer's text inputs: curve and orientation CSV, analytic surface descriptions,
//! NURBS patch JSON (parsed, validated and evaluated), lengths with units, and a layup request
//! made of the numbers read (validated). Never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use towpath_geom::surface::{tessellate, Analytic, Nurbs, Surface, Tessellation};
use towpath_geom::DVec3;
use towpath_layup::input::{read_curve, read_orientations};
use towpath_layup::ply::Method;
use towpath_layup::request::{DirectionSource, LayupRequest, Limits, SurfaceRequest, SurfaceSource};
use towpath_layup::section::Coverage;
use towpath_layup::units::Units;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let curve = read_curve(text).ok();
    let _ = read_orientations(text);
    let width = Units::parse_length(text);
    if let Ok(s) = Analytic::parse(text) {
        let _ = s.closest(DVec3::new(1.0, 2.0, 3.0));
    }
    if let Ok(n) = Nurbs::from_json(text) {
        if n.control.len() <= 4096 {
            let [[u0, u1], [v0, v1]] = n.domain();
            let _ = n.derivatives(0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let _ = n.closest(DVec3::ZERO);
            let _ = tessellate(&n, &Tessellation::Triangles(200));
        }
    }
    // The numbers read, as a request: every one checked, none trusted.
    let numbers: Vec<f64> = curve.iter().flatten().flat_map(|p| p.to_array()).collect();
    let at = |i: usize| numbers.get(i).copied().unwrap_or(1.0);
    let request = LayupRequest {
        surface: SurfaceRequest {
            source: SurfaceSource::Analytic(Analytic::Plane { a: at(0).abs() + 1.0, b: at(1).abs() + 1.0 }),
            tessellation: Tessellation::Chord { d_l2s: at(2), l_seg: at(3) },
            weld_tolerance: Some(at(4)),
        },
        units: width.and_then(|w| w.1).unwrap_or(Units::Mm),
        angle_deg: at(5),
        direction: DirectionSource::Axis(DVec3::new(at(6), at(7), at(8))),
        method: Method::Field,
        tow_width: width.map_or(at(9), |w| w.0),
        tows: (at(10).abs() as usize).min(100),
        coverage: Coverage::Half,
        boundary: curve.clone(),
        start: Some(DVec3::new(at(11), at(12), at(13))),
        min_steering_radius: Some(at(14)),
        limits: Limits::default(),
    };
    let _ = request.validate();
});
