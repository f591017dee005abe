//! The robot path: the poses of every pass in order and direction, joined by transits, with
//! time stamps.

use glam::DVec3;

use crate::deposition::Pose;
use crate::passes::Pass;
use crate::sequence::Sequenced;

/// Totals of a path.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct PathTotals {
    /// Length sprayed, measured along the aimed points on the surface (mm).
    pub spray_length_mm: f64,
    /// Length travelled with the spray off (mm).
    pub travel_mm: f64,
    /// Stops and turns: one per pass end joined to the next pass, plus turns sharper than 45°
    /// inside passes.
    pub turns: usize,
    /// Time of the last pose (s).
    pub cycle_time_s: f64,
    /// Time spent spraying (s).
    pub spray_time_s: f64,
}

/// Builds the poses of a sequenced plan. On passes the aimed point moves at the pass speed,
/// transits run at `travel_speed` (mm/s).
pub fn assemble(passes: &[Pass], seq: &Sequenced, home: Option<DVec3>, travel_speed: f64) -> (Vec<Pose>, PathTotals) {
    let mut poses: Vec<Pose> = Vec::new();
    let mut totals = PathTotals::default();
    let mut t = 0.0;
    if let (Some(h), Some(first)) = (home, seq.steps.first()) {
        let p = &passes[first.task.index()];
        let i = if first.mode == 0 { 0 } else { p.axes.len() - 1 };
        poses.push(Pose { position: h, axis: p.axes[i], time: 0.0, spray: false, patch: None, pass: None });
    }
    for (k, step) in seq.steps.iter().enumerate() {
        let p = &passes[step.task.index()];
        let order: Vec<usize> =
            if step.mode == 0 { (0..p.positions.len()).collect() } else { (0..p.positions.len()).rev().collect() };
        let first = order[0];
        if let Some(Some(tr)) = seq.transits.get(k) {
            let from = poses.last().map(|q| (q.position, q.axis));
            if let Some((mut prev, a0)) = from {
                let a1 = p.axes[first];
                let n = tr.via.len() + 1;
                for (j, &v) in tr.via.iter().enumerate() {
                    t += prev.distance(v) / travel_speed;
                    let axis = a0.lerp(a1, (j + 1) as f64 / n as f64).try_normalize().unwrap_or(a1);
                    poses.push(Pose { position: v, axis, time: t, spray: false, patch: None, pass: None });
                    prev = v;
                }
                t += prev.distance(p.positions[first]) / travel_speed;
                totals.travel_mm += tr.length;
                totals.turns += 1;
            }
        }
        let mut prev = p.positions[first];
        let mut prev_target = p.targets[first];
        for (j, &i) in order.iter().enumerate() {
            let pos = p.positions[i];
            if j > 0 {
                // The speed is that of the aimed point along the surface.
                let d = prev.distance(pos);
                let aim = prev_target.distance(p.targets[i]);
                let dt = if aim > 0.0 { aim } else { d } / p.speed;
                t += dt;
                totals.spray_length_mm += aim;
                totals.spray_time_s += dt;
            }
            let spray = j + 1 < order.len();
            let same_as_last =
                poses.last().is_some_and(|q| q.position.distance(pos) < 1e-9 && q.axis.distance(p.axes[i]) < 1e-12);
            let pose = Pose { position: pos, axis: p.axes[i], time: t, spray, patch: Some(p.patch), pass: Some(p.id) };
            if same_as_last && j == 0 {
                // The previous pass ended exactly here: this pose starts the new pass.
                if let Some(last) = poses.last_mut() {
                    *last = Pose { time: last.time, ..pose };
                }
            } else {
                poses.push(pose);
            }
            prev = pos;
            prev_target = p.targets[i];
        }
        totals.turns += p.turns;
    }
    // Time stamps must increase strictly: a zero-length move (it cannot happen between distinct
    // poses) gets a nanosecond.
    for i in 1..poses.len() {
        if poses[i].time <= poses[i - 1].time {
            poses[i].time = poses[i - 1].time + 1e-9;
        }
    }
    totals.cycle_time_s = poses.last().map_or(0.0, |p| p.time);
    (poses, totals)
}
