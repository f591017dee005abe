//! Runs u-nesting-cutting's cutting-path optimisation on one sheet of placed parts.
//!
//!     unesting-peer SHEET.json [--time-limit-ms N] [--max-2opt-iterations N] > ORDER.json
//!
//! SHEET.json: `{"parts": [{"id": "p0", "outer": [[x, y], ...], "holes": [[[x, y], ...], ...]}, ...]}`,
//! every polygon already in sheet coordinates (no closing vertex repeated).
//!
//! The crate's entry point, `optimize_cutting_path(&SolveResult, &[Geometry2D], &CuttingConfig)`,
//! takes a nesting result. Each part becomes one `Geometry2D` whose outer ring and holes are the
//! placed polygons, and the `SolveResult` holds one placement per part at (0, 0) with no
//! rotation, so the contours the crate extracts are exactly the sheet's polygons (the same ones
//! written to the SVG that `towpath order` reads). Config: `CuttingConfig::default()` of
//! u-nesting-cutting 0.28.2 (home (0, 0), kerf 0, pierce_candidates 1 = nearest point on the
//! contour, nearest neighbour then constrained 2-opt with max_2opt_iterations 1000 and
//! time_limit_ms 5000, exterior CCW / holes CW). The two options change only those two fields
//! (for diagnostics: `--time-limit-ms 0` = no wall-clock limit on the 2-opt,
//! `--max-2opt-iterations 0` = nearest neighbour only); the benchmark table uses neither.
//!
//! Output: `{"seconds": wall time of optimize_cutting_path, "total_rapid_distance": its own
//! figure, "sequence": [{"contour": "p0o" | "p0h1", "contour_id", "pierce": [x, y],
//! "direction": "ccw" | "cw"}, ...]}`. Contour names: part id + "o" for the outer contour,
//! + "h" + hole index for holes (the ids used in the SVG).

use std::time::Instant;

use serde_json::{json, Value};
use u_nesting_core::{Placement, SolveResult};
use u_nesting_cutting::{optimize_cutting_path, CutDirection, CuttingConfig};
use u_nesting_d2::Geometry2D;

fn ring(v: &Value) -> Vec<(f64, f64)> {
    v.as_array()
        .expect("polygon: array of points")
        .iter()
        .map(|p| (p[0].as_f64().expect("x"), p[1].as_f64().expect("y")))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("usage: unesting-peer SHEET.json [--time-limit-ms N] [--max-2opt-iterations N]");
    let mut config = CuttingConfig::default();
    let mut i = 2;
    while i < args.len() {
        let value = || args.get(i + 1).and_then(|v| v.parse().ok()).expect("option value: a whole number");
        match args[i].as_str() {
            "--time-limit-ms" => config.time_limit_ms = value() as u64,
            "--max-2opt-iterations" => config.max_2opt_iterations = value(),
            other => panic!("unknown option {other}"),
        }
        i += 2;
    }
    let sheet: Value = serde_json::from_str(&std::fs::read_to_string(&path).expect("read sheet")).expect("JSON");
    let parts = sheet["parts"].as_array().expect("parts");

    let mut geometries = Vec::with_capacity(parts.len());
    let mut result: SolveResult<f64> = SolveResult::new();
    // Contour names in the order extract_contours numbers them: per placement, the exterior,
    // then the holes in order.
    let mut names = Vec::new();
    for part in parts {
        let id = part["id"].as_str().expect("id").to_string();
        let mut g = Geometry2D::new(id.clone()).with_polygon(ring(&part["outer"]));
        names.push(format!("{id}o"));
        for (k, h) in part["holes"].as_array().map(|a| a.as_slice()).unwrap_or(&[]).iter().enumerate() {
            g = g.with_hole(ring(h));
            names.push(format!("{id}h{k}"));
        }
        geometries.push(g);
        result.placements.push(Placement::new_2d(id.into(), 0, 0.0, 0.0, 0.0));
    }
    result.boundaries_used = 1;

    let t0 = Instant::now();
    let path = optimize_cutting_path(&result, &geometries, &config).expect("optimize_cutting_path");
    let seconds = t0.elapsed().as_secs_f64();

    let sequence: Vec<Value> = path
        .sequence
        .iter()
        .map(|s| {
            json!({
                "contour": names[s.contour_id],
                "contour_id": s.contour_id,
                "pierce": [s.pierce_point.0, s.pierce_point.1],
                "direction": match s.cut_direction { CutDirection::Ccw => "ccw", CutDirection::Cw => "cw" },
            })
        })
        .collect();
    let out = json!({
        "tool": "u-nesting-cutting 0.28.2",
        "config": "CuttingConfig::default()",
        "time_limit_ms": config.time_limit_ms,
        "max_2opt_iterations": config.max_2opt_iterations,
        "seconds": seconds,
        "computation_time_ms": path.computation_time_ms,
        "total_rapid_distance": path.total_rapid_distance,
        "total_pierces": path.total_pierces,
        "sequence": sequence,
    });
    println!("{out}");
}
