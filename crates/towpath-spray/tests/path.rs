//! The robot path is legal: every pass once, in one of its two directions; time stamps
//! increase; transits keep the clearance from the part (checked by brute force against every
//! triangle).

mod common;

use common::*;
use glam::DVec3;
use towpath_geom::{closest_point_on_triangle, Mesh};
use towpath_spray::transit::CLEARANCE;
use towpath_spray::{plan, SprayPlan};

fn distance(mesh: &Mesh, p: DVec3) -> f64 {
    (0..mesh.num_faces() as u32)
        .map(|f| {
            let [a, b, c] = mesh.corners(f);
            let w = closest_point_on_triangle(p, a, b, c);
            (a * w.x + b * w.y + c * w.z).distance(p)
        })
        .fold(f64::INFINITY, f64::min)
}

fn check_legal(mesh: &Mesh, plan: &SprayPlan, standoff: f64, home: Option<DVec3>) {
    let poses = &plan.poses;
    // Time stamps increase.
    for w in poses.windows(2) {
        assert!(w[1].time > w[0].time, "{} then {}", w[0].time, w[1].time);
    }
    if let Some(h) = home {
        assert_eq!(poses[0].position, h);
        assert_eq!(poses[0].time, 0.0);
    }
    // Every pass once, contiguous, forward or backward, sprayed up to its last pose.
    let mut seen = vec![false; plan.passes.len()];
    let mut i = 0;
    while i < poses.len() {
        let Some(id) = poses[i].pass else {
            i += 1;
            continue;
        };
        assert!(!seen[id as usize], "pass {id} sprayed twice");
        seen[id as usize] = true;
        let mut j = i;
        while j < poses.len() && poses[j].pass == Some(id) {
            j += 1;
        }
        let run: Vec<DVec3> = poses[i..j].iter().map(|p| p.position).collect();
        let pass = &plan.passes[id as usize];
        let fwd = run == pass.positions;
        let rev = run.iter().rev().copied().collect::<Vec<_>>() == pass.positions;
        assert!(fwd || rev, "pass {id} is not sprayed along its poses");
        for (k, p) in poses[i..j].iter().enumerate() {
            assert_eq!(p.spray, k + 1 < j - i, "spray on along the pass, off at its end");
            assert_eq!(p.patch, Some(pass.patch));
        }
        i = j;
    }
    assert!(seen.iter().all(|&s| s), "every pass sprayed");
    // Transits: spray-off moves keep the clearance, sampled every millimetre or so.
    let need = CLEARANCE * standoff - standoff / 50.0 - 1e-6;
    let mut lifted = 0;
    for w in poses.windows(2) {
        if w[0].spray {
            continue;
        }
        if w[0].pass.is_none() || w[1].pass.is_none() {
            lifted += 1;
        }
        let n = (w[0].position.distance(w[1].position) / 5.0).ceil().max(1.0) as usize;
        for k in 0..=n {
            let p = w[0].position.lerp(w[1].position, k as f64 / n as f64);
            let d = distance(mesh, p);
            assert!(d >= need, "transit point {p} is {d} from the part (need {need})");
        }
    }
    let _ = lifted;
}

#[test]
fn box_path_is_legal_with_lifted_transits() {
    let mesh = box_mesh(300.0, 200.0, 150.0, 4);
    let mut p = params(20.0);
    p.gun.standoff = 120.0;
    p.gun.radius = 40.0;
    let home = DVec3::new(150.0, 100.0, 600.0);
    p.home = Some(home);
    let plan = plan(&mesh, &p).unwrap();
    assert_eq!(plan.partition.patches.len(), 6);
    assert!(plan.sequenced.lifted > 0, "going round the box needs lifts");
    assert_eq!(plan.sequenced.unchecked, 0);
    check_legal(&mesh, &plan, p.gun.standoff, Some(home));
    // The reported travel is the length of the spray-off moves as written.
    let travel: f64 =
        plan.poses.windows(2).filter(|w| !w[0].spray).map(|w| w[0].position.distance(w[1].position)).sum();
    assert!((travel - plan.totals.travel_mm).abs() < 1e-6 * travel.max(1.0), "{travel} vs {}", plan.totals.travel_mm);
}

#[test]
fn plate_path_is_legal_and_reproducible() {
    let mesh = analytic("plane:a=500,b=300", 1000);
    let p = params(25.0);
    let a = plan(&mesh, &p).unwrap();
    check_legal(&mesh, &a, p.gun.standoff, None);
    let b = plan(&mesh, &p).unwrap();
    assert_eq!(a.poses, b.poses, "same input, same path");
}
