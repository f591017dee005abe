//! Issue 3 ("AFP programs end to end"), bullet by bullet: the details the other test files do not
//! show on their own. Each test checks an outcome against an independent reading of the
//! program (its own text, its own geometry), not against a stored answer.

use std::time::Duration;

use towpath_machine::{Axis, AxisKind, CostKind, Machine};
use towpath_nc::{
    build_problem, footprints, optimize, parse, rewrite, verify, AfpOptions, Dialect, NcError, OptimizeOptions,
    Placement, Report, VerifyError, VerifyOptions, Width, OVERLAP_TOLERANCE,
};

fn gantry() -> Machine {
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    c.weight = 0.1;
    let mut axes =
        vec![Axis::new("X", AxisKind::Linear), Axis::new("Y", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), c];
    for a in &mut axes {
        a.max_velocity = Some(500.0);
        a.max_acceleration = Some(1000.0);
    }
    Machine::new("test gantry", axes).unwrap()
}

/// One course along x at height y from x0 to x1: four tows (mask 15) restarted at x0, two of
/// them (mask 3) cut half way, the last two (mask 12) cut at x1.
fn course(n: usize, y: f64, x0: f64, x1: f64) -> String {
    let xm = (x0 + x1) / 2.0;
    format!(
        "(COURSE {n})\nG0 X{x0} Y{y} Z20 C0\nG1 Z0 F1000\nM20\nM60 P15\nG1 X{xm} F3000 (middle)\nM61 P3\nG1 X{x1}\nM61 P12\nM21\nG1 Z20\n"
    )
}

/// A course of one tow (mask 1) along x at height y.
fn one_tow(n: usize, y: f64, x0: f64, x1: f64) -> String {
    format!("(COURSE {n})\nG0 X{x0} Y{y} Z20 C0\nG1 Z0 F1000\nM20\nM60 P1\nG1 X{x1} F3000\nM61 P1\nM21\nG1 Z20\n")
}

fn header() -> String {
    String::from("%\nO1234 (test part)\nG21 G90\nG0 Z100\n")
}

fn footer() -> &'static str {
    "(END)\nG0 Z100\nM30\n%\n"
}

/// Two plies: a base of three courses laid out of order (y 0, 80, 40) and a pad-up of two.
fn program() -> String {
    let mut s = header();
    s.push_str("(PLY 1 base)\n");
    s.push_str(&course(1, 0.0, 0.0, 400.0));
    s.push_str("M8 (coolant, unknown to towpath)\n");
    s.push_str(&course(2, 80.0, 0.0, 400.0));
    s.push_str(&course(3, 40.0, 0.0, 400.0));
    s.push_str("(PLY 2 pad)\n");
    s.push_str(&course(1, 40.0, 300.0, 380.0));
    s.push_str(&course(2, 80.0, 300.0, 380.0));
    s.push_str(footer());
    s
}

fn opts(bidirectional: bool) -> OptimizeOptions {
    OptimizeOptions {
        afp: AfpOptions { bidirectional, width: Some(Width::Tow(10.0)), ..AfpOptions::default() },
        time_limit: Some(Duration::from_millis(200)),
        threads: 1,
        ..OptimizeOptions::default()
    }
}

fn vopts() -> VerifyOptions {
    VerifyOptions { width: Some(Width::Tow(10.0)), ..VerifyOptions::default() }
}

/// "width = tow width × number of tows on, read from the restart/cut masks, so dropped tows
/// narrow it": the footprint of each laid move is as wide as its tows, and precedence follows
/// the narrowed width.
#[test]
fn dropped_tows_narrow_the_footprint_and_the_precedence_follows() {
    let d = Dialect::default();
    let m = gantry();
    // Base course at y 0: 40 wide (4 tows of 10) on x 0..200, 20 wide (2 tows) on x 200..400.
    // Pad A at y 22, one tow (y 17..27): over the wide half it overlaps the base by 3 mm; pad B,
    // the same over the narrow half, misses it by 7 mm.
    let mut text = header();
    text.push_str("(PLY 1)\n");
    text.push_str(&course(1, 0.0, 0.0, 400.0));
    text.push_str("(PLY 2)\n");
    text.push_str(&one_tow(1, 22.0, 50.0, 150.0));
    text.push_str(&one_tow(2, 22.0, 250.0, 350.0));
    text.push_str(footer());
    let p = parse(&text, &m, &d).unwrap();
    let fps = footprints(&p, &m, Width::Tow(10.0)).unwrap();
    let half_widths: Vec<f64> = fps.courses[0].moves.iter().map(|q| q.hw).collect();
    assert_eq!(half_widths.len(), 2);
    assert!((half_widths[0] - (20.0 - OVERLAP_TOLERANCE / 2.0)).abs() < 1e-9, "{half_widths:?}");
    assert!((half_widths[1] - (10.0 - OVERLAP_TOLERANCE / 2.0)).abs() < 1e-9, "{half_widths:?}");
    let afp =
        build_problem(&p, &m, &d, &AfpOptions { width: Some(Width::Tow(10.0)), ..AfpOptions::default() }).unwrap();
    let preds = |t: u32| -> Vec<u32> {
        afp.problem.precedence().predecessors(towpath_seq::TaskId(t)).iter().map(|x| x.0).collect()
    };
    assert_eq!(preds(1), vec![0], "pad A overlaps the four-tow half");
    assert!(preds(2).is_empty(), "pad B lies beside the two-tow half");
    // A fixed course width does not narrow: then pad B overlaps too.
    let afp =
        build_problem(&p, &m, &d, &AfpOptions { width: Some(Width::Course(40.0)), ..AfpOptions::default() }).unwrap();
    assert_eq!(afp.problem.precedence().predecessors(towpath_seq::TaskId(2)).len(), 1);
}

/// "M61 P0 never occurs": a cut (or restart) of no tows is refused, naming the line.
#[test]
fn an_empty_tow_mask_is_refused_with_its_line() {
    let text = program();
    for (from, to) in [("M61 P3\n", "M61 P0\n"), ("M60 P15\n", "M60 P0\n")] {
        let bad = text.replacen(from, to, 1);
        let line = bad.lines().position(|l| l == to.trim_end()).unwrap() + 1;
        match parse(&bad, &gantry(), &Dialect::default()).unwrap_err() {
            NcError::Line { line: l, message } => {
                assert_eq!(l, line);
                assert!(message.contains("mask") && message.contains("≥ 1"), "{message}");
            }
            e => panic!("expected a line error, got {e}"),
        }
    }
}

/// "Within one ply, order is free unless the user asks to keep it": the optimizer reorders the
/// base ply when free, keeps its order when asked, and the verifier holds it to that.
#[test]
fn keep_ply_order_is_kept_and_verified() {
    let d = Dialect::default();
    let m = gantry();
    let text = program();
    let p = parse(&text, &m, &d).unwrap();
    let order_within = |order: &[Placement], ply: usize| -> Vec<usize> {
        order.iter().map(|pl| pl.course).filter(|&c| p.courses[c].ply == ply).collect()
    };
    let free = optimize(&text, &m, &d, &opts(false)).unwrap();
    assert_ne!(order_within(&free.order, 0), vec![0, 1, 2], "the base ply laid 0, 80, 40 is worth reordering");
    let mut kept = opts(false);
    kept.afp.keep_ply_order = true;
    let o = optimize(&text, &m, &d, &kept).unwrap();
    for (x, ply) in p.plies.iter().enumerate() {
        assert_eq!(order_within(&o.order, x), ply.courses, "ply {x}");
    }
    let strict = VerifyOptions { keep_ply_order: true, ..vopts() };
    verify(&text, &o.text, &m, &d, &strict).unwrap();
    let e = verify(&text, &free.text, &m, &d, &strict).unwrap_err();
    assert!(matches!(e, VerifyError::Order(_)), "{e}");
}

/// "The rewritten program keeps every on-part block byte-identical (or correctly reversed)":
/// every course laid forward in the output has its whole span (approach, on-part, retract)
/// line for line as in the input, and the lines towpath does not understand stay next to their
/// course.
#[test]
fn forward_spans_are_byte_identical_and_unknown_lines_stay_with_their_course() {
    let d = Dialect::default();
    let m = gantry();
    let text = program().replace('\n', "\r\n");
    let p = parse(&text, &m, &d).unwrap();
    for bi in [false, true] {
        let o = optimize(&text, &m, &d, &opts(bi)).unwrap();
        let out = parse(&o.text, &m, &d).unwrap();
        assert_eq!(o.verification.order, o.order);
        let mut forward = 0;
        for (k, pl) in o.order.iter().enumerate() {
            if pl.reversed {
                continue;
            }
            forward += 1;
            assert_eq!(out.lines[out.courses[k].span.clone()], p.lines[p.courses[pl.course].span.clone()]);
            // The coolant line after course 1 of the base still follows its retract.
            if pl.course == 0 {
                assert_eq!(out.lines[out.courses[k].span.end], "M8 (coolant, unknown to towpath)\r");
            }
        }
        assert!(forward > 0);
        if bi {
            assert!(o.verification.reversed > 0, "nothing reversed: the test shows only forward spans");
        }
    }
}

/// A mandrel on a controller that itself takes rotary axes the short way round
/// (`rollover = true`): the transit writes the next course's own value, with no
/// set-position line, and the machine turns 20°, not 340°.
#[test]
fn rollover_controller_gets_the_target_value_and_turns_the_short_way() {
    let m = Machine::new(
        "m",
        vec![Axis::new("X", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), Axis::new("A", AxisKind::Mandrel)],
    )
    .unwrap();
    let course = |n: usize, x: f64| {
        format!("(COURSE {n})\nG0 X{x} Z320 A10\nG1 Z300 F1000\nM20\nM60 P1\nG1 A350 F2000\nM61 P1\nM21\nG1 Z320\n")
    };
    let text = format!("G90\n(PLY 1)\n{}{}{}M30\n", course(1, 0.0), course(2, 100.0), course(3, 50.0));
    let d = Dialect { rollover: true, ..Dialect::default() };
    let o = optimize(&text, &m, &d, &opts(false)).unwrap();
    assert!(!o.text.contains("G92"), "{}", o.text);
    for l in o.text.lines().filter(|l| l.starts_with("G0") && l.contains('A')) {
        assert!(l.contains("A10") && !l.contains("A10."), "{l}: the target's own text");
    }
    let v = verify(&text, &o.text, &m, &d, &VerifyOptions::default()).unwrap();
    // The best order lays x 0, 50, 100: from home (X0 Z0 A0) 320 + 10 to the first start,
    // then twice 50 along X and 20° of mandrel (350° to 10°, the short way), plus 20 mm down
    // and up per course: 330 + 2 × 70 + 3 × 40 = 590. The input (x 0, 100, 50) costs 640. A
    // 340° unwind would add 640 at least.
    let (b, a) = v.motion(CostKind::Axis).unwrap();
    assert!((b.off_part() - 640.0).abs() < 1e-6, "{}", b.off_part());
    assert!((a.off_part() - 590.0).abs() < 1e-6, "{}", a.off_part());
    // Read as a roll-over controller reads it, the output reaches every course's start exactly.
    let out = parse(&o.text, &m, &d).unwrap();
    for (k, pl) in o.order.iter().enumerate() {
        let want = &o.program.courses[pl.course].span_start.phys;
        let got = &out.courses[k].span_start.phys;
        let da = (got[2] - want[2]).rem_euclid(360.0);
        assert!(da < 1e-9 || 360.0 - da < 1e-9, "course {k}: A {} vs {}", got[2], want[2]);
        assert!((got[0] - want[0]).abs() < 1e-9 && (got[1] - want[1]).abs() < 1e-9);
    }
}

/// "The report: totals and % saved ... per ply and per precedence set, and the new course
/// order; an HTML report with a before/after plan view": the per-ply and per-set figures add
/// up to the totals measured by the verifier, and the HTML page draws both programs.
#[test]
fn report_groups_add_up_and_the_html_draws_before_and_after() {
    let d = Dialect::default();
    let m = gantry();
    let text = program();
    let afp_opts = opts(true);
    let o = optimize(&text, &m, &d, &afp_opts).unwrap();
    let r = Report::new("t.nc", &m, &o, &afp_opts.afp);
    for t in &r.totals {
        let hf = r.header_footer.iter().find(|g| g.kind == t.kind).unwrap();
        for rows in [&r.per_ply, &r.per_set] {
            let (b, a) = rows
                .iter()
                .flat_map(|row| row.off_part.iter().filter(|g| g.kind == t.kind))
                .fold((hf.before, hf.after), |(b, a), g| (b + g.before, a + g.after));
            assert!((b - t.off_before).abs() < 1e-6 * (1.0 + b), "{}: {b} vs {}", t.kind, t.off_before);
            assert!((a - t.off_after).abs() < 1e-6 * (1.0 + a), "{}: {a} vs {}", t.kind, t.off_after);
        }
        assert!(
            t.total_before >= t.off_before
                && (t.total_before - t.off_before - (t.total_after - t.off_after)).abs() < 1e-6
        );
    }
    assert_eq!(r.per_ply.iter().map(|g| g.courses).sum::<usize>(), 5);
    assert_eq!(r.per_set.iter().map(|g| g.courses).sum::<usize>(), 5);
    let positions: Vec<usize> = r.order.iter().map(|x| x.original).collect();
    assert_eq!(positions, o.order.iter().map(|p| p.course + 1).collect::<Vec<_>>());
    let json = serde_json::to_value(&r).unwrap();
    for key in ["totals", "per_ply", "per_set", "order", "header_footer"] {
        assert!(json.get(key).is_some(), "{key}");
    }
    let optimized = parse(&o.text, &m, &d).unwrap();
    let html = r.to_html(&o, &optimized, &m);
    assert_eq!(html.matches("<svg").count(), 2, "one drawing before, one after");
    assert!(html.contains("before:") && html.contains("after:"));
    // Each drawing has as many laid polylines as the program has laid runs: five courses.
    assert!(html.matches("stroke=\"#999\"").count() >= 10);
    assert!(html.contains("Per ply") && html.contains("Per precedence set") && html.contains("New course order"));
}

/// The original order reproduces the program byte for byte even through `rewrite` with every
/// course placed forward explicitly (the round trip of the issue's Tests section).
#[test]
fn round_trip_of_this_file_s_program() {
    let d = Dialect::default();
    let text = program();
    let p = parse(&text, &gantry(), &d).unwrap();
    let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
    assert_eq!(rewrite(&p, &order, &gantry(), &d, &[]).unwrap(), text);
}
