//! `towpath solve` end to end: the built binary on committed fixtures.

use super::common::*;

/// Runs `towpath solve FILE --json` with a deterministic budget and parses the answer.
fn solve_json(file: &str, extra: &[&str]) -> serde_json::Value {
    let path = data(file);
    let mut args = vec!["solve", path.to_str().unwrap(), "--json", "--threads", "1", "--seed", "1"];
    args.extend_from_slice(extra);
    let out = towpath_out(&args);
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
    let path = data("br17.atsp");
    let out = towpath_out(&["solve", path.to_str().unwrap(), "--iterations", "1000", "--threads", "1"]);
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
    let out = towpath_out(&["solve", bad.to_str().unwrap(), "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.tsp:7: expected 2 coordinates for node 2, found 1"), "{stderr}");
    assert!(out.stdout.is_empty());
    let missing = dir.join("missing.tsp");
    let out = towpath_out(&["solve", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

/// The cost of a closed tour over br17's full matrix, read from the file here (independent of
/// the readers and the checker).
fn br17_tour_cost(tour: &[u64]) -> f64 {
    let text = std::fs::read_to_string(data("br17.atsp")).unwrap();
    let body = text.split("EDGE_WEIGHT_SECTION").nth(1).unwrap();
    let m: Vec<f64> = body.split_whitespace().filter_map(|w| w.parse().ok()).collect();
    assert!(m.len() >= 17 * 17);
    (0..tour.len()).map(|i| m[(tour[i] as usize - 1) * 17 + tour[(i + 1) % tour.len()] as usize - 1]).sum()
}

#[test]
fn every_solver_answers_and_says_which_ran() {
    for solver in ["towpath", "doherty", "castelino", "ga", "aco1", "aco2", "aco"] {
        let name = if solver == "aco" { "aco2" } else { solver };
        let v = solve_json("br17.atsp", &["--time-limit", "0.3", "--solver", solver]);
        assert_eq!(v["solver"], name);
        let tour: Vec<u64> = v["tour"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        let mut sorted = tour.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (1..=17).collect::<Vec<_>>(), "{solver}");
        let cost = v["cost"].as_f64().unwrap();
        assert_eq!(cost, br17_tour_cost(&tour), "{solver}: reported cost is the tour's");
        assert!(cost >= 39.0, "{solver}: {cost} below br17's optimum");

        let v = solve_json("ESC07.sop", &["--time-limit", "0.3", "--solver", solver]);
        assert_eq!(v["solver"], name);
        let tour: Vec<u64> = v["tour"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        assert_eq!((tour.first(), tour.last(), tour.len()), (Some(&1), Some(&9), 9), "{solver}");
        assert!(v["cost"].as_f64().unwrap() >= 2125.0, "{solver}");
    }
}

#[test]
fn randomized_solvers_repeat_under_a_seed() {
    for solver in ["ga", "aco1", "aco2"] {
        let path = data("11berlin52.gtsp");
        let run = |seed: &str| {
            let out = towpath_out(&["solve", path.to_str().unwrap(), "--json", "--solver", solver, "--seed", seed]);
            assert!(out.status.success(), "{solver}: {}", String::from_utf8_lossy(&out.stderr));
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            (v["tour"].clone(), v["cost"].as_f64().unwrap())
        };
        let a = run("5");
        assert_eq!(a, run("5"), "{solver}: same seed, same answer");
        assert!(a.1 >= 4040.0, "{solver}: {} below 11berlin52's optimum", a.1);
    }
}

#[test]
fn a_solver_that_cannot_take_the_problem_exits_2() {
    // Seed 000's solver has no consecutive groups; example.json has one.
    let path = data("example.json");
    let out = towpath_out(&["solve", path.to_str().unwrap(), "--solver", "doherty", "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("example.json") && stderr.contains("doherty") && stderr.contains("consecutive"),
        "{stderr}"
    );
    assert!(out.stdout.is_empty());
    // The ant system keeps dense trails: more than 2048 points are refused, not a crash.
    let dir = std::env::temp_dir().join(format!("towpath-solve-aco-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let big = dir.join("grid2500.tsp");
    let mut text =
        String::from("NAME: grid2500\nTYPE: TSP\nDIMENSION: 2500\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n");
    for i in 0..2500 {
        text.push_str(&format!("{} {} {}\n", i + 1, i % 50, i / 50));
    }
    text.push_str("EOF\n");
    std::fs::write(&big, text).unwrap();
    let out = towpath_out(&["solve", big.to_str().unwrap(), "--solver", "aco1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("grid2500.tsp") && stderr.contains("aco1") && stderr.contains("too large"), "{stderr}");
    let out = towpath_out(&["solve", big.to_str().unwrap(), "--solver", "lkh"]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}
