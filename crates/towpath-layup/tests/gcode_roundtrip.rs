//! The G-code of `towpath_layup::output::to_gcode` read back by towpath-nc's program parser
//! (reference dialect, a machine with X Y Z A B C axes): the same plies and courses, every
//! on-part position on the generated centreline within the written rounding, the tows running
//! on every move equal to the tows laid there, and the head angles rebuilding the surface frame.

use glam::{DMat3, DVec3};
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh};
use towpath_layup::boundary::Region;
use towpath_layup::course::Course;
use towpath_layup::field::Rosette;
use towpath_layup::output::{self, Meta, Post};
use towpath_layup::ply::{plan, Method, Ply, PlySpec};
use towpath_layup::section::Coverage;
use towpath_machine::{Axis, AxisKind, Machine};
use towpath_nc::{parse, Dialect, Program};

fn mesh_of(desc: &str, t: Tessellation) -> Mesh {
    let s = Analytic::parse(desc).unwrap();
    Mesh::build(&tessellate_analytic(&s, &t).unwrap(), &BuildOptions::default()).unwrap().0
}

/// X Y Z linear, A B rotary, C continuous heading: the axes the post-processor writes.
fn six_axis() -> Machine {
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    let axes = vec![
        Axis::new("X", AxisKind::Linear),
        Axis::new("Y", AxisKind::Linear),
        Axis::new("Z", AxisKind::Linear),
        Axis::new("A", AxisKind::Rotary),
        Axis::new("B", AxisKind::Rotary),
        c,
    ];
    Machine::new("six-axis", axes).unwrap()
}

fn meta(surface: &str, angle: f64, spec: &PlySpec, ply_number: usize) -> Meta {
    Meta {
        surface: surface.into(),
        angle_deg: angle,
        direction_source: "axis".into(),
        tow_width: spec.tow_width,
        tows: spec.tows,
        coverage_percent: spec.coverage.percent(),
        method: spec.method,
        ply_number,
        input_units: towpath_layup::units::Units::Mm,
    }
}

/// The on-part stations the program must visit, from the course alone (docs/layup-gcode.md): the
/// centreline points after the first, and one station at every tow event, an event written
/// before a point at the same arc length. Each with its arc length and frame.
fn expected_stations(c: &Course) -> Vec<(f64, DVec3, DVec3, DVec3)> {
    let mut st: Vec<(f64, u8, DVec3, DVec3, DVec3)> = Vec::new();
    for e in c.events() {
        let (p, n, d) = c.frame_at(e.s);
        st.push((e.s, 0, p, n, d));
    }
    for q in &c.points[1..] {
        st.push((q.s, 1, q.p, q.n, q.d));
    }
    st.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    st.into_iter().map(|(s, _, p, n, d)| (s, p, n, d)).collect()
}

fn head_frame(abc: [f64; 3]) -> DMat3 {
    let [a, b, c] = abc.map(f64::to_radians);
    DMat3::from_rotation_x(a) * DMat3::from_rotation_y(b) * DMat3::from_rotation_z(c)
}

/// Checks a parsed program against the ply it was written from; returns the number of on-part
/// moves checked.
fn check_round_trip(ply: &Ply, program: &Program, ply_number: usize, tows: usize) -> usize {
    assert_eq!(program.plies.len(), 1);
    assert_eq!(program.plies[0].number, Some(ply_number as i64));
    assert_eq!(program.courses.len(), ply.courses.len());
    assert_eq!(program.plies[0].courses, (0..ply.courses.len()).collect::<Vec<_>>());
    let mut moves = 0;
    let mut laid_from_program = 0.0;
    for (i, c) in ply.courses.iter().enumerate() {
        let pc = &program.courses[i];
        assert_eq!(pc.number, Some(i as i64 + 1));
        // One approach move (the contact G1) and one retract move (the lift) are kept with the
        // course; the G0 moves around them are transit.
        assert_eq!(pc.approach().len(), 1, "course {i}: approach lines {:?}", pc.approach());
        let segs: Vec<_> = program.on_part_segments(i).copied().collect();
        let want = expected_stations(c);
        assert_eq!(segs.len(), want.len(), "course {i}: on-part moves");
        let first = program.point(segs[0].from);
        assert!((DVec3::new(first[0], first[1], first[2]) - c.points[0].p).abs().max_element() <= 5.001e-4);
        let mut s_prev = 0.0;
        for (seg, &(s, p, n, d)) in segs.iter().zip(&want) {
            let v = program.point(seg.to);
            let at = DVec3::new(v[0], v[1], v[2]);
            // Three decimals: every coordinate within half a micrometre of the course point.
            assert!((at - p).abs().max_element() <= 5.001e-4, "course {i} s {s}: {at} vs {p}");
            let r = head_frame([v[3], v[4], v[5]]);
            assert!((r.z_axis - n).length() < 1e-4, "course {i} s {s}: normal {} vs {n}", r.z_axis);
            assert!((r.x_axis - d).length() < 1e-4, "course {i} s {s}: direction {} vs {d}", r.x_axis);
            // The tows running on the move are the tows the course lays there.
            if s - s_prev > 1e-6 {
                let mid = 0.5 * (s + s_prev);
                let laid: u64 = (0..tows).filter(|&k| c.laid(k, mid)).map(|k| 1u64 << k).sum();
                assert_eq!(seg.mask, laid, "course {i} between s {s_prev} and {s}");
                let f = program.point(seg.from);
                let len = (at - DVec3::new(f[0], f[1], f[2])).length();
                laid_from_program += len * seg.mask.count_ones() as f64;
            }
            assert!(seg.on_part && !seg.rapid);
            s_prev = s;
            moves += 1;
        }
        assert!((s_prev - c.length()).abs() < 1e-9, "course {i} ends at its last point");
    }
    // Laid tow length from the program's moves and masks against the ply's laid intervals.
    let tol = moves as f64 * tows as f64 * 2e-3;
    assert!(
        (laid_from_program - ply.quality.tow_length).abs() < tol,
        "{laid_from_program} vs {}",
        ply.quality.tow_length
    );
    moves
}

#[test]
fn plate_ply_with_boundary_round_trips_through_the_program_parser() {
    let mesh = mesh_of("plane:a=400,b=300", Tessellation::Chord { d_l2s: 0.1, l_seg: 25.0 });
    let square = [
        DVec3::new(50.0, 50.0, 0.0),
        DVec3::new(350.0, 50.0, 0.0),
        DVec3::new(350.0, 250.0, 0.0),
        DVec3::new(50.0, 250.0, 0.0),
    ];
    let region = Region::curve(&mesh, &square, 3.0, None).unwrap();
    let field = Rosette { axis: DVec3::X, angle: 30f64.to_radians() };
    let mut spec = PlySpec::new(6.35, 8);
    spec.coverage = Coverage::Zero;
    spec.start = Some(DVec3::new(200.0, 150.0, 0.0));
    let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
    let text = output::to_gcode(&ply, &meta("plane:a=400,b=300", 30.0, &spec, 4), &Post::default());
    let program = parse(&text, &six_axis(), &Dialect::default()).unwrap();
    let moves = check_round_trip(&ply, &program, 4, 8);
    assert!(moves > 100);
    // Angled courses in a square drop and add tows one by one: the program carries those events.
    let events = text.lines().filter(|l| l.starts_with("M60") || l.starts_with("M61")).count();
    assert!(events > 4 * ply.courses.len(), "{events} events on {} courses", ply.courses.len());
}

#[test]
fn curved_panel_ply_round_trips_with_head_angles() {
    // A ±45°-type ply on a cylindrical panel: the normal turns through 120°, so A and B vary.
    let desc = "cylinder:r=300,l=400,a0=30,a1=150";
    let mesh = mesh_of(desc, Tessellation::Chord { d_l2s: 0.05, l_seg: 15.0 });
    let region = Region::whole(&mesh);
    let field = Rosette { axis: DVec3::Z, angle: (-45f64).to_radians() };
    for method in [Method::Field, Method::Parallel] {
        let mut spec = PlySpec::new(6.35, 16);
        spec.method = method;
        spec.coverage = Coverage::Full;
        let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).unwrap();
        let text = output::to_gcode(&ply, &meta(desc, -45.0, &spec, 1), &Post::default());
        let program = parse(&text, &six_axis(), &Dialect::default()).unwrap();
        let moves = check_round_trip(&ply, &program, 1, 16);
        assert!(moves > 200, "{method:?}: {moves}");
    }
}
