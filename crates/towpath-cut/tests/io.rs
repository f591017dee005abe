//! Readers and writers: SVG transforms applied (bounding boxes computed by hand), round trips
//! through SVG, DXF, G-code and JSON keeping every piece's geometry (checked by the verifier
//! against the input after reading the output back), refused input named, and no panic on
//! arbitrary bytes (proptest).

use proptest::prelude::*;
use towpath_cut::geom::{bbox_of, dist};
use towpath_cut::io::{read, write, Format};
use towpath_cut::verify::Rules;
use towpath_cut::{order, verify, Drawing, OrderOptions, Placement};
use towpath_seq::SolveOptions;

fn opts() -> OrderOptions {
    OrderOptions {
        solve: SolveOptions { time_limit: None, iterations: Some(100), threads: 1, ..SolveOptions::default() },
        ..OrderOptions::default()
    }
}

fn bbox_all(d: &Drawing) -> [f64; 4] {
    let pts: Vec<[f64; 2]> = d.pieces.iter().flat_map(|p| p.path.flatten(1e-3)).collect();
    bbox_of(&pts)
}

/// Matches the pieces read back from an output to the input's, by geometry, and verifies them
/// as an ordering of the input.
fn round_trip(format: Format, text: &str, tol: f64) -> (Drawing, Drawing) {
    let (d, src) = read(format, text, "in", tol).unwrap();
    let r = order(&d, &opts()).unwrap();
    let out = write(&src, &d, &r.placements).unwrap();
    let (back, _) = read(format, &out, "out", tol).unwrap();
    assert_eq!(back.pieces.len(), d.pieces.len(), "{out}");
    // Each piece read back is matched to the input piece it came from (closest start/end),
    // then the whole is checked by the verifier.
    let mut placements = Vec::new();
    let mut used = vec![false; d.pieces.len()];
    for p in &back.pieces {
        let best = (0..d.pieces.len())
            .filter(|&i| !used[i] && d.pieces[i].path.closed == p.path.closed)
            .min_by(|&a, &b| {
                let da = (d.pieces[a].path.length() - p.path.length()).abs()
                    + dist(d.pieces[a].path.end(), p.path.end()).min(dist(d.pieces[a].path.start, p.path.end()));
                let db = (d.pieces[b].path.length() - p.path.length()).abs()
                    + dist(d.pieces[b].path.end(), p.path.end()).min(dist(d.pieces[b].path.start, p.path.end()));
                da.total_cmp(&db)
            })
            .unwrap();
        used[best] = true;
        let reversed = !p.path.closed
            && dist(p.path.start, d.pieces[best].path.start) > dist(p.path.start, d.pieces[best].path.end());
        placements.push(Placement { piece: best, path: p.path.clone(), reversed, lead_in: None });
    }
    let o = opts();
    let rules =
        Rules { inner_first: true, mix_operations: false, reverse: true, tolerance: tol * 10.0, start: o.start };
    let v = verify(&d, &placements, &rules);
    assert!(v.ok(), "{}", v.problems());
    // The order written is the order chosen.
    let chosen: Vec<usize> = r.placements.iter().map(|p| p.piece).collect();
    let written: Vec<usize> = placements.iter().map(|p| p.piece).collect();
    assert_eq!(chosen, written);
    (d, back)
}

const SVG: &str = r##"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="200mm" height="100mm" viewBox="0 0 200 100">
  <defs><style>.c{stroke:#000}</style></defs>
  <g id="engrave" inkscape:groupmode="layer" inkscape:label="Engrave" transform="translate(5,0)">
    <path class="c" d="M 10 10 L 30 10 Q 40 20 30 30" fill="none"/>
    <text x="0" y="0">label</text>
  </g>
  <g id="cut" inkscape:label="Cut" transform="translate(10,20) scale(2)">
    <rect id="outer" x="0" y="0" width="40" height="30" fill="none" stroke="red"/>
    <g transform="rotate(90 20 15)" stroke="blue"><circle id="hole" cx="20" cy="15" r="5"/></g>
    <polyline points="50,0 60,10 70,0"/>
  </g>
</svg>"##;

#[test]
fn svg_transforms_are_applied() {
    let (d, _) = read(Format::Svg, SVG, "t.svg", 1e-3).unwrap();
    assert_eq!(d.operations, ["Engrave", "Cut"]);
    let by_id = |id: &str| d.pieces.iter().find(|p| p.id == id).unwrap();
    // rect: translate(10,20) scale(2) of [0,40]×[0,30] → [10,90]×[20,80]
    let b = bbox_of(&by_id("outer").path.flatten(1e-3));
    for (x, y) in b.iter().zip([10.0, 20.0, 90.0, 80.0]) {
        assert!((x - y).abs() < 1e-3, "{b:?}");
    }
    // circle r 5 at (20,15), rotated about its centre, then scaled 2: centre (50,50), r 10
    let b = bbox_of(&by_id("hole").path.flatten(1e-4));
    for (x, y) in b.iter().zip([40.0, 40.0, 60.0, 60.0]) {
        assert!((x - y).abs() < 1e-2, "{b:?}");
    }
    assert!(by_id("outer").path.closed && by_id("hole").path.closed);
    // The engrave stroke: translate(5,0): starts at (15,10).
    let s = d.pieces.iter().find(|p| p.operation == 0).unwrap();
    assert!(dist(s.path.start, [15.0, 10.0]) < 1e-4 && !s.path.closed);
}

#[test]
fn svg_round_trip_keeps_geometry_layers_and_attributes() {
    let (d, back) = round_trip(Format::Svg, SVG, 1e-3);
    let (a, b) = (bbox_all(&d), bbox_all(&back));
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() < 1e-3, "{a:?} vs {b:?}");
    }
    let (_, src) = read(Format::Svg, SVG, "t.svg", 1e-3).unwrap();
    let r = order(&d, &opts()).unwrap();
    let out = write(&src, &d, &r.placements).unwrap();
    for kept in [
        "inkscape:label=\"Engrave\"",
        "<text x=\"0\" y=\"0\">label</text>",
        "id=\"outer\"",
        "stroke=\"red\"",
        "stroke=\"blue\"",
        "<style>",
    ] {
        assert!(out.contains(kept), "{kept} missing in {out}");
    }
    // The hole comes before the outer contour in the output text.
    assert!(out.find("id=\"hole\"").unwrap() < out.find("id=\"outer\"").unwrap());
}

fn dxf_text() -> String {
    use dxf::entities::*;
    let mut dr = dxf::Drawing::new();
    dr.header.version = dxf::enums::AcadVersion::R2000;
    let mut add = |layer: &str, t: EntityType| {
        let mut e = Entity::new(t);
        e.common.layer = layer.into();
        dr.add_entity(e);
    };
    add("CUT", EntityType::Circle(Circle::new(dxf::Point::new(50.0, 50.0, 0.0), 10.0)));
    let mut lw = LwPolyline::default();
    lw.set_is_closed(true);
    for (x, y, b) in [(0.0, 0.0, 0.0), (100.0, 0.0, 0.5), (100.0, 100.0, 0.0), (0.0, 100.0, 0.0)] {
        lw.vertices.push(dxf::LwPolylineVertex { x, y, bulge: b, ..Default::default() });
    }
    add("CUT", EntityType::LwPolyline(lw));
    add("ENGRAVE", EntityType::Line(Line::new(dxf::Point::new(20.0, 20.0, 0.0), dxf::Point::new(30.0, 25.0, 0.0))));
    add("ENGRAVE", EntityType::Arc(Arc::new(dxf::Point::new(70.0, 20.0, 0.0), 5.0, 10.0, 200.0)));
    let mut sp = Spline { degree_of_curve: 3, ..Default::default() };
    sp.control_points = vec![
        dxf::Point::new(10.0, 80.0, 0.0),
        dxf::Point::new(20.0, 90.0, 0.0),
        dxf::Point::new(30.0, 70.0, 0.0),
        dxf::Point::new(40.0, 80.0, 0.0),
    ];
    sp.knot_values = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    add("ENGRAVE", EntityType::Spline(sp));
    let mut buf = Vec::new();
    dr.save(&mut buf).unwrap();
    String::from_utf8(buf).unwrap()
}

#[test]
fn dxf_round_trip() {
    let text = dxf_text();
    let (d, back) = round_trip(Format::Dxf, &text, 1e-3);
    assert_eq!(d.operations, ["CUT", "ENGRAVE"]);
    assert_eq!(back.operations, d.operations);
    // The circle: length 2π·10 exactly (two half arcs).
    let c = d.pieces.iter().find(|p| p.path.closed && p.path.segs.len() == 2).unwrap();
    assert!((c.path.length() - 20.0 * std::f64::consts::PI).abs() < 1e-9);
    // The arc from 10° to 200°, r 5: length 5·190°.
    let a = d.pieces.iter().find(|p| !p.path.closed && matches!(p.path.segs[0], towpath_cut::Seg::Arc { .. })).unwrap();
    assert!((a.path.length() - 5.0 * 190f64.to_radians()).abs() < 1e-9);
    // The clamped cubic spline ends at its end control points.
    let s = d.pieces.iter().find(|p| p.path.segs.len() > 4 && !p.path.closed).unwrap();
    assert!(dist(s.path.start, [10.0, 80.0]) < 1e-9 && dist(s.path.end(), [40.0, 80.0]) < 1e-9);
}

const GCODE: &str = "%
(test program)
G21 G90 G17
M5
G0 Z5
G0 X0 Y0
M3 S1000
G1 X40 Y0 F1200
G1 X40 Y40
G1 X0 Y40
G1 X0 Y0
M5
G0 X10 Y10
M3
G1 X20 Y10 F600
G2 X30 Y20 I0 J10
G1 X30 Y30
M5
G0 X15 Y15
M3
G1 X25 Y15
G3 X25 Y25 R5
G1 X15 Y25
G1 X15 Y15
M5
G0 X0 Y0
M30
%
";

#[test]
fn gcode_round_trip_regenerates_rapids_and_keeps_moves() {
    let (d, _) = round_trip(Format::Gcode, GCODE, 1e-4);
    assert_eq!(d.pieces.len(), 3);
    assert!(d.pieces[0].path.closed && !d.pieces[1].path.closed && d.pieces[2].path.closed);
    // The G2 arc from (20, 10) to (30, 20) round (20, 20), clockwise: three quarters, 15π.
    let arc_len = towpath_cut::geom::seg_length([20.0, 10.0], &d.pieces[1].path.segs[1]);
    assert!((arc_len - 15.0 * std::f64::consts::PI).abs() < 1e-9, "{arc_len}");
    let (_, src) = read(Format::Gcode, GCODE, "t.nc", 1e-4).unwrap();
    let r = order(&d, &opts()).unwrap();
    let out = write(&src, &d, &r.placements).unwrap();
    // Header and footer kept; one rapid per piece plus the footer's return.
    assert!(out.starts_with("%\n(test program)\nG21 G90 G17\nM5\nG0 Z5\n"));
    assert!(out.trim_end().ends_with("G0 X0 Y0\nM30\n%"));
    assert_eq!(out.lines().filter(|l| l.starts_with("G0 X")).count(), 4);
    // The small square (inside the big one) comes before it.
    let (back, _) = read(Format::Gcode, &out, "o.nc", 1e-4).unwrap();
    let big = back.pieces.iter().position(|p| (p.path.length() - 160.0).abs() < 1e-9).unwrap();
    let small = back.pieces.iter().position(|p| p.path.closed && (p.path.length() - 160.0).abs() > 1.0).unwrap();
    assert!(small < big);
}

#[test]
fn refused_input_names_the_line_or_element() {
    let e = read(Format::Gcode, "G21\nG91\nG1 X1\n", "r.nc", 1e-3).unwrap_err().to_string();
    assert!(e.starts_with("r.nc:2:") && e.contains("G91"), "{e}");
    let e = read(Format::Gcode, "G1 X1 Y\n", "w.nc", 1e-3).unwrap_err().to_string();
    assert!(e.starts_with("w.nc:1:") && e.contains("'Y'"), "{e}");
    let e = read(Format::Gcode, "G0 X0 Y0\nG2 X10 Y0 I1 J1\n", "a.nc", 1e-3).unwrap_err().to_string();
    assert!(e.starts_with("a.nc:2:"), "{e}");
    let e = read(Format::Svg, "<svg xmlns=\"http://www.w3.org/2000/svg\">\n<path d=\"M0 0\"></svg>", "x.svg", 1e-3)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("x.svg:2:"), "{e}");
    let j = r#"{"format": "towpath-cut/1", "pieces": [{"id": "a", "closed": true, "points": [[0,0],[1,1]]}]}"#;
    let e = read(Format::Json, j, "c.json", 1e-3).unwrap_err().to_string();
    assert!(e.contains("pieces[0] (id \"a\")") && e.contains("marked closed"), "{e}");
    let e = read(
        Format::Dxf,
        "0\nSECTION\n2\nENTITIES\n0\nCIRCLE\n8\n0\n10\n1\n20\n1\n40\n0\n0\nENDSEC\n0\nEOF\n",
        "c.dxf",
        1e-3,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("CIRCLE") && e.contains("radius"), "{e}");
}

#[test]
fn json_round_trip_with_hierarchy() {
    let j = r#"{"format": "towpath-cut/1", "units": "mm", "operations": ["mark", "cut"],
      "pieces": [
        {"id": "sheet", "operation": "cut", "closed": true, "points": [[0,0],[100,0],[100,100],[0,100]]},
        {"id": "part", "operation": "cut", "closed": true, "points": [[10,10],[50,10],[50,50],[10,50]], "bulges": [0, 0.3, 0, 0]},
        {"id": "mark1", "operation": "mark", "points": [[60,60],[70,70]]},
        {"id": "mark2", "operation": "mark", "points": [[80,80],[90,90]], "after": ["mark1"], "reversible": false}
      ]}"#;
    let (d, back) = round_trip(Format::Json, j, 1e-4);
    assert_eq!(d.hierarchy, vec![(2, 3)]);
    let ids: Vec<&str> = back.pieces.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["mark1", "mark2", "part", "sheet"]);
}

/// Two pieces that touch, with no torch/pen line between them in the order written: the rapid
/// between them is written although it does not move, so they are read back as two pieces
/// (a case `gcode_from_random_moves_round_trips` found).
#[test]
fn touching_pieces_stay_apart_when_written() {
    let g = "G90\nG0 X8 Y-31\nG1 X0 Y-1\nM5\nG1 X0 Y0\nG0 X0 Y1\nG0 X0 Y0\n";
    for start in [None, Some([0.0, 0.0]), Some([8.0, -31.0])] {
        let (d, src) = read(Format::Gcode, g, "p.nc", 1e-4).unwrap();
        assert_eq!(d.pieces.len(), 2);
        let o = OrderOptions { start, ..opts() };
        let r = order(&d, &o).unwrap();
        let out = write(&src, &d, &r.placements).unwrap();
        let (back, _) = read(Format::Gcode, &out, "o.nc", 1e-4).unwrap();
        assert_eq!(back.pieces.len(), 2, "{out}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn readers_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        for f in [Format::Svg, Format::Dxf, Format::Gcode, Format::Json] {
            let _ = read(f, &text, "fuzz", 1e-3);
        }
    }

    #[test]
    fn gcode_from_random_moves_round_trips(moves in proptest::collection::vec((0u8..3, -100i32..100, -100i32..100), 1..30)) {
        let mut g = String::from("G90\n");
        for (k, x, y) in &moves {
            let w = ["G0", "G1", "M5"][*k as usize];
            if w == "M5" { g.push_str("M5\n"); } else { g.push_str(&format!("{w} X{x} Y{y}\n")); }
        }
        if let Ok((d, src)) = read(Format::Gcode, &g, "p.nc", 1e-4) {
            let r = order(&d, &opts()).unwrap();
            let out = write(&src, &d, &r.placements).unwrap();
            let (back, _) = read(Format::Gcode, &out, "o.nc", 1e-4).unwrap();
            prop_assert_eq!(back.pieces.len(), d.pieces.len());
            let total = |d: &Drawing| d.pieces.iter().map(|p| p.path.length()).sum::<f64>();
            prop_assert!((total(&back) - total(&d)).abs() < 1e-6 * (1.0 + total(&d)));
        }
    }
}
