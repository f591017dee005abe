//! `towpath solve` end to end: the built binary on committed fixtures.

use std::path::PathBuf;
use std::process::{Command, Output};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../towpath-formats/tests/data").join(name)
}

fn towpath(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_towpath")).args(args).output().expect("the binary runs")
}

/// Runs `towpath solve FILE --json` with a deterministic budget and parses the answer.
fn solve_json(file: &str, extra: &[&str]) -> serde_json::Value {
    let path = fixture(file);
    let mut args = vec!["solve", path.to_str().unwrap(), "--json", "--threads", "1", "--seed", "1"];
    args.extend_from_slice(extra);
    let out = towpath(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{file}: {stderr}");
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{file}: not JSON ({e})"))
}

#[test]
fn json_output_of_a_tsp_has_the_optimum_and_a_tour_from_node_1() {
    let v = solve_json("burma14.tsp", &["--iterations", "2000"]);
    assert_eq!(v["name"], "burma14");
    assert_eq!(v["type"], "TSP");
    assert_eq!(v["dimension"], 14);
    assert_eq!(v["cost"], 3323.0, "burma14's published optimum");
    assert_eq!(v["seed"], 1);
    assert_eq!(v["threads"], 1);
    assert!(v["iterations"].as_u64().is_some());
    assert!(v["time_seconds"].as_f64().is_some());
    let mut tour: Vec<u64> = v["tour"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    assert_eq!(tour[0], 1);
    tour.sort_unstable();
    assert_eq!(tour, (1..=14).collect::<Vec<_>>());
}

#[test]
fn sop_answer_is_the_path_from_node_1_to_node_n() {
    let v = solve_json("ESC07.sop", &["--iterations", "500"]);
    assert_eq!(v["type"], "SOP");
    assert_eq!(v["cost"], 2125.0, "ESC07's optimum");
    let tour: Vec<u64> = v["tour"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    assert_eq!((tour.first(), tour.last(), tour.len()), (Some(&1), Some(&9), 9));
}

#[test]
fn json_problem_answer_names_tasks_and_modes() {
    let v = solve_json("example.json", &["--time-limit", "1"]);
    assert_eq!(v["type"], "JSON");
    let tour = v["tour"].as_array().unwrap();
    assert_eq!(tour.len(), 4);
    assert!(tour.iter().all(|s| s["task"].is_string() && s["mode"].is_u64()));
}

#[test]
fn summary_says_checked() {
    let path = fixture("br17.atsp");
    let out = towpath(&["solve", path.to_str().unwrap(), "--iterations", "1000", "--threads", "1"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(stdout.starts_with("br17 (ATSP, dimension 17, 17 tasks): cost 39 "), "{stdout}");
    assert!(stdout.contains("checked") && stdout.contains("tour: 1 "), "{stdout}");
}

#[test]
fn malformed_file_exits_2_with_file_and_line() {
    let dir = std::env::temp_dir().join(format!("towpath-solve-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.tsp");
    std::fs::write(
        &bad,
        "NAME: bad\nTYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n2 5\n3 1 1\nEOF\n",
    )
    .unwrap();
    let out = towpath(&["solve", bad.to_str().unwrap(), "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.tsp:7: expected 2 coordinates for node 2, found 1"), "{stderr}");
    assert!(out.stdout.is_empty());
    let missing = dir.join("missing.tsp");
    let out = towpath(&["solve", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}
