//! The JSON format: located errors, defaults, route ends.

use std::path::Path;

use towpath_formats::{parse_instance, parse_json, with_problem, ErrorKind, FormatError, LoadedProblem};
use towpath_seq::{End, StateId};

fn refuse(text: &str) -> FormatError {
    match parse_json(text, Path::new("p.json")) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts the error's line and column and a part of its message.
fn expect(text: &str, line: usize, column: usize, needle: &str) {
    let e = refuse(text);
    let msg = e.to_string();
    assert_eq!((e.line(), e.column()), (Some(line), Some(column)), "{msg}");
    assert!(msg.starts_with(&format!("p.json:{line}:{column}: ")), "{msg}");
    assert!(msg.contains(needle), "`{msg}` does not contain `{needle}`");
}

const BASE: &str = r#"{
  "states": { "points": [[0, 0], [3, 4], [6, 8]] },
  "tasks": [
    { "id": "a", "modes": [ { "entry": 0 } ] },
    { "id": "b", "modes": [ { "entry": 1, "exit": 2, "cost": 1.5 } ] }
  ],
  "precedence": [ ["a", "b"] ],
  "end": "free"
}"#;

#[test]
fn defaults_and_costs() {
    let inst = parse_json(BASE, Path::new("dir/p.json")).unwrap();
    assert_eq!(inst.name, "p", "the default name is the file name");
    assert_eq!(inst.dimension, 3);
    let LoadedProblem::Points(p) = &inst.problem else { panic!("points give point costs") };
    assert_eq!(p.end(), End::Free);
    assert_eq!(p.modes(towpath_seq::TaskId(1))[0].exit, StateId(2));
    // a (state 0) then b: 5 to state 1, 1.5 inside b; open path.
    let steps = inst.steps_from_tasks(&[
        towpath_formats::TaskStep { task: "a".into(), mode: 0 },
        towpath_formats::TaskStep { task: "b".into(), mode: 0 },
    ]);
    assert_eq!(inst.problem.check(&steps.unwrap()).unwrap(), 6.5);
}

#[test]
fn matrix_states_with_forbidden_moves() {
    let text = r#"{"states": {"matrix": [[0, null], [2, 0]]},
        "tasks": [{"id": "x", "modes": [{"entry": 0}]}, {"id": "y", "modes": [{"entry": 1}]}],
        "end": "free"}"#;
    let inst = parse_instance(text, Path::new("m.txt")).unwrap();
    with_problem!(&inst.problem, p => {
        assert_eq!(p.transition(StateId(0), StateId(1)), f64::INFINITY);
        assert_eq!(p.transition(StateId(1), StateId(0)), 2.0);
    });
}

#[test]
fn syntax_and_type_errors_carry_serde_positions() {
    expect(&BASE.replace(r#""entry": 0 }"#, r#""entry": "zero" }"#), 4, 45, "found string");
    expect(&BASE.replace(r#""end": "free""#, r#""end": "open""#), 8, 15, "unknown variant `open`");
    expect(&BASE.replace(r#""precedence""#, r#""precedense""#), 7, 14, "unknown field `precedense`");
    let e = refuse("{\n  \"states\": ");
    assert_eq!(e.line(), Some(2));
    assert!(matches!(e.kind(), ErrorKind::Json(_)));
}

#[test]
fn semantic_errors_are_located_by_path() {
    expect(&BASE.replace(r#"["a", "b"]"#, r#"["a", "c"]"#), 7, 25, r#"precedence[0][1]: unknown task id "c""#);
    expect(&BASE.replace(r#""exit": 2"#, r#""exit": 7"#), 5, 51, "tasks[1].modes[0].exit: state 7 is out of range");
    expect(&BASE.replace(r#""id": "b""#, r#""id": "a""#), 5, 13, r#"task id "a" is used twice (first by tasks[0])"#);
    expect(&BASE.replace(r#"[ { "entry": 0 } ]"#, "[]"), 4, 5, r#"tasks[0]: task "a" has no modes"#);
    expect(&BASE.replace("[6, 8]", "[6]"), 2, 42, "states.points[2]: a point has 2 or 3 coordinates, found 1");
    expect(
        &BASE.replace(r#"["a", "b"]"#, r#"["a", "b"], ["b", "a"]"#),
        7,
        31,
        r#"precedence cycle: task "b" -> task "a" -> task "b""#,
    );
    expect(&BASE.replace(r#""end": "free""#, r#""end": "closed""#), 7, 17, "has no beginning");
    expect(&BASE.replace(r#""end": "free""#, r#""end": {"at": 9}"#), 8, 17, "end.at: state 9 is out of range");
    expect(
        &BASE.replace(r#""end": "free""#, r#""end": "free", "first": "b""#),
        8,
        27,
        r#"task "b" must come first, but task "a" must precede it"#,
    );
}
