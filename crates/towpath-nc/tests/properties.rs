//! Property tests over generated programs: exact round trips (LF, CRLF and CR line ends); any
//! feasible order, with any legal reversals, rewrites into a program the independent verifier
//! accepts and whose measured off-part motion is the solver's route cost; heater switches keep
//! their laid stretches under any order; the verifier notices any line removed or slipped in;
//! the optimizer never returns a dearer program; the parser never panics.

use proptest::prelude::*;
use towpath_machine::{Axis, AxisKind, CostKind, Machine};
use towpath_nc::{
    build_problem, optimize, parse, reverse_course, rewrite, verify, AfpOptions, Clearance, Dialect, Irreversible,
    OptimizeOptions, Placement, Switch, VerifyOptions, Width,
};
use towpath_seq::{check, Step, TaskId};

fn machine() -> Machine {
    let mut c = Axis::new("C", AxisKind::Continuous);
    c.heading = true;
    c.weight = 0.2;
    let mut axes =
        vec![Axis::new("X", AxisKind::Linear), Axis::new("Y", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), c];
    for a in &mut axes {
        a.max_velocity = Some(400.0);
        a.max_acceleration = Some(800.0);
    }
    Machine::new("prop", axes).unwrap()
}

#[derive(Clone, Debug)]
struct CourseSpec {
    x: f64,
    y: f64,
    angle: f64,
    len: f64,
    points: usize,
    heading: f64,
    mask: u64,
    mid_cut: Option<(usize, u64)>,
    extra: u8,
    /// The last on-part move is a clockwise arc (radius = its chord), which cannot be reversed.
    arc: bool,
    /// A heater switched on after the tow restart and off before the last cut (`M8`, `M9`).
    heater: bool,
}

#[derive(Clone, Debug)]
struct PartSpec {
    plies: Vec<Vec<CourseSpec>>,
    course_markers: bool,
    /// Line ends: 0 LF, 1 CRLF, 2 CR.
    ends: u8,
    final_newline: bool,
}

fn course_spec() -> impl Strategy<Value = CourseSpec> {
    (
        (0.0f64..300.0, 0.0f64..300.0, 0.0f64..std::f64::consts::TAU, 20.0f64..250.0),
        (
            1usize..5,
            0u32..3600,
            1u64..16,
            proptest::option::of((0usize..4, 1u64..16)),
            0u8..4,
            proptest::bool::weighted(0.2),
            proptest::bool::weighted(0.3),
        ),
    )
        .prop_map(|((x, y, angle, len), (points, h, mask, mid, extra, arc, heater))| CourseSpec {
            x: (x * 1000.0).round() / 1000.0,
            y: (y * 1000.0).round() / 1000.0,
            angle,
            len,
            points,
            heading: h as f64 / 10.0,
            mask,
            // A cut of some (not all) of the tows on, at an inner point.
            mid_cut: mid.and_then(|(at, cut)| {
                let c = cut & mask;
                (points > 1 && c != 0 && c != mask).then(|| (1 + at % (points - 1), c))
            }),
            extra,
            arc,
            heater,
        })
}

fn part_spec() -> impl Strategy<Value = PartSpec> {
    (
        proptest::collection::vec(proptest::collection::vec(course_spec(), 1..5), 1..4),
        any::<bool>(),
        0u8..3,
        any::<bool>(),
    )
        .prop_map(|(plies, course_markers, ends, final_newline)| PartSpec {
            plies,
            course_markers,
            ends,
            final_newline,
        })
}

fn n(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn program(spec: &PartSpec) -> String {
    let mut l: Vec<String> = vec!["%".into(), "(generated part)".into(), "G21 G90".into(), "G0 Z100".into()];
    for (pi, ply) in spec.plies.iter().enumerate() {
        l.push(format!("(PLY {} generated)", pi + 1));
        for (ci, c) in ply.iter().enumerate() {
            if spec.course_markers {
                l.push(format!("(COURSE {})", ci + 1));
            }
            let pt = |k: usize| {
                let t = c.len * k as f64 / c.points as f64;
                (c.x + t * c.angle.cos(), c.y + t * c.angle.sin())
            };
            let (x0, y0) = pt(0);
            l.push(format!("G0 X{} Y{} Z20 C{}", n(x0), n(y0), n(c.heading)));
            if c.extra == 1 {
                l.push("M8 (heater)".into());
            }
            l.push("G1 Z0 F1000".into());
            l.push("M20".into());
            l.push(format!("M60 P{}", c.mask));
            if c.heater {
                l.push("M8 (heater on)".into());
            }
            let mut on = c.mask;
            for k in 1..=c.points {
                let (x, y) = pt(k);
                let feed = if k == 1 { " F2500" } else { "" };
                let comment = if c.extra == 2 && k == 1 { " (first move)" } else { "" };
                if c.arc && k == c.points {
                    let r = n(c.len / c.points as f64);
                    l.push(format!("G2 X{} Y{} R{r}{feed}{comment}", n(x), n(y)));
                } else {
                    l.push(format!("G1 X{} Y{}{feed}{comment}", n(x), n(y)));
                }
                if let Some((at, cut)) = c.mid_cut {
                    if at == k {
                        l.push(format!("M61 P{cut}"));
                        on &= !cut;
                    }
                }
                if c.extra == 3 && k == 1 {
                    l.push("(a note inside the course)".into());
                }
            }
            if c.heater {
                l.push("M9 (heater off)".into());
            }
            l.push(format!("M61 P{on}"));
            l.push("M21".into());
            // Retracts of two heights, so that a reversed course's approach (the retract run
            // backwards at the approach's feed) is not as long as its forward one.
            l.push(if c.mask % 2 == 0 { "G1 Z20".into() } else { "G1 Z35".into() });
            if c.extra == 1 {
                l.push("M9 (heater off)".into());
            }
        }
    }
    l.push("G0 Z100".into());
    l.push("M30".into());
    let sep = ["\n", "\r\n", "\r"][spec.ends as usize % 3];
    let mut s = l.join(sep);
    if spec.final_newline {
        s.push_str(sep);
    }
    s
}

/// For each laid move (tows on), keyed by its end points in X, Y, Z whatever the direction:
/// whether the heater is on while it is laid, reading `M8`/`M9` lines in the program's order.
fn heated(p: &towpath_nc::Program) -> std::collections::BTreeMap<String, Vec<bool>> {
    let mut on = false;
    let mut at_line = Vec::with_capacity(p.lines.len());
    for l in &p.lines {
        at_line.push(on);
        if l.starts_with("M8") {
            on = true;
        } else if l.starts_with("M9") {
            on = false;
        }
    }
    let key = |i: u32| p.point(i)[..3].iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>().join(",");
    // Courses may lay the same moves: each key holds all of them.
    let mut out: std::collections::BTreeMap<String, Vec<bool>> = std::collections::BTreeMap::new();
    for s in p.segments.iter().filter(|s| s.on_part && s.mask != 0) {
        let (a, b) = (key(s.from), key(s.to));
        out.entry(if a < b { format!("{a}|{b}") } else { format!("{b}|{a}") })
            .or_default()
            .push(at_line[s.line as usize]);
    }
    for v in out.values_mut() {
        v.sort();
    }
    out
}

/// A random feasible order with random reversals.
fn random_order(k: usize, prec: &towpath_seq::Precedence, rev_ok: &[bool], seed: u64) -> Vec<Placement> {
    let mut state = seed | 1;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut indeg: Vec<usize> = (0..k).map(|t| prec.predecessors(TaskId(t as u32)).len()).collect();
    let mut ready: Vec<usize> = (0..k).filter(|&t| indeg[t] == 0).collect();
    let mut out = Vec::new();
    while !ready.is_empty() {
        let i = (rnd() % ready.len() as u64) as usize;
        let t = ready.swap_remove(i);
        out.push(Placement { course: t, reversed: rev_ok[t] && rnd() % 2 == 0 });
        for s in prec.successors(TaskId(t as u32)) {
            indeg[s.index()] -= 1;
            if indeg[s.index()] == 0 {
                ready.push(s.index());
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(40),
        ..ProptestConfig::default()
    })]

    #[test]
    fn round_trip_is_exact(spec in part_spec()) {
        let text = program(&spec);
        let d = Dialect::default();
        let p = parse(&text, &machine(), &d).unwrap();
        prop_assert_eq!(p.courses.len(), spec.plies.iter().map(Vec::len).sum::<usize>());
        let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
        prop_assert_eq!(rewrite(&p, &order, &machine(), &d, &[]).unwrap(), text);
    }

    #[test]
    fn any_feasible_order_verifies_and_costs_what_the_solver_thinks(spec in part_spec(), seed in any::<u64>()) {
        let text = program(&spec);
        let d = Dialect::default();
        let m = machine();
        let p = parse(&text, &m, &d).unwrap();
        let opts = AfpOptions { bidirectional: true, width: Some(Width::Tow(6.0)), cost: CostKind::Axis, ..AfpOptions::default() };
        let afp = build_problem(&p, &m, &d, &opts).unwrap();
        let rev_ok: Vec<bool> = (0..p.courses.len()).map(|c| afp.reversed[c].is_some()).collect();
        let arcs: Vec<bool> = spec.plies.iter().flatten().map(|c| c.arc).collect();
        let heaters: Vec<bool> = spec.plies.iter().flatten().map(|c| c.heater).collect();
        for c in 0..p.courses.len() {
            prop_assert_eq!(rev_ok[c], !arcs[c] && !heaters[c], "course {} reversible unless it holds an arc or M8/M9", c);
        }
        let order = random_order(p.courses.len(), afp.problem.precedence(), &rev_ok, seed);
        let steps: Vec<Step> = order.iter().map(|pl| Step { task: TaskId(pl.course as u32), mode: pl.reversed as u32 }).collect();
        let route = check(&afp.problem, &steps).unwrap();
        let out = rewrite(&p, &order, &m, &d, &afp.reversed).unwrap();
        let v = verify(&text, &out, &m, &d, &VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() }).unwrap();
        prop_assert_eq!(&v.order, &order);
        let identity = order.iter().enumerate().all(|(i, pl)| pl.course == i && !pl.reversed);
        let (b, a) = v.motion(CostKind::Axis).unwrap();
        prop_assert!((a.on_part - b.on_part).abs() <= 1e-6 * (1.0 + b.on_part));
        if !identity {
            let measured: f64 = a.off_course.iter().sum();
            prop_assert!((measured - route).abs() <= 1e-6 * (1.0 + route), "measured {} route {}", measured, route);
            // Under the time cost too, where approach and retract moves run at their programmed
            // feeds and a reversed course's approach takes the original approach's feed.
            let timed = build_problem(&p, &m, &d, &AfpOptions { cost: CostKind::Time, ..opts.clone() }).unwrap();
            let route = check(&timed.problem, &steps).unwrap();
            let (_, a) = v.motion(CostKind::Time).unwrap();
            let measured: f64 = a.off_course.iter().sum();
            prop_assert!((measured - route).abs() <= 1e-6 * (1.0 + route), "time: measured {} route {}", measured, route);
            // With a clearance, every transit goes up to it, across and down, as the solver
            // prices it, under every cost model, and the program still verifies.
            let dc = Dialect { clearance: Some(Clearance { axis: "Z".into(), value: 50.0 }), ..Dialect::default() };
            let out = rewrite(&p, &order, &m, &dc, &afp.reversed).unwrap();
            let v = verify(&text, &out, &m, &dc, &VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() }).unwrap();
            prop_assert_eq!(&v.order, &order);
            for cost in CostKind::ALL {
                let priced = build_problem(&p, &m, &dc, &AfpOptions { cost, ..opts.clone() }).unwrap();
                let route = check(&priced.problem, &steps).unwrap();
                let (_, a) = v.motion(cost).unwrap();
                let measured: f64 = a.off_course.iter().sum();
                prop_assert!((measured - route).abs() <= 1e-6 * (1.0 + route), "{} with clearance: measured {} route {}", cost, measured, route);
            }
        }
        // Every course reverses with the heading turned half a turn, but those holding an arc
        // or codes the dialect does not describe.
        for c in 0..p.courses.len() {
            match reverse_course(&p, c, &m, &d) {
                Ok(r) => prop_assert!(r.shift.abs() == 180.0 && !arcs[c] && !heaters[c]),
                Err(Irreversible::Undescribed { words, .. }) => prop_assert!(heaters[c] && words == "M8"),
                Err(why) => prop_assert!(arcs[c] && why.to_string().contains("arc"), "{}", why),
            }
        }
    }

    /// Declared as a switch, the heater is on along exactly the same laid moves (by their end
    /// points, whatever the direction) in any feasible order with any legal reversals, read
    /// from the rewritten text line by line.
    #[test]
    fn switches_keep_their_laid_stretches_in_any_order(spec in part_spec(), seed in any::<u64>()) {
        let text = program(&spec);
        let d = Dialect { switches: vec![Switch { on: "M8".into(), off: "M9".into() }], ..Dialect::default() };
        let m = machine();
        let p = parse(&text, &m, &d).unwrap();
        let opts = AfpOptions { bidirectional: true, width: Some(Width::Tow(6.0)), ..AfpOptions::default() };
        // A heater switched on before the approach of the last course is switched off in the
        // footer, not with the course (unless the course's own M9 does): laid earlier, it would
        // stay on for the courses after it.
        if spec.plies.iter().flatten().last().is_some_and(|c| c.extra == 1 && !c.heater) {
            let e = build_problem(&p, &m, &d, &opts).unwrap_err().to_string();
            prop_assert!(e.contains("\"M8 (heater)\" leaves a switch on"), "{}", e);
            return Ok(());
        }
        let afp = build_problem(&p, &m, &d, &opts).unwrap();
        let arcs: Vec<bool> = spec.plies.iter().flatten().map(|c| c.arc).collect();
        // A heater switched on before the course and again within it: reversed, the switch
        // lines would not keep their stretch (it starts on), so the course is laid forward.
        let on_before: Vec<bool> = spec.plies.iter().flatten().map(|c| c.extra == 1 && c.heater).collect();
        let rev_ok: Vec<bool> = (0..p.courses.len()).map(|c| afp.reversed[c].is_some()).collect();
        for c in 0..p.courses.len() {
            prop_assert_eq!(rev_ok[c], !arcs[c] && !on_before[c], "course {}", c);
        }
        let order = random_order(p.courses.len(), afp.problem.precedence(), &rev_ok, seed);
        let out = rewrite(&p, &order, &m, &d, &afp.reversed).unwrap();
        verify(&text, &out, &m, &d, &VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() }).unwrap();
        let q = parse(&out, &m, &d).unwrap();
        prop_assert_eq!(heated(&p), heated(&q));
    }

    /// Every line of the optimized program is accounted for: removing any line is noticed (but
    /// a repeated ply comment, a blank line, or a transit line towpath wrote, whose loss may not
    /// change the motion checked: a set-position line before a course that writes no value of
    /// that axis, say), and so is any of these lines slipped in anywhere.
    #[test]
    fn verifier_notices_any_line_removed_or_slipped_in(spec in part_spec(), at in any::<usize>(), extra in 0usize..5) {
        let text = program(&spec);
        let d = Dialect::default();
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(6.0)), ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(50),
            threads: 1,
            ..OptimizeOptions::default()
        };
        let out = optimize(&text, &machine(), &d, &opts).unwrap().text;
        let lines: Vec<&str> = out.lines().collect();
        let vopts = VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() };
        let i = at % lines.len();
        let mut removed = lines.clone();
        let gone = removed.remove(i).trim_end_matches('\r');
        let repeated_ply = gone.starts_with("(PLY") && removed.iter().any(|l| l.trim_end_matches('\r') == gone);
        let transit = ["G0 ", "G92 ", "G90 G0 "].iter().any(|t| gone.starts_with(t))
            || gone.split_whitespace().all(|w| ["G0", "G1", "G90", "G91"].contains(&w) || w.starts_with('F'));
        if !(gone.trim().is_empty() || repeated_ply || transit) {
            prop_assert!(verify(&text, &removed.join("\n"), &machine(), &d, &vopts).is_err(), "line {} {:?} removed", i + 1, gone);
        }
        let mut slipped = lines.clone();
        let new = ["M0", "G4 P5000", "(a note)", "M8", "S300"][extra];
        slipped.insert(at % (lines.len() + 1), new);
        prop_assert!(verify(&text, &slipped.join("\n"), &machine(), &d, &vopts).is_err(), "{:?} slipped in at line {}", new, at % (lines.len() + 1) + 1);
    }

    #[test]
    fn optimizer_never_returns_a_dearer_program(spec in part_spec(), bi in any::<bool>()) {
        let text = program(&spec);
        let d = Dialect::default();
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: bi, width: Some(Width::Tow(6.0)), ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(200),
            threads: 1,
            ..OptimizeOptions::default()
        };
        let o = optimize(&text, &machine(), &d, &opts).unwrap();
        let (b, a) = o.verification.motion(CostKind::Axis).unwrap();
        prop_assert!(a.off_part() <= b.off_part() * (1.0 + 1e-12) + 1e-9);
        if o.fell_back {
            prop_assert_eq!(o.text, text);
        }
    }

    #[test]
    fn optimizing_the_output_again_still_verifies_against_the_original(spec in part_spec()) {
        let text = program(&spec);
        let d = Dialect::default();
        let opts = |seed| OptimizeOptions {
            afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(6.0)), ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(100),
            threads: 1,
            seed,
            ..OptimizeOptions::default()
        };
        let once = optimize(&text, &machine(), &d, &opts(1)).unwrap();
        // Read again, the output's plies each hold courses of one original ply.
        let reread = parse(&once.text, &machine(), &d).unwrap();
        for ply in &reread.plies {
            let origin: std::collections::BTreeSet<usize> =
                ply.courses.iter().map(|&k| once.program.courses[once.order[k].course].ply).collect();
            prop_assert!(origin.len() <= 1, "{:?}", origin);
        }
        let twice = optimize(&once.text, &machine(), &d, &opts(2)).unwrap();
        let v = verify(&text, &twice.text, &machine(), &d, &VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() });
        prop_assert!(v.is_ok(), "{:?}", v.err());
    }

    #[test]
    fn verifier_never_panics_on_mutated_output(spec in part_spec(), edits in proptest::collection::vec((0usize..10_000, 0u8..4, any::<char>()), 1..4)) {
        let text = program(&spec);
        let d = Dialect::default();
        let opts = OptimizeOptions {
            afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(6.0)), ..AfpOptions::default() },
            time_limit: None,
            iterations: Some(50),
            threads: 1,
            ..OptimizeOptions::default()
        };
        let out = optimize(&text, &machine(), &d, &opts).unwrap().text;
        let mut lines: Vec<String> = out.lines().map(str::to_string).collect();
        for (at, kind, ch) in edits {
            if lines.is_empty() {
                break;
            }
            let i = at % lines.len();
            match kind {
                0 => { lines.remove(i); }
                1 => { let l = lines[i].clone(); lines.insert(i, l); }
                2 => { if i + 1 < lines.len() { lines.swap(i, i + 1); } }
                _ => { let mut l: Vec<char> = lines[i].chars().collect(); let k = at % (l.len() + 1); l.insert(k, ch); lines[i] = l.into_iter().collect(); }
            }
        }
        let mutated = lines.join("\n");
        let r = verify(&text, &mutated, &machine(), &d, &VerifyOptions { width: Some(Width::Tow(6.0)), ..VerifyOptions::default() });
        // Removing or duplicating a line of motion is always caught.
        if r.is_ok() {
            let p = parse(&mutated, &machine(), &d).unwrap();
            prop_assert_eq!(p.courses.len(), spec.plies.iter().map(Vec::len).sum::<usize>());
        }
    }

    #[test]
    fn parser_never_panics_on_line_soup(lines in proptest::collection::vec(
        prop_oneof![
            Just("G0 X10 Y10 Z5 C0".to_string()),
            Just("G1 X20 F100".to_string()),
            Just("M20".to_string()), Just("M21".to_string()),
            Just("M60 P3".to_string()), Just("M61 P3".to_string()), Just("M61 P1".to_string()),
            Just("(PLY 1)".to_string()), Just("(COURSE 2)".to_string()),
            Just("G91".to_string()), Just("G90".to_string()), Just("G92 C10".to_string()),
            Just("X-5".to_string()), Just("%".to_string()), Just("G2 X1".to_string()),
            Just("G2 X30 Y10 R20".to_string()), Just("G3 X5 I-5 J0".to_string()), Just("G18".to_string()),
            Just("G2 X0 Z5 I-5 K0".to_string()), Just("I3 J4".to_string()),
            "[ -~]{0,20}",
        ], 0..40)) {
        let text = lines.join("\n");
        let d = Dialect::default();
        if let Ok(p) = parse(&text, &machine(), &d) {
            let order: Vec<Placement> = (0..p.courses.len()).map(|c| Placement { course: c, reversed: false }).collect();
            prop_assert_eq!(rewrite(&p, &order, &machine(), &d, &[]).unwrap(), text.clone());
            for c in 0..p.courses.len() {
                let _ = reverse_course(&p, c, &machine(), &d);
            }
        }
    }

    #[test]
    fn parser_never_panics_on_any_text(text in "\\PC{0,300}") {
        let _ = parse(&text, &machine(), &Dialect::default());
    }
}
