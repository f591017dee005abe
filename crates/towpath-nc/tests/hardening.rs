//! Issue 17 ("hardening"), the AFP program classes, one test (or a few) per class: mandrel
//! programs laid on or near the mandrel axis; codes inside a course that a reversal must keep
//! meaning the same; the verifier accounting for every line; precedence ply by ply without
//! widths, widths checked against the part and the dialect; line ends. Each test checks what
//! comes out against the program text read on its own, not against a stored answer.

use std::collections::BTreeMap;

use towpath_machine::{Axis, AxisKind, Machine};
use towpath_nc::demo::{demo_parts, TOW_WIDTH};
use towpath_nc::{
    build_problem, optimize, parse, reverse_course, rewrite, verify, AfpOptions, Dialect, Irreversible, NcError,
    OptimizeOptions, Placement, PrecedenceRule, Program, Report, Switch, VerifyError, VerifyOptions, Width,
    WidthSource,
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

/// A course along x at height y with `inside` written after the tow restart and `before_lift`
/// before the last cut (heater codes, say).
fn course(n: usize, y: f64, x0: f64, x1: f64, inside: &str, before_cut: &str) -> String {
    let xm = (x0 + x1) / 2.0;
    format!(
        "(COURSE {n})\nG0 X{x0} Y{y} Z20 C0\nG1 Z0 F1000\nM20\nM60 P15\n{inside}G1 X{xm} F3000\nM61 P3\nG1 X{x1}\n{before_cut}M61 P12\nM21\nG1 Z20\n"
    )
}

/// Two plies laid badly, every course with the given lines inside.
fn program(inside: &str, before_cut: &str) -> String {
    let mut s = String::from("%\nG21 G90\nG0 Z100\n(PLY 1 base)\n");
    for (n, y) in [(1, 0.0), (2, 40.0), (3, 80.0)] {
        s.push_str(&course(n, y, 0.0, 400.0, inside, before_cut));
    }
    s.push_str("(PLY 2 pad)\n");
    for (n, y) in [(1, 40.0), (2, 80.0)] {
        s.push_str(&course(n, y, 300.0, 380.0, inside, before_cut));
    }
    s.push_str("(END)\nG0 Z100\nM30\n%\n");
    s
}

fn opts(bidirectional: bool) -> OptimizeOptions {
    OptimizeOptions {
        afp: AfpOptions { bidirectional, width: Some(Width::Tow(10.0)), ..AfpOptions::default() },
        time_limit: None,
        iterations: Some(400),
        threads: 1,
        ..OptimizeOptions::default()
    }
}

fn vopts() -> VerifyOptions {
    VerifyOptions { width: Some(Width::Tow(10.0)), ..VerifyOptions::default() }
}

/// For every laid move (tows on), keyed by its two end points (X, Y, Z) whatever the direction, the codes
/// switched on while it is laid, found by reading the text line by line: `on` codes add,
/// `off` codes remove (each with the words written after it).
fn switched_on_along_laid_moves(text: &str, p: &Program, pairs: &[(&str, &str)]) -> BTreeMap<String, Vec<String>> {
    let mut state: Vec<String> = Vec::new();
    let mut at_line: Vec<Vec<String>> = Vec::new();
    for line in &p.lines {
        at_line.push(state.clone());
        let words: Vec<&str> = line.split('(').next().unwrap_or("").split_whitespace().collect();
        if let Some(first) = words.first() {
            let rest = words[1..].join(" ");
            for (on, off) in pairs {
                if first == on {
                    state.push(rest.clone());
                } else if first == off {
                    state.retain(|x| *x != rest);
                }
            }
        }
    }
    assert_eq!(text.lines().count(), p.lines.len());
    let mut out = BTreeMap::new();
    for s in p.segments.iter().filter(|s| s.on_part && s.mask != 0) {
        // X, Y and Z: a reversed course has its heading C turned half a turn.
        let key = |i: u32| p.point(i)[..3].iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>().join(",");
        let (a, b) = (key(s.from), key(s.to));
        let k = if a < b { format!("{a}|{b}") } else { format!("{b}|{a}") };
        let mut on = at_line[s.line as usize].clone();
        on.sort();
        let _ = out.insert(k, on);
    }
    out
}

/// A mandrel program laid on or near the mandrel axis (the radial axis at 0 or 0.0001 during
/// contact) is refused where footprints are needed, naming the first laid move's line and the
/// mandrel axis, not unrolled at a made-up radius (exit 0 with every footprint overlapping) nor
/// left to run out of memory. The bound is the course width / 2π, checked on both sides of it.
#[test]
fn laid_points_on_or_near_the_mandrel_axis_are_refused() {
    let d = Dialect::default();
    let part = demo_parts().into_iter().find(|p| p.name == "cylinder-base-3-pads").unwrap();
    // The radial axis Z is 400 on the part and 425 off it.
    assert!(part.program.contains("Z400 ") && part.program.contains("Z425 "));
    let opts = AfpOptions { width: Some(Width::Tow(TOW_WIDTH)), ..AfpOptions::default() };
    for z in ["0", "0.0001"] {
        let text = part.program.replace("Z400 ", &format!("Z{z} "));
        let p = parse(&text, &part.machine, &d).unwrap();
        // The first laid move: the first move line after the first tow restart.
        let lines: Vec<&str> = text.lines().collect();
        let restart = lines.iter().position(|l| l.starts_with("M60")).unwrap();
        let first_laid = restart + lines[restart..].iter().position(|l| l.starts_with("G1")).unwrap() + 1;
        let e = build_problem(&p, &part.machine, &d, &opts).unwrap_err();
        match &e {
            NcError::MandrelAxis { line, radius, label, origin, .. } => {
                assert_eq!(*line, first_laid, "{e}");
                assert!(*radius <= 1e-4 + 1e-9, "{e}");
                assert_eq!((label.as_str(), *origin), ("A", [0.0; 3]));
            }
            other => panic!("{other}"),
        }
        assert!(e.to_string().contains("origin and direction of the machine's mandrel axis A"), "{e}");
        // The verifier builds the same footprints and refuses the same way.
        let v =
            verify(&text, &text, &part.machine, &d, &VerifyOptions { width: opts.width, ..VerifyOptions::default() });
        assert!(matches!(v, Err(VerifyError::Setup(NcError::MandrelAxis { .. }))), "{v:?}");
        // Ply by ply needs no footprints, so nothing is unrolled and nothing refused.
        let plies = AfpOptions { precedence: PrecedenceRule::Plies, ..opts.clone() };
        build_problem(&p, &part.machine, &d, &plies).unwrap();
    }
    // Either side of width / 2π with a fixed course width of 50.8 mm (8.085 mm).
    let w = 50.8;
    let bound = w / std::f64::consts::TAU;
    let fixed = AfpOptions { width: Some(Width::Course(w)), ..AfpOptions::default() };
    for (z, ok) in [(bound * 1.01, true), (bound * 0.99, false)] {
        let text = part.program.replace("Z400 ", &format!("Z{z:.4} "));
        let p = parse(&text, &part.machine, &d).unwrap();
        assert_eq!(build_problem(&p, &part.machine, &d, &fixed).is_ok(), ok, "z {z}");
    }
}

/// Codes inside a course that the dialect does not describe keep the course forward, with the
/// line named in the report; declared as a switch, they keep their meaning reversed: every
/// laid stretch runs with the heater on exactly as in the original, read back from the
/// output's own text. The same with a dialect without contact codes.
#[test]
fn codes_inside_a_course_keep_their_meaning() {
    let m = gantry();
    let heater = program("M8 (heater on)\n", "M9 (heater off)\n");
    let no_contact_text = heater.replace("M20\n", "").replace("M21\n", "");
    let no_contact = Dialect { contact_on: String::new(), contact_off: String::new(), ..Dialect::default() };
    for (text, base) in [(heater.clone(), Dialect::default()), (no_contact_text, no_contact)] {
        // Undeclared: forward only, and said so.
        let p = parse(&text, &m, &base).unwrap();
        let m8 = p.lines.iter().position(|l| l.starts_with("M8")).unwrap() + 1;
        match reverse_course(&p, 0, &m, &base).unwrap_err() {
            Irreversible::Undescribed { line, words } => assert_eq!((line, words.as_str()), (m8, "M8")),
            other => panic!("{other}"),
        }
        let o = optimize(&text, &m, &base, &opts(true)).unwrap();
        assert_eq!(o.verification.reversed, 0);
        assert_eq!(o.afp.not_reversible.len(), 5);
        let r = Report::new("heater.nc", &m, &o, &opts(true).afp);
        assert!(r.warnings.iter().any(|w| w.contains("5 courses are laid forward only")), "{:?}", r.warnings);
        // Declared as a switch: reversed, with the heater on along the same laid stretches.
        let d = Dialect { switches: vec![Switch { on: "M8".into(), off: "M9".into() }], ..base.clone() };
        let o = optimize(&text, &m, &d, &opts(true)).unwrap();
        assert!(o.verification.reversed > 0);
        let pairs = [("M8", "M9")];
        let before = switched_on_along_laid_moves(&text, &parse(&text, &m, &d).unwrap(), &pairs);
        let after = switched_on_along_laid_moves(&o.text, &parse(&o.text, &m, &d).unwrap(), &pairs);
        assert!(before.values().all(|on| on.len() == 1), "{before:?}");
        assert_eq!(before, after);
        // The reversal the issue found (heater off at the start, on at the end): refused.
        let reversed = o.order.iter().position(|pl| pl.reversed).unwrap();
        let out = parse(&o.text, &m, &d).unwrap();
        let span = out.courses[reversed].span.clone();
        let mut lines: Vec<String> = o.text.lines().map(str::to_string).collect();
        let on = span.clone().find(|&j| lines[j].starts_with("M8")).unwrap();
        let off = span.clone().find(|&j| lines[j].starts_with("M9")).unwrap();
        lines.swap(on, off);
        let wrong = lines.join("\n") + "\n";
        for dialect in [&d, &base] {
            let e = verify(&text, &wrong, &m, dialect, &vopts()).unwrap_err();
            assert!(matches!(e, VerifyError::Unmatched { .. }), "{e}");
        }
        verify(&text, &o.text, &m, &d, &vopts()).unwrap();
    }
}

/// Switches pair up by the words written with their codes (`M64 P3` with `M65 P3`), even
/// interleaved; a point code stays at its point; a switch left on keeps the course forward.
#[test]
fn switches_pair_by_their_words_and_point_codes_stay_at_their_point() {
    let m = gantry();
    let d = Dialect {
        switches: vec![Switch { on: "M64".into(), off: "M65".into() }],
        point_codes: vec!["M0".into()],
        ..Dialect::default()
    };
    // P3 on over the whole laying, P4 from the first cut: on P3, on P4, off P3, off P4.
    let text = program("M64 P3\nM0 (check)\n", "M65 P3\n")
        .replace("M61 P3\n", "M61 P3\nM64 P4\n")
        .replace("M61 P12\nM21\n", "M61 P12\nM65 P4\nM21\n");
    let p = parse(&text, &m, &d).unwrap();
    let order: Vec<Placement> = (0..5).map(|c| Placement { course: c, reversed: true }).collect();
    let rev: Vec<_> = (0..5).map(|c| Some(reverse_course(&p, c, &m, &d).unwrap())).collect();
    let out = rewrite(&p, &order, &m, &d, &rev).unwrap();
    let pairs = [("M64", "M65")];
    let q = parse(&out, &m, &d).unwrap();
    assert_eq!(switched_on_along_laid_moves(&text, &p, &pairs), switched_on_along_laid_moves(&out, &q, &pairs));
    // M0 at the same machine point: where the move before it ends (read from each text).
    let points = |p: &Program| {
        let mut v: Vec<String> = (0..p.lines.len())
            .filter(|&j| p.lines[j].starts_with("M0"))
            .map(|j| {
                let s = p.segments.iter().rev().find(|s| (s.line as usize) < j).unwrap();
                // X, Y, Z: the heading C turns half a turn reversed.
                p.point(s.to)[..3].iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(",")
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(points(&p).len(), 5);
    assert_eq!(points(&p), points(&q));
    verify(&text, &out, &m, &d, &vopts()).unwrap();
    // A switch left on at the end of the course: forward only.
    let left_on = text.replacen("M65 P4\n", "", 1);
    let p = parse(&left_on, &m, &d).unwrap();
    assert!(matches!(reverse_course(&p, 0, &m, &d), Err(Irreversible::Switch { .. })));
}

/// A switch turned on between courses and left on for the courses after it would run other
/// courses with it on in another order: the optimizer refuses, naming the line, and the
/// verifier refuses an order that changes which switches a course runs with. Turned off again
/// around one course (or in the header and footer), the courses may move.
#[test]
fn switches_left_on_between_courses_are_refused() {
    let m = gantry();
    let d = Dialect { switches: vec![Switch { on: "M8".into(), off: "M9".into() }], ..Dialect::default() };
    // Switched on before course 2 of ply 1 (travelling with it), never off.
    let text = program("", "").replacen("(COURSE 2)\n", "(COURSE 2)\nM8 (heater on)\n", 1);
    let line = text.lines().position(|l| l.starts_with("M8")).unwrap() + 1;
    let e = optimize(&text, &m, &d, &opts(true)).unwrap_err();
    assert!(
        matches!(&e, NcError::Line { line: l, message } if *l == line && message.contains("leaves a switch on")),
        "{e}"
    );
    // Course 1 (in the original laid with the heater off) moved after course 2: refused.
    let p = parse(&text, &m, &d).unwrap();
    let order: Vec<Placement> = [1, 0, 2, 3, 4].iter().map(|&course| Placement { course, reversed: false }).collect();
    let out = rewrite(&p, &order, &m, &d, &[]).unwrap();
    let e = verify(&text, &out, &m, &d, &vopts()).unwrap_err();
    assert!(matches!(&e, VerifyError::Order(w) if w.contains("switches")), "{e}");
    // Switched off again after course 2 (before the next course's comment, so travelling with
    // course 2 too): the courses may move, and that order verifies.
    let balanced = text.replacen("(COURSE 3)\n", "M9 (heater off)\n(COURSE 3)\n", 1);
    let o = optimize(&balanced, &m, &d, &opts(true)).unwrap();
    verify(&balanced, &o.text, &m, &d, &vopts()).unwrap();
    let p = parse(&balanced, &m, &d).unwrap();
    verify(&balanced, &rewrite(&p, &order, &m, &d, &[]).unwrap(), &m, &d, &vopts()).unwrap();
}

/// The verifier accounts for every line: a stop or a dwell slipped into a course, a line slipped
/// between courses or after the footer, a kept line dropped or doubled, a footer line dropped,
/// each named by its own line (the extra footer line no longer reported as a different line
/// missing).
#[test]
fn the_verifier_accounts_for_every_line() {
    let m = gantry();
    let d = Dialect::default();
    let text = program("", "").replacen("(COURSE 2)\n", "M8 (coolant, unknown to towpath)\n(COURSE 2)\n", 1);
    let p = parse(&text, &m, &d).unwrap();
    let order: Vec<Placement> = [(0, false), (2, true), (1, false), (3, true), (4, false)]
        .iter()
        .map(|&(course, reversed)| Placement { course, reversed })
        .collect();
    let rev: Vec<_> = (0..5).map(|c| reverse_course(&p, c, &m, &d).ok()).collect();
    let written = rewrite(&p, &order, &m, &d, &rev).unwrap();
    let out: Vec<String> = written.lines().map(str::to_string).collect();
    let q = parse(&written, &m, &d).unwrap();
    let (fwd, rev) = (2, 1);
    let with = |at: usize, line: &str| {
        let mut v = out.clone();
        v.insert(at, line.to_string());
        v.join("\n") + "\n"
    };
    let without = |at: usize| {
        let mut v = out.clone();
        v.remove(at);
        v.join("\n") + "\n"
    };
    let extra = |t: &str| match verify(&text, t, &m, &d, &vopts()) {
        Err(VerifyError::ExtraLine { line, text, .. }) => (line, text),
        other => panic!("{other:?}"),
    };
    // Into a forward course's on-part block, after its tow restart.
    let at = q.courses[fwd].on_part.start + 2;
    assert_eq!(extra(&with(at, "M0")), (at + 1, "M0".to_string()));
    assert_eq!(extra(&with(at, "G4 P5000")), (at + 1, "G4 P5000".to_string()));
    // Into a reversed course: no longer a legal reversal.
    let at = q.courses[rev].on_part.start + 2;
    let e = verify(&text, &with(at, "M0"), &m, &d, &vopts()).unwrap_err();
    assert!(
        matches!(&e, VerifyError::Unmatched { detail, .. } if detail.contains(&format!("optimized line {} (\"M0\")", at + 1))),
        "{e}"
    );
    // Between two courses (before the second course's comment).
    let at = out.iter().position(|l| l.starts_with("(COURSE")).unwrap() + 1;
    let at = at + out[at..].iter().position(|l| l.starts_with("(COURSE")).unwrap();
    assert_eq!(extra(&with(at, "M0")), (at + 1, "M0".to_string()));
    // After the footer: that line, not a footer line reported missing.
    let n = out.len();
    match verify(&text, &with(n, "M0"), &m, &d, &vopts()).unwrap_err() {
        VerifyError::ExtraLine { line, text, place } => {
            assert_eq!((line, text.as_str()), (n + 1, "M0"));
            assert!(place.contains("after the original's footer"), "{place}");
        }
        e => panic!("{e}"),
    }
    // A kept line dropped: named by its original line; doubled: the copy named.
    let kept = out.iter().position(|l| l.starts_with("M8")).unwrap();
    let original_line = text.lines().position(|l| l.starts_with("M8")).unwrap() + 1;
    match verify(&text, &without(kept), &m, &d, &vopts()).unwrap_err() {
        VerifyError::LostLine { line, .. } => assert_eq!(line, original_line),
        e => panic!("{e}"),
    }
    assert_eq!(extra(&with(kept + 1, &out[kept])).0, kept + 2);
    // A footer line dropped: that one.
    let m30 = out.iter().rposition(|l| l == "M30").unwrap();
    match verify(&text, &without(m30), &m, &d, &vopts()).unwrap_err() {
        VerifyError::LostLine { line, text: t } => {
            assert_eq!((line, t.as_str()), (text.lines().position(|l| l == "M30").unwrap() + 1, "M30"))
        }
        e => panic!("{e}"),
    }
    // The output itself verifies.
    verify(&text, &written, &m, &d, &vopts()).unwrap();
}

/// Ply by ply needs no widths (the README says so, and the verifier no longer asks for them);
/// the output lays every ply after the one before, checked here from the order alone.
#[test]
fn ply_by_ply_needs_no_widths() {
    let m = gantry();
    let d = Dialect::default();
    let text = program("", "");
    let mut o = opts(true);
    o.afp = AfpOptions { bidirectional: true, precedence: PrecedenceRule::Plies, ..AfpOptions::default() };
    let r = optimize(&text, &m, &d, &o).unwrap();
    assert!(r.verification.ply_order_checked && !r.verification.precedence_checked);
    assert_eq!(r.width.source, WidthSource::Default);
    let plies: Vec<usize> = r.order.iter().map(|p| r.program.courses[p.course].ply).collect();
    assert!(plies.windows(2).all(|w| w[0] <= w[1]), "{plies:?}");
    let strict = VerifyOptions { strict_plies: true, ..VerifyOptions::default() };
    verify(&text, &r.text, &m, &d, &strict).unwrap();
    // Without a width and without ply by ply, the verifier still needs footprints.
    let e = verify(&text, &r.text, &m, &d, &VerifyOptions::default()).unwrap_err();
    assert!(matches!(e, VerifyError::Setup(NcError::NeedsWidth { checking: true, .. })), "{e}");
    assert!(e.to_string().contains("ply-by-ply precedence needs none"), "{e}");
}

/// A width wider than the part (1e20) is refused rather than optimized into a program its own
/// verifier rejects; a width at the size of the part is optimized and verifies; a width given
/// far from the dialect's is used, with a warning in the result and the report.
#[test]
fn widths_are_checked_against_the_part_and_the_dialect() {
    let m = gantry();
    let text = program("", "");
    let d = Dialect::default();
    let mut o = opts(false);
    o.afp.width = Some(Width::Course(1e20));
    assert!(matches!(optimize(&text, &m, &d, &o).unwrap_err(), NcError::ImplausibleWidth { .. }));
    // The laid paths span (0, 0)–(400, 80): a course as wide as that is accepted.
    o.afp.width = Some(Width::Course((400.0f64 * 400.0 + 80.0 * 80.0).sqrt()));
    let r = optimize(&text, &m, &d, &o).unwrap();
    verify(&text, &r.text, &m, &d, &VerifyOptions { width: o.afp.width, ..VerifyOptions::default() }).unwrap();
    // An inch user's tow width beside a dialect in mm: used, with a warning.
    let dialect = Dialect { tow_width: Some(6.35), ..Dialect::default() };
    o.afp.width = Some(Width::Tow(0.25));
    let r = optimize(&text, &m, &dialect, &o).unwrap();
    assert_eq!((r.width.source, r.width.width), (WidthSource::Given, Some(Width::Tow(0.25))));
    let w = r.width.warning.clone().unwrap();
    assert!(w.contains("25.4 times narrower") && w.contains("inches"), "{w}");
    let report = Report::new("p.nc", &m, &r, &o.afp);
    assert!(report.warnings.contains(&w) && report.summary().contains("width: tow width 0.25 mm"));
    let v = verify(&text, &r.text, &m, &dialect, &VerifyOptions { width: o.afp.width, ..VerifyOptions::default() })
        .unwrap();
    assert_eq!(v.width.warning, Some(w));
    // The dialect's own width: no warning, and it says where it came from.
    o.afp.width = None;
    let r = optimize(&text, &m, &dialect, &o).unwrap();
    assert_eq!((r.width.source, r.width.warning.is_none()), (WidthSource::Dialect, true));
    assert!(Report::new("p.nc", &m, &r, &o.afp).summary().contains("(from the dialect)"));
}

/// A program with CR line ends is read like the same program with LF ones and written back
/// with CR line ends; a CR in the middle of an LF line (mixed line ends) is refused, naming it.
#[test]
fn cr_line_ends_are_read_and_kept() {
    let m = gantry();
    let d = Dialect::default();
    let lf = program("", "");
    let cr = lf.replace('\n', "\r");
    let (a, b) = (parse(&lf, &m, &d).unwrap(), parse(&cr, &m, &d).unwrap());
    assert_eq!((a.courses.len(), a.plies.len(), a.lines.clone()), (b.courses.len(), b.plies.len(), b.lines.clone()));
    let identity: Vec<Placement> = (0..b.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
    assert_eq!(rewrite(&b, &identity, &m, &d, &[]).unwrap(), cr);
    let (x, y) = (optimize(&lf, &m, &d, &opts(true)).unwrap(), optimize(&cr, &m, &d, &opts(true)).unwrap());
    assert!(!y.text.contains('\n') && y.verification.reversed > 0);
    assert_eq!(y.text, x.text.replace('\n', "\r"));
    verify(&cr, &y.text, &m, &d, &vopts()).unwrap();
    // CRLF stays CRLF.
    let crlf = lf.replace('\n', "\r\n");
    let z = optimize(&crlf, &m, &d, &opts(true)).unwrap();
    assert_eq!(z.text, x.text.replace('\n', "\r\n"));
    // Mixed: a CR alone between two moves of an LF program.
    let mixed = lf.replacen("G1 Z0 F1000\nM20\n", "G1 Z0 F1000\rM20\n", 1);
    let line = lf.lines().position(|l| l == "G1 Z0 F1000").unwrap() + 1;
    let e = parse(&mixed, &m, &d).unwrap_err().to_string();
    assert!(e.starts_with(&format!("line {line}: a carriage return (CR) in the middle of the line")), "{e}");
    // A CR inside a comment is part of the comment.
    parse(&lf.replacen("(END)", "(E\rND)", 1), &m, &d).unwrap();
}

/// Arcs whose chords would take more memory than towpath allows are refused, naming the line
/// where the budget runs out (full circles of radius 10⁶ mm take 4096 chords each).
#[test]
fn arcs_past_the_chord_budget_are_refused() {
    let m = gantry();
    let d = Dialect::default();
    let circles = "G2 I1000000 J0\n".repeat(300);
    let text = format!("G90\n(PLY 1)\nG0 X0 Y0 Z0 C0\nM20\nM60 P1\nG1 X1 F100\n{circles}M61 P1\nM21\nM30\n");
    let e = parse(&text, &m, &d).unwrap_err().to_string();
    // 1,000,000 chords: the 245th circle (4096 chords each) passes the budget.
    let line = 6 + 1_000_000 / 4096 + 1;
    assert!(e.starts_with(&format!("line {line}: the program's arcs need more than 1000000 chords")), "{e}");
    parse(&text.replace(&circles, &"G2 I1000000 J0\n".repeat(200)), &m, &d).unwrap();
}
