//! AFP programs end to end, detail by detail (course footprints, reversal, rewriting, the
//! verifier's refusals, the report): what the other test files do not show on their own. Each test checks an outcome against an independent reading of the
//! program (its own text, its own geometry), not against a stored answer.

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

/// The default options for the gantry (cycle time: it has velocities).
fn opts(bidirectional: bool) -> OptimizeOptions {
    OptimizeOptions {
        afp: AfpOptions { bidirectional, width: Some(Width::Tow(10.0)), ..AfpOptions::for_machine(&gantry()) },
        // A work budget, not a time limit: the result depends only on the inputs.
        time_limit: None,
        iterations: Some(300),
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
    let mut axis = opts(false);
    axis.afp.cost = CostKind::Axis; // no velocities on this machine
    let o = optimize(&text, &m, &d, &axis).unwrap();
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
    assert!(html.matches("marker-end=").count() >= 10, "laid courses drawn with their direction arrows");
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

/// "Precedence: the seed-000 precedence network ...": when that rule is chosen, the verifier
/// (and so the optimizer's self-check) requires every course of a precedence set laid before
/// any course of the next, a stronger rule than the course-level one.
#[test]
fn verifier_keeps_seed_000_sets_in_order_when_asked() {
    let d = Dialect::default();
    let m = gantry();
    // Ply 1: two courses far apart (y 0 and y 200). Ply 2: one course over the first. The plies
    // intersect, so they are two sets; the pad needs only the course under it.
    let mut text = header();
    text.push_str("(PLY 1)\n");
    text.push_str(&course(1, 0.0, 0.0, 400.0));
    text.push_str(&course(2, 200.0, 0.0, 400.0));
    text.push_str("(PLY 2)\n");
    text.push_str(&course(1, 0.0, 100.0, 300.0));
    text.push_str(footer());
    let p = parse(&text, &m, &d).unwrap();
    let order: Vec<Placement> = [0, 2, 1].iter().map(|&c| Placement { course: c, reversed: false }).collect();
    let out = rewrite(&p, &order, &m, &d, &[]).unwrap();
    verify(&text, &out, &m, &d, &vopts()).unwrap();
    let sets = VerifyOptions { doherty_sets: true, ..vopts() };
    let e = verify(&text, &out, &m, &d, &sets).unwrap_err();
    assert!(matches!(&e, VerifyError::Order(msg) if msg.contains("set 1") && msg.contains("set 2")), "{e}");
    // The sets' order itself passes.
    verify(&text, &text, &m, &d, &sets).unwrap();
    // The optimizer under `--precedence sets` writes a program that keeps them.
    let mut o = opts(true);
    o.afp.precedence = towpath_nc::PrecedenceRule::Sets;
    let r = optimize(&text, &m, &d, &o).unwrap();
    assert_eq!(r.afp.sets.len(), 2);
    verify(&text, &r.text, &m, &d, &sets).unwrap();
    let last_of_first = r.order.iter().rposition(|pl| pl.course < 2).unwrap();
    let first_of_second = r.order.iter().position(|pl| pl.course == 2).unwrap();
    assert!(last_of_first < first_of_second);
}

/// A course whose on-part block turns through a clockwise half circle (`arc`): along x from
/// `x0` to `x0 + 100`, then round a centre 50 further on, bulging to `y + 50`.
fn arc_course(n: usize, y: f64, x0: f64, arc: &str) -> String {
    let x1 = x0 + 100.0;
    format!(
        "(COURSE {n})\nG0 X{x0} Y{y} Z20 C0\nG1 Z0 F1000\nM20\nM60 P3\nG1 X{x1} F3000\n{arc}\nM61 P3\nM21\nG1 Z20\n",
        arc = arc.replace("{x2}", &(x1 + 100.0).to_string()).replace("{y}", &y.to_string())
    )
}

fn arc_program(arc: &str) -> String {
    let mut s = header();
    s.push_str("(PLY 1)\n");
    s.push_str(&course(1, 0.0, 0.0, 400.0));
    s.push_str(&arc_course(2, 200.0, 0.0, arc));
    s.push_str(&course(3, 100.0, 0.0, 400.0));
    s.push_str("(PLY 2)\n");
    // Over the top of the arc only (the arc reaches y 250 at x 150; its chord stays at y 200).
    s.push_str(&one_tow(1, 250.0, 130.0, 170.0));
    s.push_str(&one_tow(2, 0.0, 300.0, 380.0));
    s.push_str(footer());
    s
}

/// G2/G3 arcs inside on-part blocks are on-part motion: parsed as the arc they describe (not
/// the chord), kept byte for byte, counted in footprints and costs, and only their course's
/// reversal is refused, naming the line.
#[test]
fn arcs_on_part_are_kept_as_written_and_refuse_only_reversal() {
    let d = Dialect::default();
    let m = gantry();
    let arc_line = "G2 X{x2} Y{y} I50 J0";
    let text = arc_program(arc_line);
    let written = "G2 X200 Y200 I50 J0";
    assert!(text.contains(written));
    let line = text.lines().position(|l| l == written).unwrap() + 1;
    let p = parse(&text, &m, &d).unwrap();
    // The arc's pieces lie on its circle (centre 150, 200; radius 50), clockwise over the top,
    // and each chord stays within a few micrometres of the arc.
    let pieces: Vec<_> = p.segments.iter().filter(|s| s.line as usize == line - 1).collect();
    assert!(pieces.len() > 10, "{}", pieces.len());
    let mut top: f64 = 0.0;
    for s in &pieces {
        assert!(s.on_part && s.mask == 3 && !s.rapid);
        let (a, b) = (p.point(s.from), p.point(s.to));
        for q in [a, b] {
            assert!(((q[0] - 150.0).hypot(q[1] - 200.0) - 50.0).abs() < 1e-9, "{q:?}");
            top = top.max(q[1]);
        }
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        assert!(50.0 - (mid[0] - 150.0).hypot(mid[1] - 200.0) < 0.005);
    }
    assert!((top - 250.0).abs() < 1e-6, "clockwise from the left goes over the top: {top}");
    // The footprint follows the arc: the pad over its top must come after it.
    let o = AfpOptions { width: Some(Width::Tow(10.0)), ..AfpOptions::default() };
    let afp = build_problem(&p, &m, &d, &o).unwrap();
    let preds: Vec<u32> = afp.problem.precedence().predecessors(towpath_seq::TaskId(3)).iter().map(|t| t.0).collect();
    assert_eq!(preds, vec![1]);
    // On-part tool distance: 100 straight + half of a circle of radius 50, to a few µm.
    let v = verify(&text, &text, &m, &d, &vopts()).unwrap();
    let (tool, _) = v.motion(CostKind::Tool).unwrap();
    let laid = 2.0 * 400.0 + 100.0 + 50.0 * std::f64::consts::PI + 40.0 + 80.0;
    assert!((tool.on_part - laid).abs() < 0.01, "{} vs {laid}", tool.on_part);
    // Optimized either way, the arc line is kept as written and the output verifies.
    for bi in [false, true] {
        let r = optimize(&text, &m, &d, &opts(bi)).unwrap();
        assert_eq!(r.text.lines().filter(|l| *l == written).count(), 1, "bi={bi}");
        assert!(r.order.iter().any(|pl| pl.course == 1 && !pl.reversed));
        verify(&text, &r.text, &m, &d, &vopts()).unwrap();
        if bi {
            let (c, why) = &r.afp.not_reversible[0];
            assert_eq!((*c, r.afp.not_reversible.len()), (1, 1));
            let why = why.to_string();
            assert!(why.contains(&format!("line {line}")) && why.contains("arc"), "{why}");
            assert!(r.verification.reversed > 0, "the other courses still reverse");
        }
    }
    // An arc turned the other way round (same ends, same centre) is other on-part motion.
    let r = optimize(&text, &m, &d, &opts(false)).unwrap();
    let flipped = r.text.replacen(written, "G3 X200 Y200 I50 J0", 1);
    let e = verify(&text, &flipped, &m, &d, &vopts()).unwrap_err();
    assert!(matches!(e, VerifyError::Unmatched { .. }), "{e}");
    // Reversing that course on purpose is refused, naming the line.
    let e = towpath_nc::reverse_course(&p, 1, &m, &d).unwrap_err().to_string();
    assert!(e.contains(&format!("line {line}")), "{e}");
}

/// The same arc given by its radius, and the long way round with a negative radius; a
/// counter-clockwise arc goes under; arcs that cannot be, or that are off-part, are refused
/// with their line.
#[test]
fn arc_forms_and_arc_errors() {
    let d = Dialect::default();
    let m = gantry();
    let points = |arc: &str| -> Vec<Vec<f64>> {
        let text = arc_program(arc);
        let p = parse(&text, &m, &d).unwrap();
        let line = p.lines.iter().position(|l| l.starts_with("G2 ") || l.starts_with("G3 ")).unwrap();
        p.segments.iter().filter(|s| s.line as usize == line).map(|s| p.point(s.to).to_vec()).collect()
    };
    let by_centre = points("G2 X{x2} Y{y} I50 J0");
    let by_radius = points("G2 X{x2} Y{y} R50");
    assert_eq!(by_centre.len(), by_radius.len());
    for (a, b) in by_centre.iter().zip(&by_radius) {
        assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
    }
    let under = points("G3 X{x2} Y{y} I50 J0");
    assert!(under.iter().all(|q| q[1] <= 200.0 + 1e-9) && under.iter().any(|q| q[1] < 151.0));
    // A quarter turn from (100, 200) to (150, 250): R50 short way (centre 150, 200), R-50 the
    // three-quarter way round (centre 100, 250).
    let short = points("G2 X150 Y250 R50");
    let long = points("G2 X150 Y250 R-50");
    assert!(long.len() > 2 * short.len());
    assert!(short.iter().all(|q| ((q[0] - 150.0).hypot(q[1] - 200.0) - 50.0).abs() < 1e-9));
    assert!(long.iter().all(|q| ((q[0] - 100.0).hypot(q[1] - 250.0) - 50.0).abs() < 1e-9));
    // A full circle back to the start.
    let full = points("G2 X100 Y{y} I50");
    assert!(
        full.iter().any(|q| q[0] > 199.99) && full.iter().any(|q| q[1] > 249.99) && full.iter().any(|q| q[1] < 150.01)
    );
    assert!(full.len() + 1 >= 2 * by_centre.len());
    for (arc, why) in [
        ("G2 X{x2} Y{y} I40 J0", "not on its circle"),
        ("G2 X{x2} Y{y}", "centre"),
        ("G2 X{x2} Y{y} R20", "shorter than half"),
        ("G2 X{x2} Y{y} R50 I50", "both"),
    ] {
        let text = arc_program(arc);
        let bad = arc.replace("{x2}", "200").replace("{y}", "200");
        let line = text.lines().position(|l| l == bad).unwrap() + 1;
        match parse(&text, &m, &d).unwrap_err() {
            NcError::Line { line: l, message } => {
                assert_eq!(l, line, "{arc}");
                assert!(message.contains(why), "{arc}: {message}");
            }
            e => panic!("{arc}: expected a line error, got {e}"),
        }
    }
    // Off-part (the approach written as an arc): refused, naming the line.
    let text = arc_program("G2 X{x2} Y{y} I50 J0").replacen("G1 Z0 F1000\n", "G1 Z0 F1000\nG3 X10 Y0 I5\n", 1);
    match parse(&text, &m, &d).unwrap_err() {
        NcError::Line { line, message } => {
            assert_eq!(text.lines().nth(line - 1), Some("G3 X10 Y0 I5"));
            assert!(message.contains("outside a course's on-part block"), "{message}");
        }
        e => panic!("expected a line error, got {e}"),
    }
    // A dialect without arcs refuses them as before.
    let no_arcs = Dialect { arc_cw: Vec::new(), arc_ccw: Vec::new(), ..Dialect::default() };
    let e = parse(&arc_program("G2 X{x2} Y{y} I50 J0"), &m, &no_arcs).unwrap_err();
    assert!(e.to_string().contains("G2 with axis words"), "{e}");
}

/// The arc plane is modal state like the others: a course whose arc relies on the XY plane,
/// laid after a course that switched to ZX, is entered with the plane restored, and without
/// that line the verifier sees a different arc.
#[test]
fn the_arc_plane_is_restored_before_a_course_that_relies_on_it() {
    let d = Dialect::default();
    let m = gantry();
    let mut text = header();
    text.push_str("(PLY 1)\n");
    text.push_str(&arc_course(1, 0.0, 0.0, "G2 X{x2} Y{y} I50 J0"));
    // Course 2 turns to the ZX plane for a hump over x 100..200 (counter-clockwise seen from +Y
    // goes up in Z).
    text.push_str(&arc_course(2, 300.0, 0.0, "G18\nG3 X{x2} Z0 I50 K0"));
    text.push_str(footer());
    let p = parse(&text, &m, &d).unwrap();
    let hump = p.segments.iter().filter(|s| p.lines[s.line as usize].starts_with("G3")).map(|s| p.point(s.to)[2]);
    assert!((hump.fold(0.0, f64::max) - 50.0).abs() < 1e-6);
    let order = [Placement { course: 1, reversed: false }, Placement { course: 0, reversed: false }];
    let out = rewrite(&p, &order, &m, &d, &[]).unwrap();
    let restore = out.lines().position(|l| l == "G17").expect("the XY plane is restored");
    let arc = out.lines().position(|l| l == "G2 X200 Y0 I50 J0").unwrap();
    let g18 = out.lines().position(|l| l == "G18").unwrap();
    assert!(g18 < restore && restore < arc, "{out}");
    verify(&text, &out, &m, &d, &vopts()).unwrap();
    let without: Vec<&str> = out.lines().filter(|l| *l != "G17").collect();
    let e = verify(&text, &without.join("\n"), &m, &d, &vopts()).unwrap_err();
    assert!(matches!(e, VerifyError::Unmatched { .. }), "{e}");
}

/// Courses with fewer approach or retract moves than the dialect's counts (the first course
/// laid from home with no move before it; courses joined by a single move, which the dialect
/// gives to the retract): moved elsewhere, such a course is preceded or followed by a
/// regenerated transit that, read again, counts as its approach or retract. The verifier
/// accepts that (it is off-part motion), and still checks everything laid. Found by the
/// `afp_program` fuzz target.
#[test]
fn courses_with_short_approach_or_retract_blocks_verify_when_moved() {
    let d = Dialect::default();
    let m = gantry();
    let lay = |y: f64| format!("M20\nM60 P1\nG1 X400 Y{y} F3000\nM61 P1\nM21\n");
    // Course 1 starts where the machine stands (home); each later course is reached by one
    // move, which is the previous course's retract; the last course has no retract.
    let mut text = String::from("G90\n(PLY 1)\n(COURSE 1)\nG1 F1000\n");
    text.push_str(&lay(0.0));
    for (n, y) in [(2, 80.0), (3, 40.0), (4, 120.0)] {
        text.push_str(&format!("G0 X0 Y{y} Z0\n(COURSE {n})\n"));
        text.push_str(&lay(y));
    }
    text.push_str("M30\n");
    let p = parse(&text, &m, &d).unwrap();
    assert_eq!(p.courses.len(), 4);
    assert!(p.courses.iter().all(|c| c.approach().is_empty()), "no course has an approach move");
    // Any order, forward or reversed: the rewrite verifies, and a changed laid point does not.
    let rev: Vec<_> = (0..4).map(|c| towpath_nc::reverse_course(&p, c, &m, &d).ok()).collect();
    assert!(rev.iter().all(Option::is_some));
    for order in [[(2, false), (0, false), (3, false), (1, false)], [(3, true), (1, false), (0, true), (2, true)]] {
        let order: Vec<Placement> = order.iter().map(|&(course, reversed)| Placement { course, reversed }).collect();
        let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
        let v = verify(&text, &out, &m, &d, &vopts()).unwrap();
        assert_eq!(v.order, order);
        let (b, a) = v.motion(CostKind::Axis).unwrap();
        assert!((a.on_part - b.on_part).abs() < 1e-9);
        let bad = out.replacen("X400 Y40", "X400 Y41", 1);
        assert_ne!(bad, out);
        assert!(verify(&text, &bad, &m, &d, &vopts()).is_err());
    }
    // Courses that all end where the next one's approach starts: moved, a course with no
    // retract is followed by no transit at all, and the next course's approach reads as its
    // retract. The approach is still checked, wherever it was read.
    let mut ends = String::from("G90\n(PLY 1)\n");
    for (n, y) in [(1, 0.0), (2, 40.0), (3, 80.0)] {
        ends.push_str(&format!("(COURSE {n})\nG0 X0 Y{y} Z20\nM20\nM60 P1\nG1 X300 Y0 F3000\nM61 P1\nM21\n"));
        if n < 3 {
            ends.push_str("G1 Z20\n");
        }
    }
    ends.push_str("M30\n");
    let p = parse(&ends, &m, &d).unwrap();
    assert!(p.courses[2].retract().is_empty());
    let order: Vec<Placement> = (0..3).rev().map(|course| Placement { course, reversed: false }).collect();
    let out = rewrite(&p, &order, &m, &d, &[]).unwrap();
    let v = verify(&ends, &out, &m, &d, &vopts()).unwrap();
    assert_eq!(v.order, order);
    let moved = out.replacen("G0 X0 Y40 Z20", "G0 X0 Y41 Z20", 1);
    assert_ne!(moved, out);
    assert!(verify(&ends, &moved, &m, &d, &vopts()).is_err(), "a changed approach is caught");
    // The optimizer's self-check accepts its own output too, in either dialect reading.
    for dialect in [d.clone(), Dialect { retract_moves: 0, ..Dialect::default() }] {
        for bi in [false, true] {
            let o = optimize(&text, &m, &dialect, &opts(bi)).unwrap();
            let v = verify(&text, &o.text, &m, &dialect, &vopts()).unwrap();
            let (b, a) = v.motion(CostKind::Axis).unwrap();
            assert!(a.off_part() <= b.off_part() + 1e-9);
        }
    }
}

/// A transit line with a comment: rewritten, the comment stays on a line of its own; in the
/// original order (or when the optimizer finds nothing cheaper and returns the input) the
/// transit line itself keeps it, and the program still verifies against itself. Found by the
/// `afp_program` fuzz target.
#[test]
fn comments_on_transit_lines_verify_in_the_original_order() {
    let d = Dialect::default();
    let m = gantry();
    let text = program().replacen("G0 X0 Y80 Z20 C0\n", "G0 X0 Y80 Z20 C0 (to course 2)\n", 1);
    assert_ne!(text, program());
    verify(&text, &text, &m, &d, &vopts()).unwrap();
    let o = optimize(&text, &m, &d, &opts(true)).unwrap();
    assert!(o.text.lines().any(|l| l == "(to course 2)"));
    verify(&text, &o.text, &m, &d, &vopts()).unwrap();
    // The original order is the input itself.
    let mut keep = opts(false);
    keep.afp.keep_ply_order = true;
    keep.afp.precedence = towpath_nc::PrecedenceRule::Plies;
    let single = format!("{}(PLY 1)\n{}{}", header(), course(1, 0.0, 0.0, 400.0), footer()).replacen(
        "G0 X0 Y0 Z20 C0\n",
        "G0 X0 Y0 Z20 C0 (first)\n",
        1,
    );
    let o = optimize(&single, &m, &d, &keep).unwrap();
    assert_eq!(o.text, single);
    // Losing the comment is still caught.
    let lost = o.text.replacen(" (first)", "", 1);
    assert!(matches!(verify(&single, &lost, &m, &d, &vopts()).unwrap_err(), VerifyError::LostLine { .. }));
}

/// A course that lays nothing (roller on and off, tows restarted and cut, at one point) with
/// no retract: reversed, its approach becomes its retract and the transit its approach; the
/// verifier anchors the comparison where its on-part block sits. Found by the fuzz target.
#[test]
fn a_course_that_lays_nothing_reverses_and_verifies() {
    let d = Dialect::default();
    let m = gantry();
    let text = format!(
        "G90\n(PLY 1)\n{}(COURSE 2)\nG0 X500 Y0 Z20 C0\nG1 Z0 F1000\nM20\nM60 P1\nM61 P1\nM21\nM30\n",
        course(1, 0.0, 0.0, 400.0)
    );
    let p = parse(&text, &m, &d).unwrap();
    assert_eq!(p.on_part_segments(1).count(), 0);
    let rev: Vec<_> = (0..2).map(|c| towpath_nc::reverse_course(&p, c, &m, &d).ok()).collect();
    for order in [[(1, true), (0, true)], [(1, true), (0, false)], [(0, true), (1, true)]] {
        let order: Vec<Placement> = order.iter().map(|&(course, reversed)| Placement { course, reversed }).collect();
        let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
        let v = verify(&text, &out, &m, &d, &vopts()).unwrap_or_else(|e| panic!("{order:?}: {e}\n{out}"));
        assert_eq!(v.order, order);
    }
    // The same with the plunge written on the contact line (the move comes first, so it is
    // not laid): reversed, the move comes after the lift.
    let plunge = text.replacen("G1 Z0 F1000\nM20\nM60 P1\nM61 P1", "G1 Z0 F1000 M20\nM60 P1\nM61 P1", 1);
    assert_ne!(plunge, text);
    let p2 = parse(&plunge, &m, &d).unwrap();
    let rev2: Vec<_> = (0..2).map(|c| towpath_nc::reverse_course(&p2, c, &m, &d).ok()).collect();
    for order in [[(1, true), (0, false)], [(0, false), (1, true)]] {
        let order: Vec<Placement> = order.iter().map(|&(course, reversed)| Placement { course, reversed }).collect();
        let out = rewrite(&p2, &order, &m, &d, &rev2).unwrap();
        let v = verify(&plunge, &out, &m, &d, &vopts()).unwrap_or_else(|e| panic!("{order:?}: {e}\n{out}"));
        assert_eq!(v.order, order);
    }
    // A third course with no move at all, right after the second: moved first and reversed,
    // the transit to it reads as its approach; its place is where its on-part block sits.
    let text = text.replacen("M30\n", "(COURSE 3)\nM20\nM21\nM30\n", 1);
    let p = parse(&text, &m, &d).unwrap();
    assert_eq!(p.courses.len(), 3);
    let rev: Vec<_> = (0..3).map(|c| towpath_nc::reverse_course(&p, c, &m, &d).ok()).collect();
    for order in [[(2, true), (1, true), (0, true)], [(2, false), (0, false), (1, false)]] {
        let order: Vec<Placement> = order.iter().map(|&(course, reversed)| Placement { course, reversed }).collect();
        let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
        let v = verify(&text, &out, &m, &d, &vopts()).unwrap_or_else(|e| panic!("{order:?}: {e}\n{out}"));
        // Two courses that lay nothing at the same point are interchangeable: only the course
        // that lays material must be where it was put.
        assert_eq!(v.order.iter().position(|p| p.course == 0), order.iter().position(|p| p.course == 0));
    }
}

/// A rapid move may not run while the roller is in contact (issue 17): such a program is refused
/// by the optimizer and the verifier alike, naming the line, whether `G0` is written on the
/// line or modal; outside contact rapids are as they were.
#[test]
fn rapid_moves_in_contact_are_refused() {
    let d = Dialect::default();
    let m = gantry();
    let odd = "(COURSE 2)\nG0 X0 Y100 Z20 C0\nG1 Z0 F1000\nM20\nM60 P1\nG0 X50\nF91\nG1 X100\nM61 P1\nM21\nG1 Z20\n";
    let text = format!("G90\n(PLY 1)\n{}{odd}M30\n", course(1, 0.0, 0.0, 400.0));
    let line = text.lines().position(|l| l == "G0 X50").unwrap() + 1;
    let e = parse(&text, &m, &d).unwrap_err().to_string();
    assert!(e.starts_with(&format!("line {line}: a rapid move (G0) while the roller is in contact")), "{e}");
    assert!(optimize(&text, &m, &d, &opts(true)).is_err());
    let good = text.replace("G0 X50", "G1 X50");
    parse(&good, &m, &d).unwrap();
    // The verifier reads the optimized program the same way: a rapid slipped in is refused.
    let e = verify(&good, &text, &m, &d, &vopts()).unwrap_err();
    assert!(matches!(&e, VerifyError::Optimized(NcError::Line { line: l, .. }) if *l == line), "{e}");
    // Modal: G0 set before contact, then a bare axis move in contact.
    let modal = good.replace("M20\nM60 P1\nG1 X50", "G0\nM20\nM60 P1\nX50");
    assert_ne!(modal, good);
    let e = parse(&modal, &m, &d).unwrap_err().to_string();
    assert!(e.contains("a rapid move (G0) while the roller is in contact"), "{e}");
    // Without contact codes: while tows are on.
    let d2 = Dialect { contact_on: String::new(), contact_off: String::new(), ..Dialect::default() };
    let no_contact = text.replace("M20\n", "").replace("M21\n", "");
    let e = parse(&no_contact, &m, &d2).unwrap_err().to_string();
    assert!(e.contains("a rapid move (G0) while tows are on (mask 1)"), "{e}");
    // Tow and contact codes written on the rapid's line take effect after it: "G0 X0 M20"
    // moves before contact, "G0 X0 M21" in contact.
    let after = good.replacen("G1 Z0 F1000\nM20\n", "G1 Z0 F1000\nG0 Z0 M20\n", 1);
    parse(&after, &m, &d).unwrap();
    let lift = good.replacen("M61 P1\nM21\n", "M61 P1\nG0 X100 M21\n", 1);
    assert!(parse(&lift, &m, &d).unwrap_err().to_string().contains("rapid move (G0) while the roller is in contact"));
}

/// Two courses that lay exactly the same, one with a retract move and one without: the
/// verifier must give the optimized course that has the retract to the original that needs
/// one. Found by the fuzz target.
#[test]
fn twin_courses_are_told_apart_by_their_retract() {
    let d = Dialect::default();
    let m = gantry();
    let lay = |n: usize, y: f64| format!("(COURSE {n})\nM20\nM60 P1\nG1 X100 Y{y} F3000\nG1 X0\nM61 P1\nM21\n");
    // A: laid from home with no approach, no retract. B: the same laying, then a
    // (zero-length) retract. C: elsewhere.
    let text = format!(
        "G90\n(PLY 1)\n{}{}G1 Z0\n(COURSE 3)\nG0 X0 Y50 Z0\n{}G1 Z0\nM30\n",
        lay(1, 0.0),
        lay(2, 0.0),
        lay(3, 50.0).replacen("(COURSE 3)\n", "", 1)
    );
    let p = parse(&text, &m, &d).unwrap();
    assert_eq!(p.courses.len(), 3);
    assert!(p.courses[0].approach().is_empty() && p.courses[0].retract().is_empty());
    assert!(p.courses[1].approach().is_empty() && !p.courses[1].retract().is_empty());
    let order: Vec<Placement> = [2, 1, 0].iter().map(|&course| Placement { course, reversed: false }).collect();
    let out = rewrite(&p, &order, &m, &d, &[]).unwrap();
    let v = verify(&text, &out, &m, &d, &vopts()).unwrap_or_else(|e| panic!("{e}\n{out}"));
    assert_eq!(v.order, order);
}

/// Inputs the `afp_program` fuzz target found (kept as they were, bytes and all): the program
/// written in reverse order, reversing what can be, verifies against the input; only
/// precedence may be left unchecked (there is no width). `look-alike-courses.nc` has several
/// courses that lay nothing at the same point with different approach and retract moves: the
/// verifier's greedy matching needs an augmenting path there; `repeated-contact-code.nc` has
/// a lift written twice on one line, which the reversal must swap twice;
/// `set-position-before-a-reversed-course.nc` a `G92` after a transit;
/// `no-op-lift-in-the-approach.nc` a lift code outside the on-part block.
#[test]
fn fuzz_regressions_verify() {
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    let mut a = Axis::new("A", AxisKind::Mandrel);
    a.weight = 2.0;
    let m = Machine::new(
        "fuzz",
        vec![
            Axis::new("X", AxisKind::Linear),
            Axis::new("Y", AxisKind::Linear),
            Axis::new("Z", AxisKind::Linear),
            c,
            a,
        ],
    )
    .unwrap();
    let d = Dialect::default();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_afp");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = String::from_utf8_lossy(&std::fs::read(&path).unwrap()).into_owned();
        let p = parse(&text, &m, &d).unwrap();
        let rev: Vec<_> = (0..p.courses.len()).map(|c| towpath_nc::reverse_course(&p, c, &m, &d).ok()).collect();
        let order: Vec<Placement> =
            (0..p.courses.len()).rev().map(|c| Placement { course: c, reversed: rev[c].is_some() }).collect();
        let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
        match verify(&text, &out, &m, &d, &VerifyOptions::default()) {
            Ok(_) | Err(VerifyError::Setup(_) | VerifyError::Precedence { .. }) => {}
            Err(e) => panic!("{}: {e}", path.display()),
        }
        n += 1;
    }
    assert!(n >= 1);
}

/// A set-position line after a course's transit (`G92 Z30`: the course is written in shifted
/// coordinates): laid reversed, that line runs before the new transit, which then reaches the
/// reversed course's entry in those coordinates. (Run after the new transit, as it was after
/// the old one, it declared the offset at the wrong place.) Found by the fuzz target.
#[test]
fn set_position_lines_before_a_reversed_course() {
    let d = Dialect::default();
    let m = gantry();
    let text = program().replacen("G0 X0 Y80 Z20 C0\n", "G0 X0 Y80 Z20 C0\nG92 Z30\n", 1);
    assert_ne!(text, program());
    let p = parse(&text, &m, &d).unwrap();
    assert!((p.courses[1].span_start.phys[2] - p.courses[1].span_start.prog[2] + 10.0).abs() < 1e-12);
    let rev: Vec<_> = (0..p.courses.len()).map(|c| towpath_nc::reverse_course(&p, c, &m, &d).ok()).collect();
    let order: Vec<Placement> = [(0, false), (1, true), (2, false), (3, false), (4, true)]
        .iter()
        .map(|&(course, reversed)| Placement { course, reversed })
        .collect();
    let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
    let v = verify(&text, &out, &m, &d, &vopts()).unwrap_or_else(|e| panic!("{e}\n{out}"));
    assert_eq!(v.order, order);
    let o = optimize(&text, &m, &d, &opts(true)).unwrap();
    verify(&text, &o.text, &m, &d, &vopts()).unwrap();
}

/// A lift code where the roller is already lifted (in an approach block) changes nothing;
/// swapped for a reversal it would put the roller down. Such a course is laid forward only,
/// and the report says why. Found by the fuzz target.
#[test]
fn contact_codes_outside_the_on_part_block_keep_a_course_forward() {
    let d = Dialect::default();
    let m = gantry();
    let text = program().replacen("G1 Z0 F1000\nM20\n", "G1 Z0 F1000\nM21 (make sure)\nM20\n", 1);
    assert_ne!(text, program());
    let p = parse(&text, &m, &d).unwrap();
    let e = towpath_nc::reverse_course(&p, 0, &m, &d).unwrap_err().to_string();
    assert!(e.contains("outside the on-part block"), "{e}");
    let o = optimize(&text, &m, &d, &opts(true)).unwrap();
    assert_eq!(o.afp.not_reversible.iter().map(|x| x.0).collect::<Vec<_>>(), vec![0]);
    assert!(o.order.iter().any(|pl| pl.course == 0 && !pl.reversed));
    verify(&text, &o.text, &m, &d, &vopts()).unwrap();
}

/// Motion time respects programmed feeds: rapids run at the axes' limits, feed moves at their
/// F (mm/min, or deg/min for rotary axes alone), each axis ramping at its acceleration. Every
/// figure below is worked out by hand for the demo gantry (X, Y: 1000 mm/s, 2000 mm/s²; Z: 500
/// mm/s, 1000 mm/s²; C: 180°/s, 720°/s²).
#[test]
fn motion_time_respects_programmed_feeds() {
    let m = towpath_nc::demo::gantry();
    let text =
        "%\nG21 G90\n(PLY 1)\n(COURSE 1)\nG0 X100 Y0 Z25 C0\nG1 Z0 F3000\nM20\nM60 P1\nG1 X400 F6000\nM61 P1\nM21\n\
                G1 Z25 F3000\nG1 C90 F1800\nG1 X500 C180 F6000\nM30\n";
    // Transit, a rapid from home: X 100 mm never reaches full speed, 2·√(100/2000) s; Z 25 mm
    // is quicker.
    let transit = 2.0 * (100.0f64 / 2000.0).sqrt();
    // Approach and retract: 25 mm at 50 mm/s, plus 50/1000 s of ramps.
    let z_move = 25.0 / 50.0 + 50.0 / 1000.0;
    // On-part: 300 mm at 100 mm/s plus 100/2000 s.
    let laid = 3.0 + 100.0 / 2000.0;
    // Footer: C alone, 90° at 30°/s plus 30/720 s; then X 100 mm at 100 mm/s with C 90° in step
    // (C cruises at 90°/s: 1 + 90/720 s, slower than X's 1 + 100/2000 s).
    let footer = (3.0 + 30.0 / 720.0) + (1.0 + 90.0 / 720.0);
    for (dialect, text) in [
        (Dialect::default(), text.to_string()),
        (
            Dialect { feed_unit: towpath_nc::FeedUnit::PerSecond, ..Dialect::default() },
            text.replace("F3000", "F50").replace("F6000", "F100").replace("F1800", "F30"),
        ),
    ] {
        let v = verify(&text, &text, &m, &dialect, &VerifyOptions::default()).unwrap();
        let (before, after) = v.motion(CostKind::Time).unwrap();
        assert_eq!(before, after);
        assert!((before.off_course[0] - (transit + 2.0 * z_move)).abs() < 1e-9, "{:?}", before);
        assert!((before.on_part - laid).abs() < 1e-9, "{:?}", before);
        assert!((before.off_other - footer).abs() < 1e-9, "{:?}", before);
        // The distance costs do not depend on feeds: seed 000's axis cost is Σ C(a)·|Δa|.
        let (axis, _) = v.motion(CostKind::Axis).unwrap();
        assert!((axis.on_part - 300.0).abs() < 1e-9 && (axis.off_course[0] - 175.0).abs() < 1e-9, "{axis:?}");
    }
}

/// `clearance = { axis = "Z", value = 50 }`: every transit towpath writes goes up to Z50, moves
/// the other axes there, and comes down to where the next course's approach starts; X, Y and C
/// never move below the clearance between courses. The optimized program verifies, and its
/// measured off-part motion is what the solver priced.
#[test]
fn transits_go_by_way_of_the_clearance() {
    let text = program();
    let d = Dialect { clearance: Some(towpath_nc::Clearance { axis: "z".into(), value: 50.0 }), ..Dialect::default() };
    // Axis distance on a machine without velocities: every transit written up to Z50 and down
    // takes longer than the program's own direct ones, so with a time model the cycle-time
    // guard would keep the input order here (as it must) and nothing would be rewritten.
    let mut m = gantry();
    for a in &mut m.axes {
        a.max_velocity = None;
        a.max_acceleration = None;
    }
    let mut axis = opts(true);
    axis.afp.cost = CostKind::Axis;
    let o = optimize(&text, &m, &d, &axis).unwrap();
    assert!(!o.fell_back && o.order.iter().enumerate().any(|(i, p)| p.course != i || p.reversed));
    let out = parse(&o.text, &m, &d).unwrap();
    let regions = out.regions();
    let mut transit_moves = vec![0; out.courses.len()];
    for s in &out.segments {
        let towpath_nc::Region::Middle(k) = regions[s.line as usize] else { continue };
        transit_moves[k] += 1;
        let (a, b) = (out.point(s.from), out.point(s.to));
        let sideways = (0..4).any(|i| i != 2 && (a[i] - b[i]).abs() > 1e-9);
        if sideways {
            assert!(a[2] == 50.0 && b[2] == 50.0, "line {}: {:?} -> {:?}", s.line + 1, a, b);
        }
        assert!(s.rapid, "line {}", s.line + 1);
    }
    // Up, across, down: three moves (one, straight down, where only Z changes).
    assert!(transit_moves.iter().all(|&n| n == 1 || n == 3), "{transit_moves:?}\n{}", o.text);
    assert!(transit_moves.iter().filter(|&&n| n == 3).count() >= 4, "{transit_moves:?}\n{}", o.text);
    let (before, after) = o.verification.motion(CostKind::Axis).unwrap();
    assert!(after.off_part() <= before.off_part());
    let measured: f64 = after.off_course.iter().sum();
    let route = towpath_seq::check(
        &o.afp.problem,
        &o.order
            .iter()
            .map(|p| towpath_seq::Step { task: towpath_seq::TaskId(p.course as u32), mode: p.reversed as u32 })
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert!((measured - route).abs() < 1e-6, "measured {measured}, solver {route}");
    verify(&text, &o.text, &gantry(), &d, &vopts()).unwrap();
    // The clearance axis must be a linear axis of the machine.
    for (axis, says) in
        [("Q", "clearance.axis: the machine has no axis \"Q\""), ("C", "clearance.axis: C is not a linear axis")]
    {
        let d =
            Dialect { clearance: Some(towpath_nc::Clearance { axis: axis.into(), value: 50.0 }), ..Dialect::default() };
        let e = parse(&text, &gantry(), &d).unwrap_err().to_string();
        assert!(e.contains(says), "{e}");
    }
    let e = Dialect::from_toml_str("clearance = { axis = \"Z\", value = nan }").unwrap_err().to_string();
    assert!(e.contains("clearance.value"), "{e}");
    let e = Dialect::from_toml_str("clearance = { axis = \"Z\", height = 50.0 }").unwrap_err().to_string();
    assert!(e.contains("unknown field `height`"), "{e}");
    let d = Dialect::from_toml_str("clearance = { axis = \"Z\", value = 50.0 }").unwrap();
    assert_eq!(Dialect::from_toml_str(&d.to_toml_string()).unwrap(), d);
}
