//! Speed modulation: the influence matrix agrees with the simulation, and modulating a badly
//! spaced raster makes the thickness (re-simulated at fine sample points, independently of the
//! coarse points the optimiser used) more even without touching the geometry.

mod common;

use glam::DVec3;
use towpath_spray::deposition::influence;
use towpath_spray::modulation::{coarse_points, modulate};
use towpath_spray::thickness::ThicknessStats;
use towpath_spray::{simulate, Gun, Pose, Profile, SamplePoints};

fn gun() -> Gun {
    Gun { standoff: 200.0, radius: 50.0, profile: Profile::Beta { beta: 2.0 }, flow: 500.0 }
}

/// Passes along x over the plate at the given y, each cut into 20 mm segments, at speed `v`,
/// with spray-off moves between them.
fn raster(ys: &[f64], x0: f64, x1: f64, v: f64, standoff: f64) -> Vec<Pose> {
    let mut poses = Vec::new();
    let mut t = 0.0;
    for (k, &y) in ys.iter().enumerate() {
        let n = ((x1 - x0) / 20.0).ceil() as usize;
        for i in 0..=n {
            let s = i as f64 / n as f64;
            let x = if k % 2 == 0 { x0 + s * (x1 - x0) } else { x1 - s * (x1 - x0) };
            if i > 0 {
                t += (x1 - x0) / n as f64 / v;
            }
            poses.push(Pose {
                position: DVec3::new(x, y, standoff),
                axis: -DVec3::Z,
                time: t,
                spray: i < n,
                patch: Some(0),
                pass: Some(k as u32),
            });
        }
        t += 0.5;
    }
    poses
}

#[test]
fn influence_columns_add_up_to_the_simulated_thickness() {
    let g = gun();
    let mesh = common::plate_with_hole(400.0, 300.0, [0.0, 0.0, 0.0, 0.0], 10.0);
    let poses = raster(&[40.0, 80.0, 150.0, 190.0, 260.0], -50.0, 450.0, 400.0, g.standoff);
    let pts = SamplePoints::new(&mesh, 12.5).unwrap();
    let sim = simulate(&g, &poses, &pts).unwrap();
    let inf = influence(&g, &poses, &pts).unwrap();
    let mut sum = vec![0.0; pts.len()];
    for col in &inf.columns {
        for &(i, a) in col {
            sum[i as usize] += a;
        }
    }
    let top = sim.iter().cloned().fold(0.0, f64::max);
    assert!(top > 1.0);
    for (i, (&a, &b)) in sum.iter().zip(&sim).enumerate() {
        assert!((a - b).abs() <= 1e-9 * top, "point {i}: columns {a} vs simulation {b}");
    }
    // one column per spray segment, each starting at a pose that sprays
    let spraying = poses.windows(2).filter(|w| w[0].spray && w[1].time > w[0].time).count();
    assert_eq!(inf.segments.len(), spraying);
    assert!(inf.segments.iter().all(|&j| poses[j as usize].spray));
}

#[test]
fn modulation_evens_out_an_overlap_and_keeps_the_geometry() {
    let g = gun();
    let (a, b) = (600.0, 400.0);
    let mesh = common::plate_with_hole(a, b, [0.0, 0.0, 0.0, 0.0], 10.0);
    // A raster along x over the whole plate and a second one along y over its left third: the
    // overlap gets twice the material (what two patches' rasters do at a seam).
    let d = 38.0;
    let ys: Vec<f64> = (0..).map(|k| 10.0 + k as f64 * d).take_while(|&y| y < b).collect();
    let v = g.speed_for(20.0, d);
    let mut before = raster(&ys, -50.0, a + 50.0, v, g.standoff);
    let t_end = before.last().unwrap().time + 1.0;
    let xs: Vec<f64> = (0..).map(|k| 10.0 + k as f64 * d).take_while(|&x| x < 200.0).collect();
    for mut p in raster(&xs, -50.0, b + 50.0, v, g.standoff) {
        p.position = DVec3::new(p.position.y, p.position.x, p.position.z);
        p.time += t_end;
        p.pass = p.pass.map(|k| k + 1000);
        before.push(p);
    }
    let mut after = before.clone();
    let report = modulate(&mesh, &g, &mut after, 20.0, 3.0).unwrap();

    // Geometry and spray flags unchanged; time stamps strictly increase.
    assert_eq!(before.len(), after.len());
    for (p, q) in before.iter().zip(&after) {
        assert_eq!((p.position, p.axis, p.spray, p.pass), (q.position, q.axis, q.spray, q.pass));
    }
    assert!(after.windows(2).all(|w| w[1].time > w[0].time));
    // Speeds within the allowed factor; transits keep their durations.
    for (w0, w1) in before.windows(2).zip(after.windows(2)) {
        let (d0, d1) = (w0[1].time - w0[0].time, w1[1].time - w1[0].time);
        if w0[0].spray {
            let f = d0 / d1;
            assert!((1.0 / 3.0 - 1e-9..=3.0 + 1e-9).contains(&f), "speed factor {f}");
        } else {
            assert!((d0 - d1).abs() < 1e-9);
        }
    }
    // Re-simulated at fine points over the interior (50 mm from the edges): more even.
    let pts = SamplePoints::new(&mesh, 5.0).unwrap();
    let inside = |i: usize| {
        let p = pts.positions[i];
        p.x > 50.0 && p.x < a - 50.0 && p.y > 50.0 && p.y < b - 50.0
    };
    let rms = |poses: &[Pose]| {
        let t = simulate(&g, poses, &pts).unwrap();
        ThicknessStats::of(&t, &pts.weights, inside, 20.0).rms_rel
    };
    let (r0, r1) = (rms(&before), rms(&after));
    eprintln!("interior RMS before {r0:.4}, after {r1:.4}");
    assert!(r0 > 0.2, "the test rasters should overlap: {r0}");
    assert!(r1 < 0.25 * r0, "RMS {r0} -> {r1}");
    assert!(report.rms_after < report.rms_before);
    assert!(report.min_speed_factor >= 1.0 / 3.0 - 1e-9 && report.max_speed_factor <= 3.0 + 1e-9);
}

#[test]
fn a_factor_of_one_keeps_the_path() {
    let g = gun();
    let mesh = common::plate_with_hole(300.0, 200.0, [0.0, 0.0, 0.0, 0.0], 10.0);
    let before = raster(&[30.0, 90.0, 170.0], -50.0, 350.0, 300.0, g.standoff);
    let mut after = before.clone();
    let r = modulate(&mesh, &g, &mut after, 20.0, 1.0).unwrap();
    assert_eq!(before, after);
    assert_eq!(r.rms_after, r.rms_before);
}

#[test]
fn coarse_points_keep_the_area_and_split_by_normal() {
    let mesh = common::box_mesh(300.0, 200.0, 100.0, 8);
    let pts = coarse_points(&mesh, 10.0).unwrap();
    let area: f64 = pts.weights.iter().sum();
    assert!((area - mesh.area()).abs() < 1e-6 * mesh.area());
    // a point never mixes faces of the box: its normal is one of the six axes
    for n in &pts.normals {
        let m = n.abs().max_element();
        assert!((m - 1.0).abs() < 1e-9, "{n}");
    }
}
