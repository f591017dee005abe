//! What a plan writes: the path file (`towpath-spray-path/1`, documented in `docs/spray.md`), a
//! CSV table of poses, the thickness map as a PLY mesh with a scalar and a colour per vertex, and
//! the one-object summary.

use std::fmt::Write as _;

use serde::Serialize;
use serde_json::{json, Value};
use towpath_geom::Mesh;

use crate::deposition::Gun;
use crate::plan::SprayPlan;
use crate::thickness::ThicknessMap;

/// The `format` of a path file.
pub const FORMAT: &str = "towpath-spray-path/1";

/// What the path file records about the run besides the plan.
#[derive(Debug, Clone, Serialize)]
pub struct Meta {
    /// The surface as given.
    pub surface: String,
    /// Target thickness (µm).
    pub target_thickness_um: f64,
    /// β_th (degrees).
    pub max_deviation_deg: f64,
    /// Pattern asked for.
    pub pattern: String,
    /// Solver used.
    pub solver: String,
    /// Travel speed (mm/s).
    pub travel_speed: f64,
    /// Run-out past free and sharp edges (mm).
    pub overrun: f64,
}

/// The summary object (`--json`): counts, lengths, times, thickness.
pub fn summary(plan: &SprayPlan, map: Option<&ThicknessMap>, meta: &Meta) -> Value {
    let t = &plan.totals;
    let mut patterns = serde_json::Map::new();
    for p in &plan.patches {
        let e = patterns.entry(p.pattern.to_string()).or_insert(json!(0));
        *e = json!(e.as_u64().unwrap_or(0) + 1);
    }
    let mut s = json!({
        "patches": plan.partition.patches.len(),
        "passes": plan.passes.len(),
        "spray_length_mm": t.spray_length_mm,
        "travel_mm": t.travel_mm,
        "turns": t.turns,
        "cycle_time_s": t.cycle_time_s,
        "spray_time_s": t.spray_time_s,
        "poses": plan.poses.len(),
        "patterns": patterns,
        "optimal_spacing_mm": plan.optimum.spacing,
        "optimal_ripple": plan.optimum.ripple,
        "solver": meta.solver,
        "solver_rounds": plan.sequenced.rounds,
        "solver_seconds": plan.sequenced.solver_seconds,
        "lifted_transits": plan.sequenced.lifted,
        "unchecked_transits": plan.sequenced.unchecked,
        "pieces": plan.partition.pieces,
        "presplit_pieces": plan.partition.presplit_pieces,
        "topology_cells": plan.partition.cells,
        "timings": plan.timings,
        "modulation": plan.modulation,
    });
    if let (Some(m), Some(o)) = (map, s.as_object_mut()) {
        o.insert("thickness".into(), thickness_json(m));
    }
    s
}

fn thickness_json(m: &ThicknessMap) -> Value {
    json!({
        "mean": m.interior.mean,
        "min": m.interior.min,
        "max": m.interior.max,
        "rms_rel": m.interior.rms_rel,
        "within_20pct": m.interior.within_20pct,
        "band_mm": m.band,
        "target": m.target,
        "whole": m.whole,
        "uncovered_triangles": m.uncovered_triangles,
    })
}

/// The path file.
pub fn path_json(plan: &SprayPlan, gun: &Gun, map: Option<&ThicknessMap>, meta: &Meta) -> Value {
    let mut order = vec![(usize::MAX, false); plan.passes.len()];
    for (k, s) in plan.sequenced.steps.iter().enumerate() {
        order[s.task.index()] = (k, s.mode == 1);
    }
    let mut first_last = vec![(usize::MAX, 0usize); plan.passes.len()];
    for (i, p) in plan.poses.iter().enumerate() {
        if let Some(id) = p.pass {
            let e = &mut first_last[id as usize];
            e.0 = e.0.min(i);
            e.1 = e.1.max(i);
        }
    }
    let passes: Vec<Value> = plan
        .passes
        .iter()
        .map(|p| {
            let (k, rev) = order[p.id as usize];
            let (f, l) = first_last[p.id as usize];
            json!({
                "id": p.id, "patch": p.patch, "closed": p.closed, "length": p.length, "speed": p.speed,
                "turns": p.turns, "order": k, "reversed": rev, "first_pose": f, "last_pose": l,
            })
        })
        .collect();
    let patches: Vec<Value> = plan
        .partition
        .patches
        .iter()
        .zip(&plan.patches)
        .map(|(p, pl)| {
            let mut v = serde_json::to_value(p).unwrap_or(Value::Null);
            if let (Some(o), Value::Object(extra)) =
                (v.as_object_mut(), serde_json::to_value(pl).unwrap_or(Value::Null))
            {
                for (k, x) in extra {
                    if k != "patch" {
                        o.insert(k, x);
                    }
                }
            }
            v
        })
        .collect();
    let mut doc = json!({
        "format": FORMAT,
        "units": {"length": "mm", "time": "s", "thickness": "um", "flow": "mm3/s", "speed": "mm/s"},
        "meta": meta,
        "gun": gun,
        "summary": summary(plan, map, meta),
        "poses": plan.poses,
        "patches": patches,
        "passes": passes,
    });
    if let (Some(m), Some(o)) = (map, doc.as_object_mut()) {
        let mut t = thickness_json(m);
        if let Some(to) = t.as_object_mut() {
            to.insert("vertex_um".into(), json!(m.vertex));
        }
        o.insert("thickness".into(), t);
    }
    doc
}

/// The poses as a CSV table.
pub fn poses_csv(plan: &SprayPlan) -> String {
    let mut s = String::from("index,time,x,y,z,ax,ay,az,spray,patch,pass\n");
    for (i, p) in plan.poses.iter().enumerate() {
        let opt = |x: Option<u32>| x.map_or(String::new(), |v| v.to_string());
        let _ = writeln!(
            s,
            "{i},{},{},{},{},{},{},{},{},{},{}",
            p.time,
            p.position.x,
            p.position.y,
            p.position.z,
            p.axis.x,
            p.axis.y,
            p.axis.z,
            u8::from(p.spray),
            opt(p.patch),
            opt(p.pass)
        );
    }
    s
}

/// Colour of a thickness: blue at or below 80 % of the target, green at the target, red at or
/// above 120 %, grey where nothing landed.
pub fn colour(t: f64, target: f64) -> [u8; 3] {
    if !(t > 0.0) {
        return [128, 128, 128];
    }
    let s = ((t / target - 0.8) / 0.4).clamp(0.0, 1.0);
    if s < 0.5 {
        [0, (510.0 * s).round() as u8, (255.0 * (1.0 - 2.0 * s)).round() as u8]
    } else {
        [(255.0 * (2.0 * s - 1.0)).round() as u8, (255.0 * (2.0 - 2.0 * s)).round() as u8, 0]
    }
}

/// The thickness map as an ASCII PLY: vertices with `thickness` (µm) and a colour, the faces.
pub fn thickness_ply(mesh: &Mesh, map: &ThicknessMap) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "ply\nformat ascii 1.0");
    let _ = writeln!(
        s,
        "comment towpath spray thickness map: thickness in um; colour blue <= 80 %, green = 100 %, red >= 120 % of the target {} um",
        map.target
    );
    let _ = writeln!(s, "element vertex {}", mesh.positions().len());
    for p in ["x", "y", "z", "thickness"] {
        let _ = writeln!(s, "property double {p}");
    }
    let _ = writeln!(s, "property uchar red\nproperty uchar green\nproperty uchar blue");
    let _ = writeln!(s, "element face {}\nproperty list uchar int vertex_indices\nend_header", mesh.num_faces());
    for (p, &t) in mesh.positions().iter().zip(&map.vertex) {
        let c = colour(t, map.target);
        let _ = writeln!(s, "{} {} {} {} {} {} {}", p.x, p.y, p.z, t, c[0], c[1], c[2]);
    }
    for t in mesh.triangles() {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_ramp() {
        assert_eq!(colour(0.0, 20.0), [128, 128, 128]);
        assert_eq!(colour(10.0, 20.0), [0, 0, 255]);
        assert_eq!(colour(20.0, 20.0), [0, 255, 0]);
        assert_eq!(colour(30.0, 20.0), [255, 0, 0]);
    }
}
