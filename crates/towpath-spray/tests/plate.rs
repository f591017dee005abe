//! A flat plate end to end: one patch, the expected passes, the closed-form raster thickness,
//! uniform thickness at the optimised spacing.

mod common;

use common::*;
use glam::DVec3;
use towpath_spray::spacing::{optimal_spacing, raster_sum};
use towpath_spray::{plan, simulate, Pose, SamplePoints, ThicknessMap};

#[test]
fn plate_is_one_patch_with_the_expected_passes() {
    let mesh = analytic("plane:a=600,b=400", 2000);
    let mut p = params(20.0);
    let d = 40.0;
    p.spacing = Some(d);
    let plan = plan(&mesh, &p).unwrap();
    assert_eq!(plan.partition.patches.len(), 1);
    // Passes along the long side (fewest passes) on the lines y = (k + ½) d, for every k whose
    // line is within the run-out (one spray radius) of the plate: -50 < (k + ½) 40 < 450.
    let e = p.gun.radius;
    let expected: Vec<f64> = (-100..100).map(|k| (k as f64 + 0.5) * d).filter(|&y| y > -e && y < 400.0 + e).collect();
    assert_eq!(plan.passes.len(), expected.len());
    let mut ys: Vec<f64> = plan.passes.iter().map(|ps| ps.positions[0].y).collect();
    ys.sort_by(f64::total_cmp);
    for (y, want) in ys.iter().zip(&expected) {
        assert!((y - want).abs() < 1e-6, "{y} vs {want}");
    }
    for ps in &plan.passes {
        let y0 = ps.positions[0].y;
        for (q, a) in ps.positions.iter().zip(&ps.axes) {
            assert!((q.y - y0).abs() < 1e-6, "a pass is a straight line along x");
            assert!((q.z - p.gun.standoff).abs() < 1e-6, "at the standoff");
            assert!((*a - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-9, "pointing at the plate");
        }
        // Runs out past both short edges: the band of the edges x = 0 and x = 600 reaches
        // √(e² − off²) past the edge on an outer line (off = distance outside), e on a line over
        // the plate.
        let xs: Vec<f64> = ps.positions.iter().map(|q| q.x).collect();
        let (lo, hi) =
            (xs.iter().cloned().fold(f64::INFINITY, f64::min), xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max));
        let off = if y0 < 0.0 {
            -y0
        } else if y0 > 400.0 {
            y0 - 400.0
        } else {
            0.0
        };
        let run = (e * e - off * off).sqrt();
        assert!((lo + run).abs() < 1e-6 && (hi - 600.0 - run).abs() < 1e-6, "{lo} {hi} {run}");
    }
    // Speed gives the target on average: F / (v d) = 20 µm.
    for ps in &plan.passes {
        assert!((1000.0 * p.gun.flow / (ps.speed * d) - 20.0).abs() < 1e-9);
    }
}

#[test]
fn endless_raster_thickness_equals_the_closed_form_sum() {
    // Straight passes 38 mm apart, 2 m long, far more than the footprint either way; thickness
    // on a line across them in the middle against F/v · Σ_k G(y − k d).
    let g = gun();
    let (d, v) = (38.0, 600.0);
    let mut poses = Vec::new();
    let mut t = 0.0;
    for k in -8..=8 {
        let y = k as f64 * d;
        for (i, x) in [-1000.0, 1000.0].iter().enumerate() {
            if i == 1 {
                t += 2000.0 / v;
            }
            poses.push(Pose {
                position: DVec3::new(*x, y, g.standoff),
                axis: -DVec3::Z,
                time: t,
                spray: i == 0,
                patch: None,
                pass: None,
            });
        }
        t += 1.0;
    }
    let n = 60;
    let pts = SamplePoints {
        positions: (0..n).map(|i| DVec3::new(3.7, i as f64 * d / n as f64, 0.0)).collect(),
        normals: vec![DVec3::Z; n],
        weights: vec![1.0; n],
        faces: vec![0; n],
        vertices: 0,
    };
    let got = simulate(&g, &poses, &pts).unwrap();
    for (i, &t) in got.iter().enumerate() {
        let y = pts.positions[i].y;
        let want = 1000.0 * g.flow / v * raster_sum(&g.profile, g.radius, d, y);
        assert!((t - want).abs() < 2e-3 * want, "y = {y}: {t} vs {want}");
    }
}

#[test]
fn plate_at_the_optimal_spacing_is_uniform_inside() {
    let mesh = analytic("plane:a=600,b=400", 2000);
    let p = params(20.0);
    let plan = plan(&mesh, &p).unwrap();
    let opt = optimal_spacing(&p.gun.profile, p.gun.radius);
    let pp = &plan.patches[0];
    // The spacing is fitted to the plate's width near the optimum.
    assert!((pp.spacing - opt.spacing).abs() < opt.spacing / 8.0, "{} vs {}", pp.spacing, opt.spacing);
    let map = ThicknessMap::compute(&mesh, &p.gun, &plan.poses, 20.0, p.gun.radius / 4.0, p.gun.radius).unwrap();
    assert!(map.interior.rms_rel < 0.012, "{:?}", map.interior);
    assert!((map.interior.mean - 20.0).abs() < 0.5, "{:?}", map.interior);
    assert!(map.whole.within_20pct > 0.99, "{:?}", map.whole);
    assert_eq!(map.uncovered_triangles, 0);
}

#[test]
fn a_hole_splits_the_passes_crossing_it() {
    // 600 × 400 plate, hole [200, 400] × [100, 300], one patch (no topology split), passes
    // along x every 20 mm. A line crossing the hole farther than the run-out (50 mm) from the
    // hole's top and bottom edges is split in two, each part running 50 mm into the hole; a
    // line nearer those edges runs across (it sprays the edge from inside the hole).
    let mesh = plate_with_hole(600.0, 400.0, [200.0, 400.0, 100.0, 300.0], 10.0);
    let mut p = params(20.0);
    p.topology = false;
    p.pattern = towpath_spray::PatternChoice::Zigzag;
    let d = 20.0;
    p.spacing = Some(d);
    let plan = plan(&mesh, &p).unwrap();
    assert_eq!(plan.partition.patches.len(), 1);
    let e = p.gun.radius;
    let mut by_line: std::collections::BTreeMap<i64, Vec<(f64, f64)>> = Default::default();
    for ps in &plan.passes {
        let y = ps.positions[0].y;
        let xs = ps.positions.iter().map(|q| q.x);
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        by_line.entry((y * 1000.0).round() as i64).or_default().push((lo, hi));
    }
    let mut split = 0;
    for (ykey, mut ivs) in by_line {
        let y = ykey as f64 / 1000.0;
        ivs.sort_by(|a, b| a.0.total_cmp(&b.0));
        if y > 100.0 + e && y < 300.0 - e {
            split += 1;
            assert_eq!(ivs.len(), 2, "line y = {y}: {ivs:?}");
            assert!((ivs[0].1 - (200.0 + e)).abs() < 1e-6 && (ivs[1].0 - (400.0 - e)).abs() < 1e-6, "{ivs:?}");
        } else {
            assert_eq!(ivs.len(), 1, "line y = {y}: {ivs:?}");
        }
    }
    assert_eq!(split, 4, "lines y = (k + ½) 20 = 170, 190, 210, 230");
}
