//! Bad inputs: every kind of refusal names the right line and says what is wrong.

use std::path::Path;

use towpath_formats::{parse_instance, parse_tour, read_instance, ErrorKind, FormatError};

/// Parses `text` as `bad.tsp` and returns the error, panicking if it was accepted.
fn refuse(text: &str) -> FormatError {
    match parse_instance(text, Path::new("bad.tsp")) {
        Ok(i) => panic!("accepted: {} ({})\n{text}", i.name, i.kind),
        Err(e) => e,
    }
}

/// Asserts the error's line and that its message contains `needle`.
fn expect(text: &str, line: Option<usize>, needle: &str) -> FormatError {
    let e = refuse(text);
    let msg = e.to_string();
    assert_eq!(e.line(), line, "{msg}");
    assert!(msg.contains(needle), "`{msg}` does not contain `{needle}`");
    match line {
        Some(l) => assert!(msg.starts_with(&format!("bad.tsp:{l}: ")), "{msg}"),
        None => assert!(msg.starts_with("bad.tsp: "), "{msg}"),
    }
    e
}

const HEAD: &str = "NAME: t\nTYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n";

#[test]
fn coordinate_errors_name_the_line() {
    let e = expect(&format!("{HEAD}1 0 0\n2 5\n3 1 1\nEOF\n"), Some(7), "expected 2 coordinates for node 2, found 1");
    assert!(matches!(e.kind(), ErrorKind::CoordinateCount { node: 2, expected: 2, found: 1 }));
    expect(&format!("{HEAD}1 0 0\n2 5 x\n3 1 1\n"), Some(7), "`x` is not a number");
    expect(&format!("{HEAD}1 0 0\n2 5 NaN\n3 1 1\n"), Some(7), "`NaN` is not a finite number");
    expect(&format!("{HEAD}1 0 0\n2 5 inf\n3 1 1\n"), Some(7), "`inf` is not a finite number");
    expect(&format!("{HEAD}1 0 0\n4 5 5\n3 1 1\n"), Some(7), "node 4 is out of range 1..=3");
    expect(&format!("{HEAD}1 0 0\n0 5 5\n3 1 1\n"), Some(7), "node 0 is out of range");
    expect(&format!("{HEAD}1 0 0\n1 5 5\n3 1 1\n"), Some(7), "node 1 is given twice (first on line 6)");
    expect(&format!("{HEAD}1 0 0\n2.5 5 5\n3 1 1\n"), Some(7), "`2.5` is not an integer");
    expect(&format!("{HEAD}1 0 0\n3 1 1\n"), Some(7), "expected 3 (one line per node");
    expect(&format!("{HEAD}1 0 0\n3 1 1\n3 1 1\n"), Some(8), "node 3 is given twice");
}

#[test]
fn header_errors() {
    expect("NAME: t\nTYPE: TSP\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n", None, "missing DIMENSION");
    expect("NAME: t\nDIMENSION: -3\n", Some(2), "DIMENSION: `-3` is not a positive integer");
    expect("NAME: t\nDIMENSION: 0\n", Some(2), "is not a positive integer");
    expect("NAME: t\nDIMENSION: 3\nDIMENSION: 4\n", Some(3), "DIMENSION is given twice (first on line 2)");
    expect("NAME: t\nFOO_BAR: 3\n", Some(2), "unknown keyword `FOO_BAR`");
    expect("NAME: t\n1 2 3\n", Some(2), "expected a keyword");
    expect("NAME: t\nTYPE: CVRP\nDIMENSION: 3\n", Some(2), "TYPE CVRP is not supported");
    expect("TYPE: TOUR\nDIMENSION: 3\n", Some(1), "tour file");
    expect("TYPE: TSP\nDIMENSION: 3\n", None, "missing EDGE_WEIGHT_TYPE");
    expect("TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\n", None, "missing NODE_COORD_SECTION");
    for ty in ["XRAY1", "XRAY2", "SPECIAL", "GEOM"] {
        expect(&format!("TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: {ty}\n"), Some(3), "is not supported");
    }
    expect(
        "TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FUNCTION\nEDGE_WEIGHT_SECTION\n1 2 3\n",
        Some(4),
        "EDGE_WEIGHT_FORMAT FUNCTION is not supported",
    );
    expect(&format!("{HEAD}1 0 0\n2 0 0\n3 0 0\nDEMAND_SECTION\n1 0\n"), Some(9), "DEMAND_SECTION is not supported");
}

#[test]
fn matrix_errors() {
    let head =
        "TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: UPPER_ROW\nEDGE_WEIGHT_SECTION\n";
    assert!(parse_instance(&format!("{head}1 2\n3\nEOF\n"), Path::new("ok.tsp")).is_ok());
    let e = expect(&format!("{head}1 2\nEOF\n"), Some(6), "expected 3 (UPPER_ROW for DIMENSION 3), found 2");
    assert!(matches!(e.kind(), ErrorKind::WrongCount { expected: 3, found: 2, .. }));
    expect(&format!("{head}1 2\n3 4\n"), Some(7), "found 4");
    expect(&format!("{head}1 2\n3 y\n"), Some(7), "`y` is not a number");
    expect(&format!("{head}1 2\n3 1e999\n"), Some(7), "`1e999` is not a finite number");
    expect(
        "TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_SECTION\n1 2 3\n",
        None,
        "missing EDGE_WEIGHT_FORMAT",
    );
}

#[test]
fn sop_precedence_errors_map_back_to_nodes() {
    // Row 2 says 3 precedes 2, row 3 says 2 precedes 3: a cycle.
    let text = "TYPE: SOP\nDIMENSION: 4\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n4\n\
                0 1 1 1\n-1 0 -1 1\n-1 -1 0 1\n-1 -1 -1 0\nEOF\n";
    let e = expect(text, Some(8), "precedence cycle: node 3 -> node 2 -> node 3");
    assert!(matches!(e.kind(), ErrorKind::PrecedenceCycle(_)));
    // Node 1 must be first but row 1 says node 2 precedes it.
    let text =
        "TYPE: SOP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n\
                0 -1 1\n1 0 1\n-1 -1 0\n";
    expect(text, Some(6), "node 1 must come first, but node 2 must precede it");
    let text =
        "TYPE: SOP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n\
                0 1 -1\n-1 0 1\n-1 -1 0\n";
    expect(text, Some(6), "precedence cycle");
    expect("TYPE: SOP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\n", Some(3), "a SOP needs EDGE_WEIGHT_TYPE EXPLICIT");
}

const GTSP: &str = "TYPE: GTSP\nDIMENSION: 4\nGTSP_SETS: 2\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n\
                    1 0 0\n2 1 0\n3 2 0\n4 3 0\nGTSP_SET_SECTION\n";

#[test]
fn gtsp_set_errors() {
    assert!(parse_instance(&format!("{GTSP}1 1 2 -1\n2 3\n4 -1\n"), Path::new("ok.gtsp")).is_ok());
    expect(&format!("{GTSP}1 1 2 -1\n2 3 -1\n"), Some(10), "node 4 is in no set (1 nodes are in no set)");
    expect(&format!("{GTSP}1 1 2 -1\n2 3 2 4 -1\n"), Some(12), "node 2 is in set 1 and in set 2");
    expect(&format!("{GTSP}1 1 2 -1\n3 3 4 -1\n"), Some(12), "set 3 is out of range 1..=2");
    expect(&format!("{GTSP}1 1 2 -1\n1 3 4 -1\n"), Some(12), "set 1 is defined twice (first on line 11)");
    expect(&format!("{GTSP}1 1 2 -1\n2 3 4\n"), Some(12), "the list of set 2 is not terminated by -1");
    expect(&format!("{GTSP}1 1 2 -1\n2 -1\n"), Some(12), "set 2 has no nodes");
    expect(&format!("{GTSP}1 1 2 -1\n2 3 9 -1\n"), Some(12), "node 9 is out of range 1..=4");
    expect(&format!("{GTSP}1 1 2 3 4 -1\n"), Some(3), "GTSP_SET_SECTION: expected 2");
    expect(&GTSP.replace("GTSP_SETS: 2", "GTSP_SETS: 9"), Some(3), "GTSP_SETS: `9` is not a set count in 1..=4");
    expect("TYPE: GTSP\nDIMENSION: 4\nEDGE_WEIGHT_TYPE: EUC_2D\n", None, "missing GTSP_SET_SECTION");
}

#[test]
fn pcglns_errors_name_sets_and_lines() {
    let base = format!(
        "{}1 1 -1\n2 2 3 -1\n3 4 -1\n",
        GTSP.replace("TYPE: GTSP", "TYPE: PCGLNS").replace("GTSP_SETS: 2", "GTSP_SETS: 3")
    );
    let ok = format!("{base}GTSP_SET_ORDERING\n2 3 -1\nSTART_GROUP_SECTION\n1\nEOF\n");
    assert!(parse_instance(&ok, Path::new("ok.pcglns")).is_ok());
    let cyc = format!("{base}GTSP_SET_ORDERING\n2 3 -1\n3 2 -1\nSTART_GROUP_SECTION\n1\n");
    let e = expect(&cyc, Some(16), "precedence cycle: set 3 -> set 2 -> set 3");
    assert!(matches!(e.kind(), ErrorKind::PrecedenceCycle(c) if c.len() == 2));
    let start = format!("{base}GTSP_SET_ORDERING\n2 1 -1\nSTART_GROUP_SECTION\n1\n");
    expect(&start, Some(15), "set 1 must come first, but set 2 must precede it");
    expect(&format!("{base}GTSP_SET_ORDERING\n2 3 -1\n"), None, "missing START_GROUP_SECTION");
    expect(
        &format!("{base}GTSP_SET_ORDERING\n2 7 -1\nSTART_GROUP_SECTION\n1\n"),
        Some(15),
        "set 7 is out of range 1..=3",
    );
    expect(&format!("{base}START_GROUP_SECTION\n5\n"), Some(15), "set 5 is out of range");
    expect(&format!("{base}START_GROUP_SECTION\n1 2\n"), Some(14), "START_GROUP_SECTION: expected 1");
}

#[test]
fn tour_errors() {
    let t = |s: &str| parse_tour(s, Path::new("x.tour"));
    assert_eq!(t("TYPE: TOUR\nDIMENSION: 3\nTOUR_SECTION\n1 3\n2\n-1\nEOF\n").unwrap().nodes, vec![1, 3, 2]);
    let e = t("TYPE: TOUR\nDIMENSION: 3\nTOUR_SECTION\n1 3\n3\n-1\n").unwrap_err();
    assert_eq!(e.to_string(), "x.tour:5: node 3 is given twice (first on line 4)");
    let e = t("TYPE: TOUR\nDIMENSION: 3\nTOUR_SECTION\n1 3\n-1\n").unwrap_err();
    assert!(e.to_string().contains("expected 3"), "{e}");
    let e = t("TYPE: TOUR\nDIMENSION: 3\nTOUR_SECTION\n1 3\n0\n-1\n").unwrap_err();
    assert_eq!(e.to_string(), "x.tour:5: TOUR_SECTION: `0` is not a node number (1 or more) or -1");
    assert!(t("TYPE: TOUR\nDIMENSION: 3\n").unwrap_err().to_string().contains("missing TOUR_SECTION"));
}

#[test]
fn unreadable_file() {
    let e = read_instance(Path::new("/nonexistent/towpath/x.tsp")).unwrap_err();
    assert!(matches!(e.kind(), ErrorKind::Io(_)));
    assert!(e.to_string().starts_with("/nonexistent/towpath/x.tsp: cannot read the file"), "{e}");
}
