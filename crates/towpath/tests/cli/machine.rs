//! `towpath machine` end to end: the G-code read back (one plunge per cell, cells in a legal
//! order, every cut move inside its feature), the report written, bad parts refused.

use super::common::*;

const PART: &str = r#"{"format": "towpath-part/1", "name": "plate", "origin": [0, 0], "clearance": 5,
 "features": [
  {"id": "face", "boundary": [[0,0],[200,0],[200,100],[0,100]], "depth": 1},
  {"id": "dumbbell", "parent": "face", "depth": 6,
   "boundary": [[10,10],[50,10],[50,26],[90,26],[90,10],[130,10],[130,50],[90,50],[90,34],[50,34],[50,50],[10,50]]},
  {"id": "ring", "parent": "face", "depth": 4, "boundary": [[140,10],[190,10],[190,90],[140,90]],
   "islands": [[[155,35],[175,35],[175,65],[155,65]]]},
  {"id": "slot", "parent": "dumbbell", "depth": 10, "boundary": [[20,20],[40,20],[40,40],[20,40]]}
 ],
 "tools": [{"number": 1, "radius": 3, "step_over": 2, "features": ["face", "dumbbell", "ring"]},
           {"number": 2, "radius": 1, "step_over": 1.5, "features": ["slot", "ring"]}]}"#;

/// `towpath machine PART --solver castelino --time-limit LIMIT --threads 1 --json`, parsed.
fn castelino(part: &std::path::Path, limit: &str) -> serde_json::Value {
    let o = towpath_out(&[
        "machine",
        part.to_str().unwrap(),
        "--solver",
        "castelino",
        "--time-limit",
        limit,
        "--threads",
        "1",
        "--json",
    ]);
    json_of(&o)
}

#[test]
fn machines_a_part_and_the_gcode_keeps_the_hierarchy() {
    let dir = scratch("machine");
    let part = dir.join("part.json");
    std::fs::write(&part, PART).unwrap();
    let nc = dir.join("part.nc");
    let html = dir.join("part.html");
    let o = towpath_out(&[
        "machine",
        part.to_str().unwrap(),
        "-o",
        nc.to_str().unwrap(),
        "--report",
        html.to_str().unwrap(),
        "--iterations",
        "100",
        "--threads",
        "1",
        "--json",
    ]);
    let v = json_of(&o);
    let g = std::fs::read_to_string(&nc).unwrap();
    let report = std::fs::read_to_string(&html).unwrap();
    assert!(report.contains("<svg") && report.contains("T1") && report.contains("T2"));
    let tools = v["tools"].as_array().unwrap();
    assert_eq!(tools.len(), 2);
    // One plunge per cell, per tool, in the order reported; parents before children.
    let cells: Vec<String> =
        g.lines().filter_map(|l| l.strip_prefix("(cell ").map(|s| s.trim_end_matches(')').to_string())).collect();
    let reported: Vec<String> = tools
        .iter()
        .flat_map(|t| t["order"].as_array().unwrap().iter().map(|c| c.as_str().unwrap().to_string()))
        .collect();
    assert_eq!(cells, reported);
    let plunges = g.lines().filter(|l| l.starts_with("G1 Z")).count();
    assert_eq!(plunges, cells.len());
    let t1: Vec<&str> = tools[0]["order"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
    let first_child = t1.iter().position(|c| !c.starts_with("face")).unwrap();
    assert!(
        t1[..first_child].iter().all(|c| c.starts_with("face"))
            && t1[first_child..].iter().all(|c| !c.starts_with("face"))
    );
    // The dumbbell splits for T1: its split cell comes before its two halves.
    let db: Vec<&&str> = t1.iter().filter(|c| c.starts_with("dumbbell")).collect();
    assert_eq!(db.len(), 3);
    assert_eq!(*db[0], "dumbbella");
    assert!(v["rapid_after"].as_f64().unwrap() <= v["rapid_before"].as_f64().unwrap() + 1e-9);
    // Castelino's transformation plans the same part legally.
    let c = castelino(&part, "1");
    assert_eq!(c["solver"], "castelino");
    assert_eq!(c["tools"][0]["cells"], v["tools"][0]["cells"]);
}

#[test]
fn bad_parts_are_refused() {
    let dir = scratch("machine-bad");
    let part = dir.join("bad.json");
    std::fs::write(&part, PART.replace("\"radius\": 3", "\"radius\": 0")).unwrap();
    let (code, _, err) = run(towpath().args(["machine", part.to_str().unwrap()]));
    assert_eq!(code, 2);
    assert!(err.contains("tools[0] (T1)") && err.contains("radius"), "{err}");
    std::fs::write(
        &part,
        PART.replace("[[140,10],[190,10],[190,90],[140,90]]", "[[140,10],[190,90],[190,10],[140,90]]"),
    )
    .unwrap();
    let (code, _, err) = run(towpath().args(["machine", part.to_str().unwrap()]));
    assert_eq!(code, 2);
    assert!(err.contains("\"ring\"") && err.contains("crosses itself"), "{err}");
    let (code, _, err) = run(towpath().args(["machine", dir.join("missing.json").to_str().unwrap()]));
    assert_eq!(code, 2, "{err}");
}

/// A tool's search stops before the time limit: small tools (here 7 and 4 cells of up to 16
/// entries) are solved exactly at once, a larger one (25 cells) stops when its plan stops
/// improving. Before, every tool took the whole limit. And no solver overruns it.
#[test]
fn tools_do_not_wait_for_the_time_limit() {
    let dir = scratch("machine-stall");
    let small = dir.join("small.json");
    std::fs::write(&small, PART).unwrap();
    // (epochs of 0.5 s: the 25-cell tool stops 4 s after its last improvement, which comes
    // within a second on a quiet machine and within a few on a loaded one)
    let limit = 10.0;
    let args = |p: &std::path::Path| {
        towpath_out(&["machine", p.to_str().unwrap(), "--time-limit", "10", "--threads", "1", "--json"])
    };
    let v = json_of(&args(&small));
    for t in v["tools"].as_array().unwrap() {
        assert!(t["solve_seconds"].as_f64().unwrap() < 1.0, "{t}");
    }
    // a face over 24 square pockets in a 4 × 6 grid: 25 cells for one tool
    let pockets: Vec<String> = (0..24)
        .map(|k| {
            let (x, y) = (10 + 40 * (k % 6), 10 + 40 * (k / 6));
            format!(
                r#"{{"id": "p{k}", "parent": "face", "depth": 5, "boundary": [[{x},{y}],[{},{y}],[{},{}],[{x},{}]]}}"#,
                x + 25,
                x + 25,
                y + 25,
                y + 25
            )
        })
        .collect();
    let ids: Vec<String> = (0..24).map(|k| format!("\"p{k}\"")).collect();
    let grid = format!(
        r#"{{"format": "towpath-part/1", "name": "grid", "origin": [0, 0], "clearance": 5,
 "features": [{{"id": "face", "boundary": [[0,0],[250,0],[250,170],[0,170]], "depth": 1}}, {}],
 "tools": [{{"number": 1, "radius": 3, "step_over": 2, "features": ["face", {}]}}]}}"#,
        pockets.join(", "),
        ids.join(", ")
    );
    let part = dir.join("grid.json");
    std::fs::write(&part, grid).unwrap();
    let v = json_of(&args(&part));
    let t = &v["tools"][0];
    assert_eq!(t["cells"], 25);
    assert!(t["solve_seconds"].as_f64().unwrap() < 0.9 * limit, "{t}");
    assert!(v["rapid_after"].as_f64().unwrap() <= v["rapid_before"].as_f64().unwrap() + 1e-9);
    // Castelino's 800-node transformation, whose local search steps take milliseconds each,
    // keeps a short limit too (it ran 1.5 s at a 0.5 s limit when the local search looked at
    // the clock every 256 steps).
    let c = castelino(&part, "0.5");
    let secs = c["tools"][0]["solve_seconds"].as_f64().unwrap();
    assert!(secs < 1.0, "castelino took {secs} s at a 0.5 s limit");
}
