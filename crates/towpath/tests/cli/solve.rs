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
        // towpath's solver reports a lower bound (the assignment relaxation, or the optimum once
        // proven), the papers' solvers none
        match (solver, v["lower_bound"].as_f64()) {
            ("towpath", Some(b)) => assert!(b <= 39.0 + 1e-9, "bound {b} above br17's optimum"),
            ("towpath", None) => panic!("no lower bound from towpath on an ATSP: {v}"),
            (_, b) => assert!(b.is_none(), "{solver}: {b:?}"),
        }

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

/// Writes `text` to a scratch file and runs `towpath solve` on it with `extra` arguments.
fn solve_text(name: &str, text: &str, extra: &[&str]) -> (i32, String, String) {
    let path = scratch_file(name);
    std::fs::write(&path, text).unwrap();
    run(towpath().arg("solve").arg(&path).args(extra))
}

#[test]
fn a_fixed_edge_is_said_to_make_a_path_not_counted_in_the_cost() {
    // A 3-node ATSP with the fixed arc 1 -> 3 (issue 17): the answer is the path 3 -> 2 -> 1,
    // cost c(3,2) + c(2,1) = 1 + 1; the closed tour through 1 -> 3 would add c(1,3) = 100.
    let text = "NAME: f\nTYPE: ATSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\n\
EDGE_WEIGHT_SECTION\n0 5 100\n1 0 7\n9 1 0\nFIXED_EDGES_SECTION\n1 3\n-1\nEOF\n";
    let (code, out, err) = solve_text("fixed.atsp", text, &["--iterations", "10", "--threads", "1"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("cost 2 "), "{out}");
    assert!(out.contains("route: a path from node 3 to node 1"), "{out}");
    assert!(out.contains("fixed arc 1 → 3") && out.contains("not counted in the cost"), "{out}");
    assert!(out.contains("tour: 3 2 1"), "{out}");
    let (code, out, err) = solve_text("fixed2.atsp", text, &["--iterations", "10", "--threads", "1", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["route"], "path");
    assert_eq!(v["cost"], 2.0);
    assert_eq!(v["fixed_edge"], serde_json::json!({"a": 1, "b": 3, "path_from": 3, "path_to": 1, "counted": false}));
    // Without a fixed edge: a closed tour, no fixed_edge field.
    let v = solve_json("br17.atsp", &["--iterations", "100"]);
    assert_eq!(v["route"], "tour");
    assert!(v.get("fixed_edge").is_none());
}

#[test]
fn sizes_taken_on_trust_are_refused_with_their_flag() {
    let att = data("att48.tsp");
    let (code, _, err) =
        run(towpath().arg("solve").arg(&att).args(["--solver", "ga", "--ga-population", "4000000000"]));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("(--ga-population)") && err.contains("at most"), "{err}");
    assert!(!err.contains("memory allocation"), "{err}");
    for threads in ["100000", "0"] {
        let (code, _, err) = run(towpath().arg("solve").arg(&att).args(["--iterations", "10", "--threads", threads]));
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("--threads"), "{err}");
    }
    let (code, _, err) = solve_text("big.tsp", "NAME: big\nTYPE: TSP\nDIMENSION: 5000000000\n", &[]);
    assert_eq!(code, 2);
    assert!(err.contains("DIMENSION 5000000000 is too large") && err.contains("4294967294"), "{err}");
}

#[test]
fn distances_too_large_to_add_up_are_refused() {
    // The reproducer: "cost 46116860184273880000 … proven optimal" before.
    let text = "NAME: far\nTYPE: TSP\nDIMENSION: 5\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n\
1 0 0\n2 3e19 0\n3 1e19 0\n4 4e19 0\n5 2e19 0\nEOF\n";
    let (code, out, err) = solve_text("far.tsp", text, &["--iterations", "10"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("far.tsp:5:") && err.contains("node 1") && err.contains("node 4"), "{err}");
    // A hundred thousand times smaller it is solved to the true optimum, 2 × 4e14 (there and back).
    let (code, out, err) = solve_text("near.tsp", &text.replace("e19", "e14"), &["--iterations", "10"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("cost 800000000000000 ") && out.contains("proven optimal"), "{out}");
}

#[test]
fn other_commands_inputs_are_pointed_to_their_command() {
    let program = "%\nN10 G90 G21\nN20 G0 X0 Y0 Z50\nN30 M20\nN40 G1 X100 F3000\nN50 M21\n%\n";
    for name in ["part.nc", "part.txt"] {
        let (code, _, err) = solve_text(name, program, &[]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("AFP program") && err.contains("towpath optimize"), "{err}");
    }
    let graph = std::fs::read_to_string(fixture("rpp_6re.json")).unwrap();
    let (code, _, err) = solve_text("graph.json", &graph, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("towpath route"), "{err}");
}

/// The kick phase's wall time comes with the kick count (their ratio is the kick rate): within
/// the run's wall time, and above zero when kicks were done.
#[test]
fn json_gives_the_kick_phase_time() {
    let v = solve_json("berlin52.tsp", &["--iterations", "3000"]);
    assert_eq!(v["cost"], 7542.0, "berlin52's published optimum");
    let kicks = v["iterations"].as_u64().unwrap();
    let search = v["search_seconds"].as_f64().unwrap();
    let total = v["time_seconds"].as_f64().unwrap();
    assert!(kicks > 0, "{v}");
    assert!(search > 0.0 && search <= total, "search {search} s of {total} s");
}

/// `--bound` proves how far from optimal the answer can be: on berlin52 the Held–Karp bound is
/// at most the published optimum 7542 and within 1 % of it; without the flag there is none.
#[test]
fn bound_flag_gives_a_held_karp_bound() {
    let v = solve_json("berlin52.tsp", &["--iterations", "3000", "--bound"]);
    let b = v["lower_bound"].as_f64().expect("a bound");
    assert!((0.99 * 7542.0..=7542.0 + 1e-6).contains(&b), "bound {b}");
    let v = solve_json("berlin52.tsp", &["--iterations", "3000"]);
    assert_eq!(v["lower_bound"], serde_json::Value::Null);
}
