//! `towpath order` end to end: outputs read back and checked against the input by the
//! library's verifier (every piece once, same geometry, holes first), totals re-measured from
//! the written file, refused input reported with file, line and problem.

use super::common::*;

use towpath_cut::io::{read, Format};
use towpath_cut::verify::{verify, Rules};
use towpath_cut::{geom::dist, Placement};

const SVG: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="120" height="120" viewBox="0 0 120 120">
  <g id="cut" transform="translate(10 10)">
    <rect id="sheet" x="0" y="0" width="100" height="100" fill="none" stroke="black"/>
    <rect id="part" x="10" y="10" width="40" height="40" fill="none" stroke="black"/>
    <circle id="hole" cx="30" cy="30" r="5" fill="none" stroke="black"/>
    <path id="s1" d="M 70 70 L 90 70" stroke="black"/>
    <path id="s2" d="M 90 80 L 70 80" stroke="black"/>
  </g>
</svg>"##;

/// Reads an output back and checks it as an ordering of the input.
fn check_output(format: Format, input: &str, output: &str, start: Option<[f64; 2]>) -> Vec<String> {
    let (d, _) = read(format, input, "in", 1e-3).unwrap();
    let (back, _) = read(format, output, "out", 1e-3).unwrap();
    assert_eq!(back.pieces.len(), d.pieces.len());
    let mut used = vec![false; d.pieces.len()];
    let mut placements = Vec::new();
    for p in &back.pieces {
        let i = (0..d.pieces.len())
            .filter(|&i| {
                !used[i]
                    && d.pieces[i].path.closed == p.path.closed
                    && (d.pieces[i].path.length() - p.path.length()).abs() < 1e-3
            })
            .min_by(|&a, &b| {
                let f = |i: usize| {
                    dist(d.pieces[i].path.start, p.path.start).min(dist(d.pieces[i].path.end(), p.path.start))
                };
                f(a).total_cmp(&f(b))
            })
            .expect("a matching input piece");
        used[i] = true;
        let reversed =
            !p.path.closed && dist(p.path.start, d.pieces[i].path.end()) < dist(p.path.start, d.pieces[i].path.start);
        placements.push(Placement { piece: i, path: p.path.clone(), reversed, lead_in: None });
    }
    let rules = Rules { inner_first: true, mix_operations: false, reverse: true, tolerance: 1e-2, start };
    let v = verify(&d, &placements, &rules);
    assert!(v.ok(), "{}", v.problems());
    back.pieces.iter().map(|p| p.id.clone()).collect()
}

#[test]
fn orders_an_svg_holes_first_and_the_file_verifies() {
    let dir = scratch("order-svg");
    let input = dir.join("in.svg");
    std::fs::write(&input, SVG).unwrap();
    let out = dir.join("out.svg");
    let o = towpath_out(&[
        "order",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--iterations",
        "50",
        "--threads",
        "1",
        "--json",
    ]);
    let v = json_of(&o);
    let written = std::fs::read_to_string(&out).unwrap();
    let ids = check_output(Format::Svg, SVG, &written, Some([0.0, 0.0]));
    let pos = |id: &str| ids.iter().position(|x| x == id).unwrap();
    assert!(pos("hole") < pos("part") && pos("part") < pos("sheet"));
    assert_eq!(v["pieces"], 5);
    assert_eq!(v["precedence_violations"], 0);
    // The drawing's own order cuts the sheet before its holes, so it is no bound; a naive legal
    // order is: hole, part, sheet, s1, s2, each entered where it starts, from the origin.
    let (d, _) = read(Format::Svg, SVG, "in", 1e-3).unwrap();
    let piece = |id: &str| d.pieces.iter().find(|p| p.id == id).unwrap();
    let mut naive = 0.0;
    let mut here = [0.0, 0.0];
    for id in ["hole", "part", "sheet", "s1", "s2"] {
        naive += dist(here, piece(id).path.start);
        here = piece(id).path.end();
    }
    assert!(v["rapid_after"].as_f64().unwrap() <= naive, "{} > naive legal order {naive}", v["rapid_after"]);
    // The reported travel is the travel of the written file, measured here.
    let (back, _) = read(Format::Svg, &written, "out", 1e-3).unwrap();
    let mut at = [0.0, 0.0];
    let mut travel = 0.0;
    for p in &back.pieces {
        travel += dist(at, p.path.start);
        at = p.path.end();
    }
    assert!((travel - v["rapid_after"].as_f64().unwrap()).abs() < 1e-3, "{travel} vs {}", v["rapid_after"]);
    // The two strokes: with reversal they are drawn head to tail (s2 backwards or s1 after s2).
    assert!(written.contains("id=\"s1\"") && written.contains("id=\"s2\""));
}

#[test]
fn gcode_with_lead_ins_and_merge() {
    let dir = scratch("order-gcode");
    let input = dir.join("in.nc");
    let prog = "G21 G90\nG0 X0 Y0\nM3\nG1 X50 Y0 F1000\nG1 X50 Y50\nG1 X0 Y50\nG1 X0 Y0\nM5\nG0 X20 Y20\nM3\nG1 X30 Y20\nG1 X30 Y30\nG1 X20 Y30\nG1 X20 Y20\nM5\nG0 X60 Y0\nM3\nG1 X70 Y0\nM5\nG0 X70 Y0\nM3\nG1 X80 Y0\nM5\nG0 X0 Y0\nM30\n";
    std::fs::write(&input, prog).unwrap();
    let out = dir.join("out.nc");
    let o = towpath_out(&[
        "order",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--iterations",
        "50",
        "--threads",
        "1",
        "--lead-in",
        "2",
        "--merge",
        "0.01",
        "--json",
    ]);
    let v = json_of(&o);
    assert_eq!(v["pieces"], 4);
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(written.starts_with("G21 G90\n") && written.ends_with("G0 X0 Y0\nM30\n"));
    // The inner square's moves come before the outer square's.
    let inner = written.find("X30 Y30").unwrap();
    let outer = written.find("X50 Y50").unwrap();
    assert!(inner < outer);
    // Lead-ins: the rapid before the outer square ends 2 mm off its contour, outside it.
    let rapids: Vec<&str> = written.lines().filter(|l| l.starts_with("G0 X")).collect();
    assert_eq!(rapids.len(), 4, "{written}"); // two squares, the merged strokes once... and home
                                              // Merged strokes: the second follows the first without a rapid in between.
    let a = written.find("X70 Y0").unwrap();
    let b = written[a..].find("X80 Y0").map(|k| a + k).or_else(|| written.find("X80 Y0")).unwrap();
    let between = &written[a.min(b)..a.max(b)];
    assert!(!between.contains("G0 X"), "rapid between merged strokes: {between}");
}

#[test]
fn dxf_round_trip_through_the_binary() {
    let dir = scratch("order-dxf");
    let mut dr = dxf::Drawing::new();
    dr.header.version = dxf::enums::AcadVersion::R2000;
    for (c, r) in [((50.0, 50.0), 30.0), ((50.0, 50.0), 10.0), ((150.0, 50.0), 20.0)] {
        let mut e = dxf::entities::Entity::new(dxf::entities::EntityType::Circle(dxf::entities::Circle::new(
            dxf::Point::new(c.0, c.1, 0.0),
            r,
        )));
        e.common.layer = "CUT".into();
        dr.add_entity(e);
    }
    let mut buf = Vec::new();
    dr.save(&mut buf).unwrap();
    let text = String::from_utf8(buf).unwrap();
    let input = dir.join("in.dxf");
    std::fs::write(&input, &text).unwrap();
    let out = dir.join("out.dxf");
    let o = towpath_out(&[
        "order",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--iterations",
        "20",
        "--threads",
        "1",
        "--json",
    ]);
    let _ = json_of(&o);
    let written = std::fs::read_to_string(&out).unwrap();
    check_output(Format::Dxf, &text, &written, Some([0.0, 0.0]));
}

#[test]
fn refused_input_names_file_and_line() {
    let dir = scratch("order-bad");
    let input = dir.join("bad.nc");
    std::fs::write(&input, "G21\nG91\nG1 X5\n").unwrap();
    let (code, _, err) = run(towpath().args(["order", input.to_str().unwrap()]));
    assert_eq!(code, 2);
    assert!(err.contains("bad.nc:2:") && err.contains("G91"), "{err}");
    let j = dir.join("bad.json");
    std::fs::write(
        &j,
        r#"{"format": "towpath-cut/1", "pieces": [{"id": "a", "closed": true, "points": [[0,0],[1,0]]}]}"#,
    )
    .unwrap();
    let (code, _, err) = run(towpath().args(["order", j.to_str().unwrap()]));
    assert_eq!(code, 2);
    assert!(err.contains("bad.json") && err.contains("pieces[0]") && err.contains("closed"), "{err}");
    let (code, _, err) = run(towpath().args(["order", j.to_str().unwrap(), "--start", "1"]));
    assert_eq!(code, 2);
    assert!(err.contains("--start"), "{err}");
    // The output may not overwrite the input.
    let s = dir.join("in.svg");
    std::fs::write(&s, SVG).unwrap();
    let (code, _, _) = run(towpath().args(["order", s.to_str().unwrap(), "-o", s.to_str().unwrap()]));
    assert_eq!(code, 2);
    assert_eq!(std::fs::read_to_string(&s).unwrap(), SVG);
}

/// `--bound` on a drawing of open strokes: a Held–Karp lower bound at most the travel of the
/// written order (measured from the file) and not far below it; none for closed contours,
/// whose entries move after the solver.
#[test]
fn bound_on_strokes_is_below_the_written_travel() {
    let dir = scratch("order-bound");
    // 60 strokes from a fixed linear congruential sequence
    let mut x: u64 = 12345;
    let mut next = || {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (x >> 33) as f64 / (1u64 << 31) as f64 * 200.0
    };
    let mut body = String::new();
    for i in 0..60 {
        let (a, b, c, d) = (next(), next(), next(), next());
        body.push_str(&format!("<path id=\"p{i}\" d=\"M {a:.3} {b:.3} L {c:.3} {d:.3}\" stroke=\"black\"/>\n"));
    }
    let svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\" viewBox=\"0 0 200 200\">\n{body}</svg>"
    );
    let input = dir.join("strokes.svg");
    std::fs::write(&input, &svg).unwrap();
    let out = dir.join("out.svg");
    let args = ["order", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--start", "none"];
    let v =
        json_of(&towpath_out(&[&args[..], &["--iterations", "2000", "--threads", "1", "--bound", "--json"]].concat()));
    let bound = v["rapid_lower_bound"].as_f64().expect("a bound for open strokes");
    let (back, _) = read(Format::Svg, &std::fs::read_to_string(&out).unwrap(), "out", 1e-3).unwrap();
    let travel: f64 = back.pieces.windows(2).map(|w| dist(w[0].path.end(), w[1].path.start)).sum();
    assert!((travel - v["rapid_after"].as_f64().unwrap()).abs() < 1e-3);
    assert!(bound <= travel + 1e-6, "bound {bound} above the written travel {travel}");
    assert!(bound >= 0.8 * travel, "bound {bound} far below the travel {travel}");
    // the summary names it
    let o = towpath_out(&[&args[..], &["--iterations", "2000", "--threads", "1", "--bound"]].concat());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("lower bound") && text.contains("Held–Karp"), "{text}");
    // closed contours: no bound, and the summary says why
    let closed = dir.join("closed.svg");
    std::fs::write(&closed, SVG).unwrap();
    let c = ["order", closed.to_str().unwrap(), "--iterations", "50", "--threads", "1", "--bound"];
    assert_eq!(json_of(&towpath_out(&[&c[..], &["--json"]].concat()))["rapid_lower_bound"], serde_json::Value::Null);
    let o = towpath_out(&c);
    assert!(String::from_utf8_lossy(&o.stdout).contains("lower bound         : none"));
}
