//! Sizes and magnitudes taken from files (issue 17): counts too large for towpath are refused as
//! too large (not as "not an integer"), integer costs too large to add up exactly are refused
//! naming the nodes or the entry, a JSON problem that is not an object is refused as what it is,
//! and a matrix export whose size is not bounded by the file is refused before it is made.

use std::path::Path;

use towpath_formats::{parse_instance, CostsAs, ErrorKind, FormatError, MAX_MATRIX_ENTRIES};
use towpath_seq::{check, Step, TaskId};

fn refuse(text: &str, name: &str) -> FormatError {
    match parse_instance(text, Path::new(name)) {
        Ok(i) => panic!("accepted: {} ({})\n{text}", i.name, i.kind),
        Err(e) => e,
    }
}

#[test]
fn counts_too_large_say_so_with_the_bound() {
    for value in ["5000000000", "4294967295", "99999999999999999999999999"] {
        let e = refuse(&format!("NAME: t\nDIMENSION: {value}\n"), "big.tsp");
        assert!(matches!(e.kind(), ErrorKind::TooLarge { .. }), "{e}");
        assert_eq!(e.line(), Some(2));
        let msg = e.to_string();
        assert!(msg.contains("DIMENSION") && msg.contains("too large") && msg.contains("4294967294"), "{msg}");
    }
    for value in ["0", "-3", "4.5", "x"] {
        let e = refuse(&format!("NAME: t\nDIMENSION: {value}\n"), "bad.tsp");
        assert!(e.to_string().contains("is not a positive integer"), "{e}");
    }
    let gtsp = "TYPE: GTSP\nDIMENSION: 2\nGTSP_SETS: 88888888888\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n\
1 0 0\n2 1 1\nGTSP_SET_SECTION\n1 1 2 -1\nEOF\n";
    let e = refuse(gtsp, "big.gtsp");
    assert!(matches!(e.kind(), ErrorKind::TooLarge { .. }), "{e}");
}

/// Five nodes on a line: the issue's reproducer at x = 0, 3e19, 1e19, 4e19, 2e19.
const FAR: &str = "NAME: far\nTYPE: TSP\nDIMENSION: 5\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n\
1 0 0\n2 3e19 0\n3 1e19 0\n4 4e19 0\n5 2e19 0\nEOF\n";

#[test]
fn integer_distances_too_large_to_add_up_are_refused_naming_the_nodes() {
    let e = refuse(FAR, "far.tsp");
    let msg = e.to_string();
    assert!(matches!(e.kind(), ErrorKind::InexactCosts { moves: 5, .. }), "{msg}");
    assert!(msg.contains("node 1") && msg.contains("node 4") && msg.contains("4e19 apart"), "{msg}");
    assert!(msg.starts_with("far.tsp:5: "), "{msg}");
    // A thousand times smaller the tour still adds up exactly, and every distance is the exact
    // difference of the coordinates (the old rounding saturated at 2^63 ≈ 9.2e18).
    let near = FAR.replace("e19", "e12");
    let inst = parse_instance(&near, Path::new("near.tsp")).unwrap();
    let steps = |order: &[u32]| order.iter().map(|&t| Step { task: TaskId(t), mode: 0 }).collect::<Vec<_>>();
    assert_eq!(inst.problem.check(&steps(&[0, 1, 2, 3, 4])).unwrap(), 12e12);
    assert_eq!(inst.problem.check(&steps(&[0, 2, 4, 1, 3])).unwrap(), 8e12);
    towpath_formats::with_problem!(&inst.problem, p => {
        assert_eq!(check(p, &steps(&[0, 4, 2, 1, 3])).unwrap(), 10e12);
    });
    // The same in a JSON problem with a rounded metric, and in an explicit matrix.
    let json = r#"{"states": {"points": [[0, 0], [3e19, 0], [1e19, 0]], "metric": "euclidean_nint"},
        "tasks": [{"id": "a", "modes": [{"entry": 0}]}, {"id": "b", "modes": [{"entry": 1}]}, {"id": "c", "modes": [{"entry": 2}]}]}"#;
    let e = refuse(json, "far.json");
    assert!(e.to_string().contains("states.points[0]") && e.to_string().contains("states.points[1]"), "{e}");
    let matrix = "NAME: m\nTYPE: ATSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\n\
EDGE_WEIGHT_SECTION\n0 1 2\n3 0 9e18\n5 6 0\nEOF\n";
    let e = refuse(matrix, "m.atsp");
    assert_eq!(e.line(), Some(8), "{e}");
    assert!(e.to_string().contains("node 2 to node 3 is 9000000000000000000"), "{e}");
    // Unrounded distances (JSON "euclidean") are floating point: large values are fine as long
    // as a route's cost is a number towpath adds up.
    let json_float = json.replace("euclidean_nint", "euclidean");
    assert!(parse_instance(&json_float, Path::new("f.json")).is_ok());
    let e = refuse(&json.replace("euclidean_nint", "euclidean").replace("3e19", "1e200"), "h.json");
    assert!(e.to_string().contains("costs are too large"), "{e}");
}

#[test]
fn a_json_problem_must_be_objects() {
    for (text, found) in [("[1,2,3]", "an array"), ("\"x\"", "string"), ("5", "integer")] {
        let e = refuse(text, "a.json");
        let msg = e.to_string();
        assert!(msg.contains("expected a problem object") && msg.contains(found), "{msg}");
        assert!(!msg.contains("expected a string"), "{msg}");
    }
    let task_as_array = r#"{"states": {"points": [[0, 0]]}, "tasks": [["a", [{"entry": 0}]]]}"#;
    let e = refuse(task_as_array, "t.json");
    assert!(e.to_string().contains("expected a task object") && e.to_string().contains("an array"), "{e}");
    let e = refuse(r#"{"states": [[0, 0]], "tasks": []}"#, "s.json");
    assert!(e.to_string().contains("expected a states object"), "{e}");
    let e = refuse(r#"{"states": {"points": [[0, 0]]}, "tasks": 5}"#, "n.json");
    assert!(e.to_string().contains("expected an array, found integer `5`"), "{e}");
}

#[test]
fn a_matrix_export_of_points_is_bounded() {
    let n = (MAX_MATRIX_ENTRIES as f64).sqrt() as usize + 1;
    let mut text = format!("NAME: big\nTYPE: TSP\nDIMENSION: {n}\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n");
    for i in 1..=n {
        text.push_str(&format!("{i} {i} 0\n"));
    }
    let inst = parse_instance(&text, Path::new("big.tsp")).unwrap();
    let e = inst.to_json(CostsAs::Matrix).unwrap_err();
    assert!(e.to_string().contains(&format!("{n} × {n}")), "{e}");
    assert!(inst.to_json(CostsAs::Native).is_ok());
}
