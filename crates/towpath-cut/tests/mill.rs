//! Machining: offset loops counted analytically, a dumbbell pocket splitting into cells linked
//! in a legal order, bad parts refused with a message naming the element, and the linking
//! against brute force on small parts.

use towpath_cut::geom::dist;
use towpath_cut::mill::{cells_for_tool, check_plan, offset_levels, plan, read_part, MillOptions};
use towpath_seq::SolveOptions;

fn opts() -> MillOptions {
    MillOptions {
        solve: SolveOptions { time_limit: None, iterations: Some(200), threads: 1, ..SolveOptions::default() },
        ..MillOptions::default()
    }
}

fn rect_part(w: f64, h: f64, r: f64, s: f64) -> String {
    format!(
        r#"{{"format": "towpath-part/1", "features": [{{"id": "p", "boundary": [[0,0],[{w},0],[{w},{h}],[0,{h}]], "depth": 3}}],
            "tools": [{{"number": 1, "radius": {r}, "step_over": {s}, "features": ["p"]}}]}}"#
    )
}

#[test]
fn rectangle_offsets_give_the_analytic_number_of_loops() {
    // Loops at distances r, r + s, r + 2s, ... exist while the distance is below half the
    // shorter side: count = floor((h/2 - r) / s) + 1 (values chosen off the boundary cases).
    for (w, h, r, s) in [(100.0, 40.0, 3.0, 4.0), (60.0, 30.0, 5.0, 2.2), (50.0, 50.0, 1.0, 1.4), (30.0, 9.0, 4.0, 1.0)]
    {
        let part = read_part(&rect_part(w, h, r, s), "rect.json").unwrap();
        let levels = offset_levels(&part.features[0], r, s);
        let expected = (((h / 2.0 - r) / s).floor() as usize) + 1;
        assert_eq!(levels.len(), expected, "{w}×{h}, r {r}, s {s}");
        for (k, level) in levels.iter().enumerate() {
            assert_eq!(level.len(), 1);
            // The k-th loop is the rectangle shrunk by r + k s (rounded corners: bbox exact).
            let d = r + s * k as f64;
            let b = level[0].outer.bbox(1e-4);
            assert!(
                (b[0] - d).abs() < 1e-6
                    && (b[1] - d).abs() < 1e-6
                    && (b[2] - (w - d)).abs() < 1e-6
                    && (b[3] - (h - d)).abs() < 1e-6,
                "{b:?} at {d}"
            );
        }
        let cells = cells_for_tool(&part, 0);
        assert_eq!(cells.len(), 1);
    }
}

const DUMBBELL: &str = r#"{"format": "towpath-part/1", "name": "dumbbell", "origin": [-10, -10],
 "features": [
  {"id": "plate", "boundary": [[-20,-20],[140,-20],[140,60],[-20,60]], "depth": 2},
  {"id": "bell", "parent": "plate", "depth": 8,
   "boundary": [[0,0],[40,0],[40,16],[80,16],[80,0],[120,0],[120,40],[80,40],[80,24],[40,24],[40,40],[0,40]]}
 ],
 "tools": [{"number": 1, "radius": 3, "step_over": 2, "features": ["plate", "bell"]},
           {"number": 2, "radius": 1, "step_over": 1.5, "features": ["bell"]}]}"#;

#[test]
fn dumbbell_splits_into_cells_linked_in_a_legal_order() {
    let part = read_part(DUMBBELL, "dumbbell.json").unwrap();
    // T1 (r 3, s 2): the corridor is 8 wide (half 4): the loop at 3 passes through it, the one
    // at 5 does not, so the bell is one cell of one loop that splits into two cells.
    let cells = cells_for_tool(&part, 0);
    let bell: Vec<_> = cells.iter().filter(|c| part.features[c.feature].id == "bell").collect();
    assert_eq!(bell.len(), 3, "{:?}", bell.iter().map(|c| (&c.id, c.levels.len())).collect::<Vec<_>>());
    assert_eq!(bell[0].levels.len(), 1);
    assert!(bell[0].parent.is_none() && bell[1].parent.is_some() && bell[2].parent.is_some());
    // Each half: a 40×40 square less the corridor side; loops at 5, 7, ... < 20: 8 levels.
    assert_eq!(bell[1].levels.len(), 8);
    assert_eq!(bell[2].levels.len(), 8);
    let o = opts();
    let p = plan(&part, &o).unwrap();
    assert!(check_plan(&part, &p, false).is_empty());
    let t1 = &p.tools[0];
    let plate_cells: Vec<usize> =
        t1.cells.iter().enumerate().filter(|(_, c)| part.features[c.feature].id == "plate").map(|(i, _)| i).collect();
    let bell_cells: Vec<usize> =
        t1.cells.iter().enumerate().filter(|(_, c)| part.features[c.feature].id == "bell").map(|(i, _)| i).collect();
    let at = |c: usize| t1.order.iter().position(|(x, _)| *x == c).unwrap();
    for &pc in &plate_cells {
        for &bc in &bell_cells {
            assert!(at(pc) < at(bc), "plate cell after a bell cell");
        }
    }
    // The split cell before its two halves.
    assert!(at(bell_cells[0]) < at(bell_cells[1]) && at(bell_cells[0]) < at(bell_cells[2]));
    assert!(t1.rapid_after <= t1.rapid_before + 1e-9);
    // Inside-out reverses the cell precedence within the bell.
    let p2 = plan(&part, &MillOptions { inside_out: true, ..opts() }).unwrap();
    assert!(check_plan(&part, &p2, true).is_empty());
    let t = &p2.tools[0];
    let at2 = |c: usize| t.order.iter().position(|(x, _)| *x == c).unwrap();
    assert!(at2(bell_cells[0]) > at2(bell_cells[1]) && at2(bell_cells[0]) > at2(bell_cells[2]));
}

#[test]
fn cell_paths_are_continuous_and_fix_the_exit() {
    let part = read_part(DUMBBELL, "dumbbell.json").unwrap();
    let p = plan(&part, &opts()).unwrap();
    for tp in &p.tools {
        for (_, cp) in &tp.order {
            for w in cp.moves.windows(2) {
                assert!(dist(w[0].end(), w[1].start) < 1e-9);
            }
        }
    }
    // The G-code has one plunge per cell and one tool change per tool.
    let g = towpath_cut::mill::output::gcode(&part, &p);
    let cells: usize = p.tools.iter().map(|t| t.cells.len()).sum();
    assert_eq!(g.lines().filter(|l| l.starts_with("G1 Z")).count(), cells);
    assert_eq!(g.lines().filter(|l| l.ends_with("M6")).count(), 2);
}

#[test]
fn bad_parts_are_refused_with_the_element_named() {
    let zero = rect_part(10.0, 10.0, 0.0, 1.0);
    let e = read_part(&zero, "z.json").unwrap_err().to_string();
    assert!(e.contains("tools[0] (T1)") && e.contains("radius"), "{e}");
    let bow = r#"{"format": "towpath-part/1", "features": [{"id": "bow", "boundary": [[0,0],[10,10],[10,0],[0,10]], "depth": 1}],
        "tools": [{"number": 1, "radius": 1, "features": ["bow"]}]}"#;
    let e = read_part(bow, "b.json").unwrap_err().to_string();
    assert!(e.contains("features[0] (id \"bow\")") && e.contains("crosses itself"), "{e}");
    let unclosed = r#"{"format": "towpath-part/1", "features": [{"id": "u", "boundary": [[0,0],[10,0]], "depth": 1}],
        "tools": [{"number": 1, "radius": 1, "features": ["u"]}]}"#;
    let e = read_part(unclosed, "u.json").unwrap_err().to_string();
    assert!(e.contains("features[0] (id \"u\")") && e.contains("closed"), "{e}");
    let syntax = "{\"format\": \"towpath-part/1\",\n \"features\": [}";
    let e = read_part(syntax, "s.json").unwrap_err().to_string();
    assert!(e.starts_with("s.json:2:"), "{e}");
}
