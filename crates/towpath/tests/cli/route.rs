//! `towpath route` end to end: the binary on a committed fixture, its output checked against the
//! instance independently, and refused input reported with file, line and problem.

use super::common::*;

use towpath_coverage::{read_instance, RppModel};

/// Length of a walk, recomputed from the instance: consecutive vertices must be joined by the
/// stated edge.
fn walk_length(text: &str, walk: &[u64], walk_edges: &[u64]) -> f64 {
    let inst = read_instance(text).unwrap();
    assert_eq!(walk.len(), walk_edges.len() + 1);
    let mut len = 0.0;
    for (i, &k) in walk_edges.iter().enumerate() {
        let e = inst.edges()[k as usize];
        let (u, v) = (walk[i] as u32, walk[i + 1] as u32);
        assert!((e.a == u && e.b == v) || (e.a == v && e.b == u), "step {i} is not along edge {k}");
        len += e.length;
    }
    len
}

#[test]
fn routes_the_fixture_optimally() {
    let path = fixture("rpp_6re.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let exact = {
        let m = RppModel::new(read_instance(&text).unwrap()).unwrap();
        towpath_seq::solve_exact(m.problem()).unwrap().unwrap().cost
    };
    let out_file = scratch_file("route.json");
    let out = towpath()
        .args(["route", path.to_str().unwrap(), "--json", "--time-limit", "1", "-o", out_file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let walk: Vec<u64> = v["walk"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    let edges: Vec<u64> = v["walk_edges"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    let len = walk_length(&text, &walk, &edges);
    assert!((len - exact).abs() < 1e-9, "walk {len} vs exact optimum {exact}");
    assert!((v["length"].as_f64().unwrap() - len).abs() < 1e-9);
    // every required edge served once
    let services = v["services"].as_array().unwrap();
    assert_eq!(services.len(), 6);
    let mut served: Vec<u64> = services.iter().map(|s| s["edge"].as_u64().unwrap()).collect();
    served.sort();
    assert_eq!(served, vec![0, 1, 2, 3, 4, 5]);
    // the file written equals what was printed
    let file: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out_file).unwrap()).unwrap();
    assert_eq!(file["walk"], v["walk"]);
}

#[test]
fn refused_input_names_file_line_and_problem() {
    let text = std::fs::read_to_string(fixture("rpp_6re.json")).unwrap();
    let bad = text.replacen("{\"a\": 0, \"b\": 2,", "{\"a\": 0, \"b\": 99,", 1);
    assert_ne!(bad, text);
    let path = scratch_file("bad.json");
    std::fs::write(&path, &bad).unwrap();
    let out = towpath().args(["route", path.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let line = bad.lines().position(|l| l.contains("\"b\": 99")).unwrap() + 1;
    assert!(err.contains("bad.json"), "{err}");
    assert!(err.contains(&format!("line {line},")), "{err}");
    assert!(err.contains("vertex 99 does not exist"), "{err}");

    let out = towpath().args(["route", "/nonexistent/graph.json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/graph.json"));
}

#[test]
fn generated_instances_are_saved_and_reread() {
    let inst = scratch_file("gen.json");
    let out = towpath()
        .args(["route", "--generate", "10", "--generate-seed", "4", "--time-limit", "0.3", "--threads", "1"])
        .args(["--save-instance", inst.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&inst).unwrap();
    let i = read_instance(&text).unwrap();
    assert_eq!((i.vertices().len(), i.required().len()), (20, 10));
}

#[test]
fn every_solver_gives_a_valid_walk() {
    let path = fixture("rpp_6re.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let exact = {
        let m = RppModel::new(read_instance(&text).unwrap()).unwrap();
        towpath_seq::solve_exact(m.problem()).unwrap().unwrap().cost
    };
    for solver in ["towpath", "doherty", "castelino", "ga", "aco1", "aco2", "aco"] {
        let out = towpath()
            .args([
                "route",
                path.to_str().unwrap(),
                "--json",
                "--time-limit",
                "2",
                "--threads",
                "1",
                "--solver",
                solver,
            ])
            .output()
            .unwrap();
        assert!(out.status.success(), "{solver}: {}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let walk: Vec<u64> = v["walk"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        let edges: Vec<u64> = v["walk_edges"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        let len = walk_length(&text, &walk, &edges);
        assert!(len >= exact - 1e-9, "{solver}: {len} below the optimum {exact}");
        assert!((v["length"].as_f64().unwrap() - len).abs() < 1e-9, "{solver}");
        let name = if solver == "aco" { "aco2" } else { solver };
        assert_eq!(v["solver"], name);
    }
    let out = towpath().args(["route", path.to_str().unwrap(), "--solver", "lkh"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn generated_sizes_are_bounded_and_said() {
    for r in ["4294967296", "5001"] {
        let (code, _, err) = run(towpath().args(["route", "--generate", r, "--time-limit", "1"]));
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("at most 5000"), "{err}");
        assert!(!err.contains("memory allocation"), "{err}");
    }
    let (code, _, err) = run(towpath().args(["route", "--generate", "0"]));
    assert_eq!(code, 2, "{err}");
    let (code, _, err) =
        run(towpath().args(["route", "--generate", "5", "--solver", "ga", "--ga-population", "4000000000"]));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("(--ga-population)"), "{err}");
}

#[test]
fn the_whole_command_honours_its_time_limit() {
    // 3000 required edges: 6000 shortest-path searches (seconds on two cores; 6.5 s with a
    // 1 s limit before, 30 s and more on a loaded machine). Either the command finishes within
    // its limit or it says, within the limit, what the paths need.
    let t0 = std::time::Instant::now();
    let (code, out, err) =
        run(towpath().args(["route", "--generate", "3000", "--time-limit", "0.5", "--threads", "2"]));
    let took = t0.elapsed().as_secs_f64();
    match code {
        0 => assert!(out.contains("verified           : yes"), "{out}"),
        2 => assert!(err.contains("not done within the time limit") && err.contains("give --time-limit"), "{err}"),
        _ => panic!("exit {code}: {err}"),
    }
    // The limit, plus the generation and process start (generous: a shared machine).
    assert!(took < 4.0, "took {took:.1} s");
}

#[test]
fn the_summary_says_the_route_was_verified() {
    let (code, out, err) = run(towpath().arg("route").arg(fixture("rpp_6re.json")).args(["--time-limit", "0.2"]));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("verified           : yes (independent check"), "{out}");
}
