//! Hand-written programs: round trips, optimization, the verifier catching broken programs,
//! and bad input refused with the line named.

use towpath_machine::{Axis, AxisKind, CostKind, Machine};
use towpath_nc::{
    build_problem, optimize, parse, reverse_course, rewrite, verify, AfpOptions, Dialect, NcError, OptimizeOptions,
    Placement, PrecedenceRule, VerifyError, VerifyOptions, Width,
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

/// One course along x at height y from x0 to x1, with a tow event pattern.
fn course(n: usize, y: f64, x0: f64, x1: f64) -> String {
    let xm = (x0 + x1) / 2.0;
    format!(
        "(COURSE {n})\nG0 X{x0} Y{y} Z20 C0\nG1 Z0 F1000\nM20\nM60 P15\nG1 X{xm} F3000 (middle)\nM61 P3\nG1 X{x1}\nM61 P12\nM21\nG1 Z20\n"
    )
}

/// Two plies: a base of three courses and a pad-up of two courses over its middle, laid badly.
fn program() -> String {
    let mut s = String::from("%\nO1234 (test part)\nG21 G90\nG0 Z100\n");
    s.push_str("(PLY 1 base)\n");
    s.push_str(&course(1, 0.0, 0.0, 400.0));
    s.push_str("M8 (coolant, unknown to towpath)\n");
    s.push_str(&course(2, 40.0, 0.0, 400.0));
    s.push_str(&course(3, 80.0, 0.0, 400.0));
    s.push_str("(PLY 2 pad)\n");
    s.push_str(&course(1, 40.0, 300.0, 380.0));
    s.push_str(&course(2, 80.0, 300.0, 380.0));
    s.push_str("(END)\nG0 Z100\nM30\n%\n");
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

#[test]
fn structure_is_read() {
    let p = parse(&program(), &gantry(), &Dialect::default()).unwrap();
    assert_eq!(p.plies.len(), 2);
    assert_eq!(p.plies[0].courses, vec![0, 1, 2]);
    assert_eq!(p.plies[1].number, Some(2));
    assert_eq!(p.courses[3].number, Some(1));
    // Header: up to the first marker; footer: after the last retract.
    assert_eq!(p.lines[p.header_end], "(PLY 1 base)");
    assert_eq!(p.lines[p.footer_start], "(END)");
    // Approach = the plunge; retract = the lift; on-part = M20..M21.
    let c = &p.courses[0];
    assert_eq!(p.lines[c.span.start], "G1 Z0 F1000");
    assert_eq!(p.lines[c.on_part.start], "M20");
    assert_eq!(p.lines[c.on_part.end - 1], "M21");
    assert_eq!(p.lines[c.span.end - 1], "G1 Z20");
    // The unknown line after course 1 stays with course 1 (before course 2's marker).
    assert!(matches!(p.courses[0].post[..], [towpath_nc::Item::Line(j)] if p.lines[j].starts_with("M8")));
    // Laid moves carry the tows on.
    let masks: Vec<u64> = p.on_part_segments(0).map(|s| s.mask).collect();
    assert_eq!(masks, vec![15, 12]);
}

#[test]
fn original_order_reproduces_the_program_exactly() {
    let d = Dialect::default();
    for text in [program(), program().replace('\n', "\r\n"), program().trim_end().to_string()] {
        let p = parse(&text, &gantry(), &d).unwrap();
        let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        assert_eq!(rewrite(&p, &order, &gantry(), &d, &[]).unwrap(), text);
    }
}

#[test]
fn optimized_program_verifies_keeps_lines_and_saves() {
    let d = Dialect::default();
    let text = program();
    for bi in [false, true] {
        let o = optimize(&text, &gantry(), &d, &opts(bi)).unwrap();
        for keep in ["O1234 (test part)", "M8 (coolant, unknown to towpath)", "(END)", "M30", "(middle)"] {
            assert!(o.text.contains(keep), "{keep} lost");
        }
        let v = verify(&text, &o.text, &gantry(), &d, &vopts()).unwrap();
        let (b, a) = v.motion(CostKind::Time).unwrap();
        assert!(a.off_part() < b.off_part(), "bi={bi}: {} -> {} s", b.off_part(), a.off_part());
        if bi {
            assert!(v.reversed > 0);
        }
        // On-part motion is the same, whichever direction.
        assert!((a.on_part - b.on_part).abs() < 1e-6);
    }
}

#[test]
fn reversal_swaps_events_and_turns_the_heading() {
    let d = Dialect::default();
    let p = parse(&program(), &gantry(), &d).unwrap();
    let r = reverse_course(&p, 0, &gantry(), &d).unwrap();
    assert_eq!(r.shift, 180.0);
    assert_eq!(r.entry.prog, vec![400.0, 0.0, 20.0, 180.0]);
    let text = r.lines.join("\n");
    // The retract, reversed, is the approach: down at the far end; tows restarted in reverse
    // order of their cuts, at the same points, with the comment kept on its move.
    assert_eq!(text, "G1 Z0 F1000\nM20\nM60 P12\nX200 F3000\nM60 P3\nX0 (middle)\nM61 P15\nM21\nZ20");
}

fn optimized(bi: bool) -> (String, String) {
    let text = program();
    let o = optimize(&text, &gantry(), &Dialect::default(), &opts(bi)).unwrap();
    (text, o.text)
}

#[test]
fn verifier_catches_a_dropped_course() {
    let (orig, out) = optimized(false);
    let p = parse(&out, &gantry(), &Dialect::default()).unwrap();
    let span = p.courses[2].span.clone();
    let broken: Vec<&str> = out.lines().enumerate().filter(|(i, _)| !span.contains(i)).map(|(_, l)| l).collect();
    let e = verify(&orig, &broken.join("\n"), &gantry(), &Dialect::default(), &vopts()).unwrap_err();
    assert!(matches!(e, VerifyError::CourseCount { got: 4, expected: 5 }), "{e}");
}

#[test]
fn verifier_catches_a_changed_on_part_point() {
    let (orig, out) = optimized(false);
    let broken = out.replacen("G1 X400\n", "G1 X400.5\n", 1);
    assert_ne!(broken, out);
    let e = verify(&orig, &broken, &gantry(), &Dialect::default(), &vopts()).unwrap_err();
    assert!(matches!(e, VerifyError::Unmatched { .. }), "{e}");
}

#[test]
fn verifier_catches_a_broken_precedence() {
    let d = Dialect::default();
    let p = parse(&program(), &gantry(), &d).unwrap();
    // The pad-up's first course (over base courses 2 and 3) first.
    let order: Vec<Placement> = [3, 0, 1, 2, 4].iter().map(|&c| Placement { course: c, reversed: false }).collect();
    let out = rewrite(&p, &order, &gantry(), &d, &[]).unwrap();
    let e = verify(&program(), &out, &gantry(), &d, &vopts()).unwrap_err();
    assert!(matches!(e, VerifyError::Precedence { .. }), "{e}");
    // Laying it after the base but before the rest of its own ply is fine.
    let order: Vec<Placement> = [0, 1, 2, 4, 3].iter().map(|&c| Placement { course: c, reversed: false }).collect();
    let out = rewrite(&p, &order, &gantry(), &d, &[]).unwrap();
    verify(&program(), &out, &gantry(), &d, &vopts()).unwrap();
    // Strict ply order rejects interleaving plies.
    let order: Vec<Placement> = [0, 1, 3, 2, 4].iter().map(|&c| Placement { course: c, reversed: false }).collect();
    let out = rewrite(&p, &order, &gantry(), &d, &[]).unwrap();
    let strict = VerifyOptions { strict_plies: true, ..vopts() };
    assert!(matches!(verify(&program(), &out, &gantry(), &d, &strict).unwrap_err(), VerifyError::Order(_)));
}

#[test]
fn verifier_catches_illegal_reversals() {
    let d = Dialect::default();
    let p = parse(&program(), &gantry(), &d).unwrap();
    let rev: Vec<_> = (0..p.courses.len()).map(|c| reverse_course(&p, c, &gantry(), &d).ok()).collect();
    let order: Vec<Placement> = [(0, true), (1, false), (2, false), (3, false), (4, false)]
        .iter()
        .map(|&(course, reversed)| Placement { course, reversed })
        .collect();
    let good = rewrite(&p, &order, &gantry(), &d, &rev).unwrap();
    verify(&program(), &good, &gantry(), &d, &vopts()).unwrap();
    // Restart and cut not swapped: the tows would be on where the original had them off.
    let no_swap = good.replacen("M60 P12", "M61 P12", 1).replacen("M61 P15", "M60 P15", 1);
    assert!(parse(&no_swap, &gantry(), &d).is_err() || verify(&program(), &no_swap, &gantry(), &d, &vopts()).is_err());
    // Events moved: restart the 3 tows one point late.
    let moved = good.replacen("M60 P3\nX0", "X0\nM60 P3", 1);
    assert_ne!(moved, good);
    let e = verify(&program(), &moved, &gantry(), &d, &vopts());
    assert!(e.is_err(), "moved tow event accepted");
    // Heading not turned.
    let mut r0 = rev[0].clone().unwrap();
    r0.entry.prog[3] = 0.0;
    r0.entry.phys[3] = 0.0;
    r0.entry.text[3] = towpath_nc::NumText::new("0");
    let mut rev2 = rev.clone();
    rev2[0] = Some(r0);
    let bad = rewrite(&p, &order, &gantry(), &d, &rev2).unwrap();
    let e = verify(&program(), &bad, &gantry(), &d, &vopts()).unwrap_err();
    assert!(e.to_string().contains("axis C"), "{e}");
}

/// Approach and retract moves keep their motion code and feed, forward and reversed (the
/// reversed approach takes the original approach's): a roller brought down at a rapid, or at
/// another feed, is refused even though the laid motion is the same.
#[test]
fn verifier_catches_an_approach_at_a_rapid_or_another_feed() {
    let d = Dialect::default();
    let (orig, out) = optimized(false);
    verify(&orig, &out, &gantry(), &d, &vopts()).unwrap();
    for broken in [
        out.replacen("G1 Z0 F1000\nM20\n", "G0 Z0\nG1 F1000\nM20\n", 1),
        out.replacen("G1 Z0 F1000\nM20\n", "G1 Z0 F9000\nM20\n", 1),
    ] {
        assert_ne!(broken, out);
        let e = verify(&orig, &broken, &gantry(), &d, &vopts()).unwrap_err();
        assert!(matches!(e, VerifyError::Unmatched { .. }), "{e}");
        assert!(e.to_string().contains("(off-part)"), "{e}");
    }
    // Course 1 first and reversed: its approach (the original retract run backwards) must take
    // the original approach's G1 F1000.
    let p = parse(&orig, &gantry(), &d).unwrap();
    let rev: Vec<_> = (0..p.courses.len()).map(|c| reverse_course(&p, c, &gantry(), &d).ok()).collect();
    let order: Vec<Placement> = (0..5).map(|c| Placement { course: c, reversed: c == 0 }).collect::<Vec<_>>();
    let good = rewrite(&p, &order, &gantry(), &d, &rev).unwrap();
    verify(&orig, &good, &gantry(), &d, &vopts()).unwrap();
    let plunge = good.replacen("G1 Z0 F1000\nM20\nM60 P12\n", "G0 Z0\nG1\nM20\nM60 P12\n", 1);
    assert_ne!(plunge, good);
    let e = verify(&orig, &plunge, &gantry(), &d, &vopts()).unwrap_err();
    assert!(e.to_string().contains("a rapid instead of feed 1000"), "{e}");
}

#[test]
fn precedence_needs_a_width_and_says_so() {
    let d = Dialect::default();
    let p = parse(&program(), &gantry(), &d).unwrap();
    let e = build_problem(&p, &gantry(), &d, &AfpOptions::default()).unwrap_err();
    assert!(matches!(e, NcError::NeedsWidth { plies: 2, checking: false }), "{e}");
    assert!(e.to_string().contains("needs course footprints, so a course or tow width"), "{e}");
    assert!(!e.to_string().contains("--"), "the library names no command-line flag: {e}");
    // Ply-by-ply precedence needs none.
    let o = AfpOptions { precedence: PrecedenceRule::Plies, ..AfpOptions::default() };
    build_problem(&p, &gantry(), &d, &o).unwrap();
    // The dialect may carry it.
    let d2 = Dialect { course_width: Some(40.0), ..Dialect::default() };
    build_problem(&p, &gantry(), &d2, &AfpOptions::default()).unwrap();
}

#[test]
fn course_precedence_of_the_test_part() {
    let d = Dialect::default();
    let p = parse(&program(), &gantry(), &d).unwrap();
    let o = AfpOptions { width: Some(Width::Tow(10.0)), ..AfpOptions::default() };
    let afp = build_problem(&p, &gantry(), &d, &o).unwrap();
    // Base courses at y 0, 40, 80 are 40 wide (4 tows): y ±20. The pad courses at y 40 and 80
    // overlap base courses 2 and 3 only (base 1 at y −20..20 just touches pad 1 at 20..60).
    let prec = afp.problem.precedence();
    let preds = |t: u32| {
        let mut v: Vec<u32> = prec.predecessors(towpath_seq::TaskId(t)).iter().map(|x| x.0).collect();
        v.sort();
        v
    };
    assert_eq!(preds(3), vec![1]);
    assert_eq!(preds(4), vec![2]);
    assert_eq!(afp.sets.len(), 2);
}

fn err_line(text: &str) -> (usize, String) {
    match parse(text, &gantry(), &Dialect::default()).unwrap_err() {
        NcError::Line { line, message } => (line, message),
        e => panic!("expected a line error, got {e}"),
    }
}

#[test]
fn bad_input_is_refused_with_the_line() {
    let good = program();
    let with = |from: &str, to: &str| {
        assert!(good.contains(from));
        good.replacen(from, to, 1)
    };
    let (l, m) = err_line(&with("G1 X200 F3000", "G1 X200 W5 F3000"));
    assert_eq!(l, 11);
    assert!(m.contains("unknown axis W"), "{m}");
    let (l, m) = err_line(&with("M20\nM60 P15", "M20\nM61 P15"));
    assert_eq!(l, 10);
    assert!(m.contains("no tows on"), "{m}");
    let (l, m) = err_line(&format!("{}(COURSE 9)\nG0 X0 Y0 Z10\nM20\nG1 X10 F100\n", good.trim_end_matches("%\n")));
    assert!(m.contains("never closed"), "{m}");
    // The M20 of the appended course: the line that opened it.
    assert_eq!(l, good.lines().count() + 2);
    // A course whose lift is missing runs into a footer line towpath cannot read inside a
    // course: the message names the course's opening line too.
    let lifts: Vec<usize> = good.lines().enumerate().filter(|(_, l)| *l == "M21").map(|(i, _)| i).collect();
    let last_lift = *lifts.last().unwrap();
    let opened = good.lines().take(last_lift).enumerate().filter(|(_, l)| *l == "M20").map(|(i, _)| i).last().unwrap();
    let cut: Vec<&str> = good.lines().enumerate().filter(|(i, _)| *i != last_lift).map(|(_, l)| l).collect();
    let (l, m) = err_line(&(cut.join("\n") + "\n"));
    // The footer's rapid G0 Z100, now in contact: refused, naming the course.
    let rapid = cut.iter().rposition(|l| *l == "G0 Z100").unwrap() + 1;
    assert_eq!(l, rapid, "{m}");
    assert!(m.contains("a rapid move (G0) while the roller is in contact"), "{m}");
    assert!(
        m.contains(&format!("inside the course opened at line {}", opened + 1)) && m.contains("M21 is missing"),
        "{m}"
    );
    let (l, m) = err_line(&with("G1 X200 F3000", "G1 Xnan F3000"));
    assert_eq!(l, 11);
    assert!(m.contains("no number"), "{m}");
    let (_, m) = err_line(&with("G1 X200 F3000", "G1 X200000000000 F3000"));
    assert!(m.contains("range"), "{m}");
    // Exponent notation is not G-code: `X1e308` would read as X1 and a word E308.
    let (l, m) = err_line(&with("G1 X200 F3000", "G1 X1e308 F3000"));
    assert_eq!(l, 11);
    assert!(m.contains("X1e308: exponent notation is not G-code (it reads as X1 and a word e308)"), "{m}");
    let (_, m) = err_line(&with("G1 X200 F3000", "G1 X200 F3E3"));
    assert!(m.contains("F3E3: exponent notation"), "{m}");
    let (_, m) = err_line(&with("M21\n", "M60 P1\nM21\n"));
    assert!(m.contains("tows still on"), "{m}");
    let (l, m) = err_line(&with("M60 P15\n", "M60 P15\nM60 P4\n"));
    assert_eq!(l, 11);
    assert!(m.contains("already on"), "{m}");
    let (_, m) = err_line(&with("(PLY 2 pad)\n", "M20\n(PLY 2 pad)\n"));
    assert!(m.contains("never closed"), "{m}");
    assert!(matches!(
        parse("G0 X1\n", &gantry(), &Dialect::default()).unwrap_err(),
        NcError::Request(m) if m.contains("no courses")
    ));
}

#[test]
fn dialect_without_contact_codes() {
    let d = Dialect { contact_on: String::new(), contact_off: String::new(), ..Dialect::default() };
    let text = program().replace("M20\n", "").replace("M21\n", "");
    let p = parse(&text, &gantry(), &d).unwrap();
    assert_eq!(p.courses.len(), 5);
    // The on-part block runs from the first restart to the last cut.
    assert!(p.lines[p.courses[0].on_part.start].starts_with("M60"));
    assert!(p.lines[p.courses[0].on_part.end - 1].starts_with("M61 P12"));
    let o = optimize(&text, &gantry(), &d, &opts(true)).unwrap();
    verify(&text, &o.text, &gantry(), &d, &vopts()).unwrap();
}

#[test]
fn incremental_blocks_are_entered_in_their_mode() {
    // Course 2's on-part motion is written incrementally.
    let text = program().replacen(
        "(COURSE 2)\nG0 X0 Y40 Z20 C0\nG1 Z0 F1000\nM20\nM60 P15\nG1 X200 F3000 (middle)\nM61 P3\nG1 X400\n",
        "(COURSE 2)\nG0 X0 Y40 Z20 C0\nG1 Z0 F1000\nM20\nG91\nM60 P15\nG1 X200 F3000 (middle)\nM61 P3\nG1 X200\nG90\n",
        1,
    );
    assert_ne!(text, program());
    let d = Dialect::default();
    for bi in [false, true] {
        let o = optimize(&text, &gantry(), &d, &opts(bi)).unwrap();
        verify(&text, &o.text, &gantry(), &d, &vopts()).unwrap();
    }
}

#[test]
fn time_and_tool_costs() {
    let d = Dialect::default();
    for cost in [CostKind::Time, CostKind::Tool] {
        let mut o = opts(true);
        o.afp.cost = cost;
        let r = optimize(&program(), &gantry(), &d, &o).unwrap();
        let (b, a) = r.verification.motion(cost).unwrap();
        assert!(a.off_part() < b.off_part(), "{cost}");
    }
}

/// A mandrel machine: courses around the mandrel end near 350° and start near 10°; the
/// rewritten transits go the short way and re-declare the programmed value.
#[test]
fn mandrel_moves_the_short_way_round() {
    let mut a = Axis::new("A", AxisKind::Mandrel);
    a.weight = 1.0;
    let m = Machine::new("m", vec![Axis::new("X", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), a]).unwrap();
    let course = |n: usize, a0: f64, a1: f64, x: f64| {
        format!("(COURSE {n})\nG0 X{x} Z320 A{a0}\nG1 Z300 F1000\nM20\nM60 P1\nG1 A{a1} F2000\nM61 P1\nM21\nG1 Z320\n")
    };
    let text = format!(
        "G90\n(PLY 1)\n{}{}{}M30\n",
        course(1, 10.0, 350.0, 0.0),
        course(2, 10.0, 350.0, 100.0),
        course(3, 10.0, 350.0, 50.0)
    );
    let d = Dialect::default();
    let mut axis = opts(false);
    axis.afp.cost = CostKind::Axis; // no velocities on this machine
    let o = optimize(&text, &m, &d, &axis).unwrap();
    // From 350° to the next start at 10°: +20°, written as A370, then declared A10.
    assert!(o.text.contains("A370\nG92 A10"), "{}", o.text);
    let v = verify(&text, &o.text, &m, &d, &VerifyOptions::default()).unwrap();
    let (b, a) = v.motion(CostKind::Axis).unwrap();
    // The original unwinds 340° between courses twice; the rewrite turns 20° instead.
    assert!(b.off_part() - a.off_part() > 2.0 * 300.0, "{} -> {}", b.off_part(), a.off_part());
}

/// A two-link arm (shoulder U, elbow V), a vertical slide W and a heading C: the tool point
/// comes from the DH chain, and footprints, precedence and the tool cost follow it.
#[test]
fn robot_with_a_dh_chain() {
    use towpath_machine::DhJoint;
    let (l1, l2) = (700.0, 500.0);
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    let mut m = Machine::new(
        "arm",
        vec![Axis::new("U", AxisKind::Rotary), Axis::new("V", AxisKind::Rotary), Axis::new("W", AxisKind::Linear), c],
    )
    .unwrap();
    m.dh = vec![
        DhJoint { a: 0.0, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("W".into()) },
        DhJoint { a: l1, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("U".into()) },
        DhJoint { a: l2, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("V".into()) },
    ];
    m.validate().unwrap();
    // Inverse kinematics of the arm (elbow down) for a point in the plane.
    let ik = |x: f64, y: f64| {
        let c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
        let q2 = c2.clamp(-1.0, 1.0).acos();
        let q1 = y.atan2(x) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
        (q1.to_degrees(), q2.to_degrees())
    };
    let w = |x: f64, y: f64, z: f64| {
        let (u, v) = ik(x, y);
        format!("U{:.4} V{:.4} W{z}", u, v)
    };
    let course = |n: usize, y: f64, x0: f64, x1: f64| {
        let mut s = format!("(COURSE {n})\nG0 {} C0\nG1 {} F1000\nM20\nM60 P3\n", w(x0, y, 20.0), w(x0, y, 0.0));
        for k in 1..=4 {
            let x = x0 + (x1 - x0) * k as f64 / 4.0;
            s.push_str(&format!("G1 {} F2000\n", w(x, y, 0.0)));
        }
        s.push_str(&format!("M61 P3\nM21\nG1 {} F1000\n", w(x1, y, 20.0)));
        s
    };
    let text = format!(
        "G90\n(PLY 1)\n{}{}{}(PLY 2)\n{}M30\n",
        course(1, 300.0, 400.0, 800.0),
        course(2, 340.0, 400.0, 800.0),
        course(3, 380.0, 400.0, 800.0),
        course(1, 340.0, 500.0, 700.0)
    );
    let d = Dialect::default();
    let p = parse(&text, &m, &d).unwrap();
    // The DH chain puts the first laid point where the inverse kinematics aimed.
    let pts = p.part_points(&m).unwrap();
    let first = pts[p.on_part_segments(0).next().unwrap().from as usize];
    assert!((first[0] - 400.0).abs() < 1e-2 && (first[1] - 300.0).abs() < 1e-2, "{first:?}");
    let o = AfpOptions { width: Some(Width::Course(40.0)), cost: CostKind::Tool, ..AfpOptions::default() };
    let afp = build_problem(&p, &m, &d, &o).unwrap();
    // The pad course (y 340, 40 wide) overlaps only base course 2 (y 340).
    let preds: Vec<u32> = afp.problem.precedence().predecessors(towpath_seq::TaskId(3)).iter().map(|t| t.0).collect();
    assert_eq!(preds, vec![1]);
    let mut opts = opts(true);
    opts.afp = AfpOptions { bidirectional: true, ..o };
    let r = optimize(&text, &m, &d, &opts).unwrap();
    let (b, a) = r.verification.motion(CostKind::Tool).unwrap();
    assert!(a.off_part() < b.off_part());
}

#[test]
fn other_approach_and_retract_counts() {
    for (approach, retract) in [(0, 0), (2, 0), (0, 2), (3, 3)] {
        let d = Dialect { approach_moves: approach, retract_moves: retract, ..Dialect::default() };
        let text = program();
        let p = parse(&text, &gantry(), &d).unwrap();
        let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        assert_eq!(rewrite(&p, &order, &gantry(), &d, &[]).unwrap(), text);
        let o = optimize(&text, &gantry(), &d, &opts(true)).unwrap();
        verify(&text, &o.text, &gantry(), &d, &vopts()).unwrap();
    }
}

#[test]
fn verifier_refuses_truncated_and_foreign_programs_without_panicking() {
    let d = Dialect::default();
    let text = program();
    let v = |other: &str| verify(&text, other, &gantry(), &d, &vopts());
    assert!(matches!(v("").unwrap_err(), VerifyError::Optimized(_)));
    assert!(v("(PLY 1)\nG0 X0 Y0 Z20 C0\nM20\nM21\n").is_err());
    let (_, out) = optimized(true);
    let cut: Vec<&str> = out.lines().take(out.lines().count() - 2).collect();
    assert!(matches!(v(&cut.join("\n")).unwrap_err(), VerifyError::LostLine { .. }));
}
