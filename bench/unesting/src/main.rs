//! Runs u-nesting-cutting's `optimize_cutting_path` on a sheet of parts already placed (the
//! same contours `towpath order` gets as SVG), for `bench/unesting.py`.
//!
//! Input JSON: `{"parts": [{"outer": [[x, y], ...], "holes": [[[x, y], ...], ...]}, ...]}` in
//! sheet coordinates. Each part becomes a `Geometry2D` placed at (0, 0) without rotation, so the
//! crate sees exactly these coordinates. Output JSON: the contours in the crate's order with
//! their pierce points, the crate's own rapid total and the wall time of the call.
//!
//!     unesting-peer SHEET.json [PIERCE_CANDIDATES]

use std::time::Instant;

use serde_json::{json, Value};
use u_nesting_core::{Placement, SolveResult};
use u_nesting_cutting::{optimize_cutting_path, ContourType, CuttingConfig};
use u_nesting_d2::Geometry2D;

fn ring(v: &Value) -> Vec<(f64, f64)> {
    v.as_array()
        .map(|pts| {
            pts.iter()
                .filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?)))
                .collect()
        })
        .unwrap_or_default()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).expect("read the sheet");
    let sheet: Value = serde_json::from_str(&text).expect("parse the sheet");
    let parts = sheet["parts"].as_array().expect("parts");
    let mut geoms = Vec::new();
    let mut result = SolveResult::<f64>::new();
    for (i, p) in parts.iter().enumerate() {
        let id = format!("P{i}");
        let mut g = Geometry2D::new(id.clone()).with_polygon(ring(&p["outer"]));
        for h in p["holes"].as_array().into_iter().flatten() {
            g = g.with_hole(ring(h));
        }
        geoms.push(g);
        result.placements.push(Placement::new_2d(id, 0, 0.0, 0.0, 0.0));
    }
    let mut config = CuttingConfig::default();
    if let Some(k) = args.get(2).and_then(|s| s.parse().ok()) {
        config.pierce_candidates = k;
    }
    let t0 = Instant::now();
    let path = optimize_cutting_path(&result, &geoms, &config);
    let seconds = t0.elapsed().as_secs_f64();
    // Contour ids: per placement, its exterior and then its holes (extract_contours' order).
    let mut names = Vec::new();
    for (i, p) in parts.iter().enumerate() {
        names.push(json!({"part": i, "hole": null}));
        for k in 0..p["holes"].as_array().map_or(0, |h| h.len()) {
            names.push(json!({"part": i, "hole": k}));
        }
    }
    let order: Vec<Value> = path
        .sequence
        .iter()
        .map(|s| {
            json!({
                "contour": names.get(s.contour_id).cloned().unwrap_or(Value::Null),
                "interior": s.contour_type == ContourType::Interior,
                "pierce": [s.pierce_point.0, s.pierce_point.1],
            })
        })
        .collect();
    let out = json!({
        "order": order,
        "total_rapid_distance": path.total_rapid_distance,
        "pierces": path.total_pierces,
        "seconds": seconds,
    });
    println!("{out}");
}
