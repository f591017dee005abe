//! Motion safety against independent references: brute-force distances (every triangle, fine
//! sampling, a different distance algorithm) on random meshes and moves, analytic answers for
//! lifts over a flange and around a mandrel, limits, and the refused set-ups.

use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use towpath_geom::{DVec3, Soup};
use towpath_machine::{CostKind, Machine, MachineCost, StateTable};
use towpath_motion::{
    check_laid_points, check_mandrel_radius, check_states, Cell, CheckOptions, Checker, Contact, Head, LiftRule,
    PlanError, PlanOptions, Planner, Rig, SetupError, TransitCost,
};
use towpath_seq::{CostModel, StateId};

const GANTRY: &str = r#"
name = "gantry"
[[axis]]
label = "X"
kind = "linear"
max_velocity = 1000.0
min = -100.0
max = 1500.0
[[axis]]
label = "Y"
kind = "linear"
max_velocity = 1000.0
min = -500.0
max = 500.0
[[axis]]
label = "Z"
kind = "linear"
max_velocity = 500.0
min = -50.0
max = 400.0
[[axis]]
label = "C"
kind = "rotary"
heading = true
max_velocity = 180.0
min = -200.0
max = 200.0
"#;

const MANDREL: &str = r#"
name = "mandrel"
[[axis]]
label = "X"
kind = "linear"
max_velocity = 1000.0
[[axis]]
label = "Z"
kind = "linear"
max_velocity = 500.0
min = 0.0
max = 400.0
[[axis]]
label = "A"
kind = "mandrel"
max_velocity = 90.0
"#;

/// A SCARA-like arm whose wrist is tilted (alpha 160°), so that the tool axis turns with the
/// joints; the slide Z moves the tool along the last joint's axis.
const ARM: &str = r#"
name = "arm"
tool_offset = [0.0, 0.0, 50.0]
[[axis]]
label = "A"
kind = "rotary"
[[axis]]
label = "B"
kind = "rotary"
[[axis]]
label = "Z"
kind = "linear"
[[dh]]
a = 300.0
d = 400.0
axis = "A"
[[dh]]
a = 250.0
alpha = 160.0
axis = "B"
[[dh]]
d = 100.0
axis = "Z"
"#;

fn machine(text: &str) -> Machine {
    Machine::from_toml_str(text).unwrap()
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

// ---------------------------------------------------------------------------------------------
// The reference: distances by another method (planar projection and edges; a ternary search
// along segments, the distance to a convex set being convex along a line), every triangle.

fn ref_point_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 { ((p - a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).length()
}

fn ref_point_triangle(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let edges = (0..3).map(|k| ref_point_segment(p, t[k], t[(k + 1) % 3])).fold(f64::INFINITY, f64::min);
    if n.length_squared() == 0.0 {
        return edges;
    }
    let nu = n.normalize();
    let h = (p - t[0]).dot(nu);
    let q = p - nu * h;
    let inside = (0..3).all(|k| (t[(k + 1) % 3] - t[k]).cross(q - t[k]).dot(n) >= 0.0);
    if inside {
        h.abs()
    } else {
        edges
    }
}

fn ref_segment_triangle(a: DVec3, b: DVec3, t: &[DVec3; 3]) -> f64 {
    // Golden-section search of the convex distance along the segment.
    let f = |s: f64| ref_point_triangle(a + (b - a) * s, t);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..45 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    f1.min(f2).min(f(0.0)).min(f(1.0))
}

/// Reference bounds [lower, upper] on the least clearance of a move, from `n` samples: tool
/// chords between samples (within the sampling chord error `dev` of the path) and the head at
/// each sample (within half a step of the head's motion).
fn reference(rig: &Rig, tris: &[[DVec3; 3]], from: &[f64], to: &[f64], n: usize) -> (f64, f64) {
    let deltas = rig.deltas(from, to);
    let dev = rig.bend_bound(from, &deltas) / (8.0 * (n * n) as f64);
    let mut buf = Vec::new();
    let poses: Vec<_> = (0..=n)
        .map(|k| {
            rig.at(from, &deltas, k as f64 / n as f64, &mut buf);
            rig.pose(&buf)
        })
        .collect();
    let (mut lower, mut upper) = (f64::INFINITY, f64::INFINITY);
    for k in 0..n {
        let d = tris
            .iter()
            .map(|t| ref_segment_triangle(poses[k].tool, poses[k + 1].tool, t))
            .fold(f64::INFINITY, f64::min);
        lower = lower.min(d - dev);
        upper = upper.min(d + dev);
    }
    if let Some(h) = rig.head() {
        for k in 0..=n {
            let p = &poses[k];
            let d =
                tris.iter().map(|t| ref_segment_triangle(p.bottom, p.top, t)).fold(f64::INFINITY, f64::min) - h.radius;
            let step = if k < n {
                (poses[k + 1].bottom - p.bottom).length().max((poses[k + 1].top - p.top).length())
            } else {
                0.0
            };
            let back = if k > 0 {
                (poses[k - 1].bottom - p.bottom).length().max((poses[k - 1].top - p.top).length())
            } else {
                0.0
            };
            upper = upper.min(d);
            lower = lower.min(d - 0.5 * step.max(back) - 2.0 * dev);
        }
    }
    (lower.max(0.0), upper.max(0.0))
}

/// Random triangles around the tool points of random states, so that moves meet them.
fn random_cell(rng: &mut Pcg64, rig: &Rig, state: &dyn Fn(&mut Pcg64) -> Vec<f64>, count: usize) -> Vec<[DVec3; 3]> {
    (0..count)
        .map(|_| {
            let s = state(rng);
            let c = rig.pose(&s).tool;
            let c = c + v(rng.gen_range(-40.0..40.0), rng.gen_range(-40.0..40.0), rng.gen_range(-40.0..40.0));
            [0, 1, 2].map(|_| c + v(rng.gen_range(-30.0..30.0), rng.gen_range(-30.0..30.0), rng.gen_range(-30.0..30.0)))
        })
        .collect()
}

fn compare_with_reference(
    text: &str,
    head: Option<Head>,
    state: &dyn Fn(&mut Pcg64) -> Vec<f64>,
    seed: u64,
    moves: usize,
) {
    let rig = Arc::new(Rig::new(&machine(text), head).unwrap());
    let mut rng = Pcg64::seed_from_u64(seed);
    let opts = CheckOptions { horizon: 40.0, ..CheckOptions::default() };
    let tol = opts.tolerance;
    let (mut collisions, mut near, mut clear) = (0, 0, 0);
    for m in 0..moves {
        let tris = random_cell(&mut rng, &rig, state, 25);
        let cell = Arc::new(Cell::from_triangles(tris.clone()));
        let checker = Checker::new(cell, rig.clone(), opts);
        let (from, to) = (state(&mut rng), state(&mut rng));
        let got = checker.check(&from, &to, Contact::None);
        let (lower, upper) = reference(&rig, &tris, &from, &to, 200);
        let l = got.min_clearance.unwrap();
        let (lower, upper) = (lower.min(opts.horizon), upper.min(opts.horizon));
        // Ours is a lower bound of the truth (≤ the reference's upper bound) and within the
        // tolerance of it (≥ the reference's lower bound − tolerance).
        assert!(l <= upper + 1e-6, "move {m}: reported {l} above the reference's {upper} ({from:?} -> {to:?})");
        assert!(l >= lower - tol - 1e-6, "move {m}: reported {l} more than the tolerance below {lower}");
        // No missed collision: a reference that finds contact means ours reports it.
        if upper < tol {
            assert!(got.collision, "move {m}: missed collision (reference {upper})");
        }
        if got.collision {
            assert!(lower < tol, "move {m}: collision reported, reference at least {lower}");
            collisions += 1;
        } else if got.near_miss {
            near += 1;
        } else {
            clear += 1;
        }
        // The quick test agrees with the measurement (up to the tolerance it keeps in hand).
        let quick = checker.is_clear(&from, &to, Contact::None);
        if quick {
            assert!(!got.collision && !got.near_miss, "move {m}: {got:?}");
        } else {
            assert!(l < opts.clearance + 2.0 * tol, "move {m}: {got:?}, reference [{lower}, {upper}]");
        }
    }
    // The random set-up exercises all three outcomes.
    assert!(collisions > 0 && clear > 0, "{collisions} collisions, {near} near misses, {clear} clear");
}

#[test]
fn gantry_moves_match_brute_force() {
    let head = Head { radius: 15.0, bottom: 20.0, top: 80.0 };
    let state = |r: &mut Pcg64| {
        vec![r.gen_range(0.0..300.0), r.gen_range(-150.0..150.0), r.gen_range(0.0..150.0), r.gen_range(-180.0..180.0)]
    };
    compare_with_reference(GANTRY, Some(head), &state, 1, 25);
    compare_with_reference(GANTRY, None, &state, 2, 20);
}

#[test]
fn mandrel_moves_match_brute_force() {
    let head = Head { radius: 10.0, bottom: 12.0, top: 60.0 };
    let state = |r: &mut Pcg64| vec![r.gen_range(0.0..300.0), r.gen_range(90.0..200.0), r.gen_range(-180.0..180.0)];
    compare_with_reference(MANDREL, Some(head), &state, 3, 30);
}

#[test]
fn arm_moves_match_brute_force() {
    let head = Head { radius: 10.0, bottom: 12.0, top: 60.0 };
    let state = |r: &mut Pcg64| vec![r.gen_range(-60.0..60.0), r.gen_range(-60.0..60.0), r.gen_range(0.0..150.0)];
    compare_with_reference(ARM, Some(head), &state, 4, 25);
}

/// The bend bound holds: second differences of sampled paths never exceed it.
#[test]
fn bend_bound_holds_on_sampled_paths() {
    let head = Some(Head { radius: 10.0, bottom: 12.0, top: 60.0 });
    let mut rng = Pcg64::seed_from_u64(5);
    for (text, range) in
        [(MANDREL, [(0.0, 300.0), (90.0, 200.0), (-180.0, 180.0)]), (ARM, [(-90.0, 90.0), (-90.0, 90.0), (0.0, 150.0)])]
    {
        let rig = Rig::new(&machine(text), head).unwrap();
        for _ in 0..50 {
            let mut s = || range.iter().map(|&(a, b)| rng.gen_range(a..b)).collect::<Vec<f64>>();
            let (from, to) = (s(), s());
            let deltas = rig.deltas(&from, &to);
            let m = rig.bend_bound(&from, &deltas);
            let n = 200;
            let h = 1.0 / n as f64;
            let mut buf = Vec::new();
            let mut pose = |t: f64| {
                rig.at(&from, &deltas, t, &mut buf);
                rig.pose(&buf)
            };
            for k in 1..n {
                let (a, b, c) = (pose((k - 1) as f64 * h), pose(k as f64 * h), pose((k + 1) as f64 * h));
                for (x, y, z) in [(a.tool, b.tool, c.tool), (a.top, b.top, c.top)] {
                    let second = (x - 2.0 * y + z).length() / (h * h);
                    assert!(second <= m * 1.0001 + 1e-6, "{text}: second derivative {second} above the bound {m}");
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Planned transits.

/// A box as 12 triangles.
fn cuboid(lo: DVec3, hi: DVec3) -> Vec<[DVec3; 3]> {
    let c = |i: usize| {
        v(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    faces.iter().flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]]).collect()
}

/// A plate z = 0 (x 0..1000, y −200..200) with a flange across it: a box x 480..520, 80 high.
fn plate_with_flange() -> Vec<[DVec3; 3]> {
    let mut t = vec![
        [v(0.0, -200.0, 0.0), v(1000.0, -200.0, 0.0), v(1000.0, 200.0, 0.0)],
        [v(0.0, -200.0, 0.0), v(1000.0, 200.0, 0.0), v(0.0, 200.0, 0.0)],
    ];
    t.extend(cuboid(v(480.0, -200.0, 0.0), v(520.0, 200.0, 80.0)));
    t
}

fn gantry_planner(head: Option<Head>, tris: Vec<[DVec3; 3]>, step: f64) -> Planner {
    let rig = Arc::new(Rig::new(&machine(GANTRY), head).unwrap());
    let checker = Checker::new(Arc::new(Cell::from_triangles(tris)), rig, CheckOptions::default());
    Planner::new(checker, PlanOptions { lift: LiftRule::Auto, step }).unwrap()
}

#[test]
fn a_transit_over_a_flange_is_lifted_just_enough() {
    let head = Head { radius: 15.0, bottom: 20.0, top: 200.0 };
    for (head, step) in [(None, 1.0), (Some(head), 0.5)] {
        let p = gantry_planner(head, plate_with_flange(), step);
        let (a, b) = ([100.0, 0.0, 25.0, 0.0], [900.0, 50.0, 25.0, 180.0]);
        let t = p.plan(&a, &b).unwrap();
        assert_eq!(t.waypoints.len(), 3, "{t:?}");
        // The tool must pass 5 mm over the flange's top at 80: the least level is 85.
        let level = t.level.unwrap();
        assert!(level >= 85.0 - 0.01 && level <= 85.0 + step + 0.01, "level {level}");
        let (up, across) = (&t.waypoints[0], &t.waypoints[1]);
        assert_eq!(up, &vec![100.0, 0.0, level, 0.0]);
        assert_eq!(across, &vec![900.0, 50.0, level, 180.0]);
        assert_eq!(t.waypoints[2], b.to_vec());
        // Every move written is clear, and one step lower would not be.
        let c = p.checker();
        let mut prev = a.to_vec();
        for w in &t.waypoints {
            assert!(c.check(&prev, w, Contact::None).is_clear());
            prev = w.clone();
        }
        let lower = [100.0, 0.0, level - step - 0.02, 0.0];
        let lower_across = [900.0, 50.0, level - step - 0.02, 180.0];
        assert!(!c.check(&lower, &lower_across, Contact::None).is_clear());
        // Backwards: the same moves reversed.
        let back = p.plan(&b, &a).unwrap();
        assert_eq!(back.waypoints, vec![across.clone(), up.clone(), a.to_vec()]);
    }
}

#[test]
fn a_transit_that_needs_no_lift_is_straight() {
    let p = gantry_planner(Some(Head { radius: 15.0, bottom: 20.0, top: 200.0 }), plate_with_flange(), 1.0);
    let (a, b) = ([100.0, -100.0, 25.0, 0.0], [400.0, 150.0, 25.0, -180.0]);
    let t = p.plan(&a, &b).unwrap();
    assert_eq!(t.waypoints, vec![b.to_vec()]);
    assert_eq!(t.level, None);
    // Over the flange's far side with the tool at 90: straight too.
    let t = p.plan(&[100.0, 0.0, 90.0, 0.0], &[900.0, 0.0, 90.0, 0.0]).unwrap();
    assert_eq!(t.waypoints.len(), 1);
}

#[test]
fn limits_are_never_exceeded_including_reversed_headings() {
    let p = gantry_planner(None, plate_with_flange(), 1.0);
    let rig = p.checker().rig();
    let mut rng = Pcg64::seed_from_u64(6);
    let mut lifted = 0;
    for _ in 0..60 {
        let mut s = || {
            let c: f64 = rng.gen_range(-20.0..20.0);
            // A reversed course's heading: turned by 180°, the way that stays within ±200.
            let c = if rng.gen_bool(0.5) {
                if c + 180.0 <= 200.0 {
                    c + 180.0
                } else {
                    c - 180.0
                }
            } else {
                c
            };
            // Off the flange (x 480..520), 10 to 40 mm over the plate.
            let x = if rng.gen_bool(0.5) { rng.gen_range(0.0..470.0) } else { rng.gen_range(530.0..1000.0) };
            vec![x, rng.gen_range(-200.0..200.0), rng.gen_range(10.0..40.0), c]
        };
        let (a, b) = (s(), s());
        let t = p.plan(&a, &b).unwrap();
        lifted += usize::from(t.level.is_some());
        let mut prev = a.clone();
        for w in &t.waypoints {
            rig.check_limits(w, 0.0).unwrap();
            assert!(p.checker().limit_violations(&prev, w).is_empty());
            prev = w.clone();
        }
    }
    assert!(lifted > 5, "{lifted}");
    // A heading turned beyond its limit is refused, naming the axis.
    let e = p.plan(&[100.0, 0.0, 25.0, 10.0], &[900.0, 0.0, 25.0, 190.0 + 20.0]).unwrap_err();
    assert!(matches!(&e, PlanError::Setup(SetupError::OutsideLimits { axis, .. }) if axis == "C"), "{e}");
    assert!(e.to_string().contains("axis C at 210 is outside its travel limits [-200, 200]"), "{e}");
    // A flange taller than Z's travel: no safe transit.
    let mut tall = plate_with_flange();
    tall.extend(cuboid(v(600.0, -200.0, 0.0), v(620.0, 200.0, 398.0)));
    let p = gantry_planner(None, tall, 1.0);
    let e = p.plan(&[100.0, 0.0, 25.0, 0.0], &[900.0, 0.0, 25.0, 0.0]).unwrap_err();
    assert!(matches!(e, PlanError::NoSafeTransit(_)), "{e}");
}

/// A cylinder of radius `r` along x (0..1000) with `n` facets round, and a flange ring at
/// x = 500..510 from radius r to `rf`.
fn mandrel_with_flange(r: f64, rf: f64, n: usize) -> Vec<[DVec3; 3]> {
    let at = |x: f64, rad: f64, k: usize| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        v(x, rad * a.cos(), rad * a.sin())
    };
    let mut t = Vec::new();
    for k in 0..n {
        for (x0, x1, r0, r1) in
            [(0.0, 1000.0, r, r), (500.0, 500.0, r, rf), (510.0, 510.0, r, rf), (500.0, 510.0, rf, rf)]
        {
            let (a, b, c, d) = (at(x0, r0, k), at(x1, r1, k), at(x1, r1, k + 1), at(x0, r0, k + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    t
}

#[test]
fn around_a_mandrel_the_lift_is_radial() {
    let rig = Arc::new(Rig::new(&machine(MANDREL), None).unwrap());
    // 256 facets: the facets' chords lie within 140·(1 − cos(π/256)) ≈ 0.011 mm of the circle.
    let checker = Checker::new(
        Arc::new(Cell::from_triangles(mandrel_with_flange(100.0, 140.0, 256))),
        rig,
        CheckOptions::default(),
    );
    let p = Planner::new(checker, PlanOptions::default()).unwrap();
    // From one course's exit at radius 125 to the next course's entry across the flange, the
    // mandrel turning by 90°: the tool must pass at least 145 from the axis.
    let (a, b) = ([300.0, 125.0, 0.0], [700.0, 125.0, 90.0]);
    let t = p.plan(&a, &b).unwrap();
    let level = t.level.unwrap();
    assert!((145.0 - 0.01..=146.0 + 0.01).contains(&level), "radius {level}");
    assert_eq!(t.waypoints[0], vec![300.0, level, 0.0]);
    assert_eq!(t.waypoints[1], vec![700.0, level, 90.0]);
    // On one side of the flange, turning the mandrel at radius 125 is clear: straight.
    let t = p.plan(&a, &[450.0, 125.0, -170.0]).unwrap();
    assert_eq!(t.waypoints.len(), 1);
    // A tool point on the mandrel axis cannot lift radially (blocked by a disc at x = 600).
    let mut tris = mandrel_with_flange(100.0, 140.0, 64);
    tris.extend((0..64).map(|k| {
        let a = |k: usize| std::f64::consts::TAU * k as f64 / 64.0;
        [
            v(600.0, 0.0, 0.0),
            v(600.0, 100.0 * a(k).cos(), 100.0 * a(k).sin()),
            v(600.0, 100.0 * a(k + 1).cos(), 100.0 * a(k + 1).sin()),
        ]
    }));
    let rig = Arc::new(Rig::new(&machine(MANDREL), None).unwrap());
    let checker = Checker::new(Arc::new(Cell::from_triangles(tris)), rig, CheckOptions::default());
    let p = Planner::new(checker, PlanOptions::default()).unwrap();
    let e = p.plan(&[300.0, 0.0, 0.0], &[700.0, 0.0, 90.0]).unwrap_err();
    assert!(matches!(&e, PlanError::NoLift(m) if m.contains("mandrel axis")), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Contact moves, the cost model, set-ups.

#[test]
fn contact_ends_allow_touching_but_not_crossing() {
    let plate = vec![
        [v(-500.0, -500.0, 0.0), v(500.0, -500.0, 0.0), v(500.0, 500.0, 0.0)],
        [v(-500.0, -500.0, 0.0), v(500.0, 500.0, 0.0), v(-500.0, 500.0, 0.0)],
    ];
    let rig = Arc::new(Rig::new(&machine(GANTRY), Some(Head { radius: 20.0, bottom: 25.0, top: 100.0 })).unwrap());
    let c = Checker::new(Arc::new(Cell::from_triangles(plate)), rig, CheckOptions::default());
    // A plunge from 25 mm onto the plate: fine; its first 15 mm measured (min 10 at the zone).
    let plunge = c.check(&[0.0, 0.0, 25.0, 0.0], &[0.0, 0.0, 0.0, 0.0], Contact::End);
    assert!(plunge.is_clear(), "{plunge:?}");
    assert!((plunge.min_clearance.unwrap() - 10.0).abs() <= 0.011, "{plunge:?}");
    // The same, 0.5 mm into the surface (compaction): within the skipped stretch, fine.
    assert!(c.check(&[0.0, 0.0, 25.0, 0.0], &[0.0, 0.0, -0.5, 0.0], Contact::End).is_clear());
    // Through the plate to 5 mm below: a collision.
    assert!(c.check(&[0.0, 0.0, 25.0, 0.0], &[0.0, 0.0, -5.0, 0.0], Contact::End).collision);
    // The retract, backwards.
    assert!(c.check(&[0.0, 0.0, 0.0, 0.0], &[10.0, 0.0, 25.0, 0.0], Contact::Start).is_clear());
    // A transit 3 mm over the plate: a near miss measured at 3; one at 0.005: a collision.
    let near = c.check(&[-100.0, 0.0, 3.0, 0.0], &[100.0, 0.0, 3.0, 0.0], Contact::None);
    assert!(near.near_miss && !near.collision, "{near:?}");
    assert!((near.min_clearance.unwrap() - 3.0).abs() <= 0.011);
    assert!(c.check(&[-100.0, 0.0, 0.005, 0.0], &[100.0, 0.0, 0.005, 0.0], Contact::None).collision);
    // Limits: Z beyond its max on a move.
    let over = c.check(&[0.0, 0.0, 25.0, 0.0], &[0.0, 0.0, 450.0, 0.0], Contact::None);
    assert_eq!(over.limits.len(), 1);
    assert_eq!(over.limits[0].label, "Z");
    assert_eq!(over.limits[0].value, 450.0);
}

#[test]
fn transit_cost_prices_the_planned_transit() {
    let p = Arc::new(gantry_planner(None, plate_with_flange(), 1.0));
    let mut states = StateTable::new(4);
    let s: Vec<StateId> = [
        [100.0, 0.0, 25.0, 0.0],
        [900.0, 0.0, 25.0, 0.0],
        [300.0, 100.0, 25.0, 90.0],
        [700.0, -100.0, 25.0, 0.0],
        [100.0, 0.0, 25.0, 0.0],
    ]
    .iter()
    .map(|x| states.push(x).unwrap())
    .collect();
    let base = MachineCost::new(machine(GANTRY), CostKind::Axis, states).unwrap();
    let cost = TransitCost::new(p.clone(), base.clone());
    // 0 → 1 crosses the flange: up 60, across 800, down 60 (axis weights 1).
    let c01 = cost.cost(s[0], s[1]);
    let level = p.plan(&[100.0, 0.0, 25.0, 0.0], &[900.0, 0.0, 25.0, 0.0]).unwrap().level.unwrap();
    assert!((c01 - (800.0 + 2.0 * (level - 25.0))).abs() < 1e-9, "{c01} {level}");
    // 0 → 2 does not: the direct cost.
    assert_eq!(cost.cost(s[0], s[2]), base.cost(s[0], s[2]));
    assert_eq!(cost.cost(s[0], s[4]), 0.0);
    // Symmetric, and the same from two threads in any order.
    let all: Vec<(StateId, StateId)> = s.iter().flat_map(|&a| s.iter().map(move |&b| (a, b))).collect();
    let fresh = TransitCost::new(p, base);
    let (x, y) = std::thread::scope(|sc| {
        let h1 = sc.spawn(|| all.iter().map(|&(a, b)| fresh.cost(a, b)).collect::<Vec<_>>());
        let h2 = sc.spawn(|| all.iter().rev().map(|&(a, b)| fresh.cost(a, b)).collect::<Vec<_>>());
        (h1.join().unwrap(), h2.join().unwrap())
    });
    let mut y = y;
    y.reverse();
    assert_eq!(x, y);
    for (i, &(a, b)) in all.iter().enumerate() {
        assert_eq!(x[i], cost.cost(a, b));
        assert_eq!(cost.cost(a, b), cost.cost(b, a));
    }
    assert!(cost.is_symmetric());
}

#[test]
fn degenerate_setups_are_refused() {
    let cell = Cell::from_triangles(plate_with_flange());
    // Laid points on the plate pass; one 300 mm above it (wrong units or frame) is refused.
    check_laid_points(&cell, &[[10.0, 0.0, 0.0], [500.0, 0.0, 80.5]], 5.0).unwrap();
    let e = check_laid_points(&cell, &[[10.0, 0.0, 0.0], [10.0, 0.0, 300.0]], 5.0).unwrap_err();
    assert!(matches!(e, SetupError::OffMold { index: 1, .. }), "{e}");
    assert!(e.to_string().contains("300.000 mm from the nearest mold triangle"), "{e}");
    assert_eq!(check_laid_points(&Cell::empty(), &[[0.0; 3]], 5.0).unwrap_err(), SetupError::EmptyMold);
    // Laid points on the mandrel's axis.
    let rig = Rig::new(&machine(MANDREL), None).unwrap();
    check_mandrel_radius(&rig, &[[0.0, 100.0, 0.0]], 1.0).unwrap();
    let e = check_mandrel_radius(&rig, &[[0.0, 100.0, 0.0], [50.0, 0.0, 0.0001]], 1.0).unwrap_err();
    assert!(matches!(e, SetupError::OnMandrelAxis { index: 1, .. }), "{e}");
    assert!(e.to_string().contains("mandrel axis"), "{e}");
    // A state outside the travel limits.
    let rig = Rig::new(&machine(GANTRY), None).unwrap();
    let (ok, bad) = ([0.0, 0.0, 0.0, 0.0], [0.0, 600.0, 0.0, 0.0]);
    check_states(&rig, [&ok[..]]).unwrap();
    let e = check_states(&rig, [&ok[..], &bad[..]]).unwrap_err();
    assert!(matches!(&e, SetupError::OutsideLimits { axis, value, .. } if axis == "Y" && *value == 600.0), "{e}");
    assert!(matches!(
        check_states(&rig, [&[0.0, 0.0][..]]).unwrap_err(),
        SetupError::WrongDimension { got: 2, expected: 4 }
    ));
    // A head reaching below the tool point; a machine without kinematics.
    let e = Rig::new(&machine(GANTRY), Some(Head { radius: 30.0, bottom: 10.0, top: 50.0 })).unwrap_err();
    assert!(e.to_string().starts_with("head.bottom"), "{e}");
    let none = Machine::from_toml_str("name = \"r\"\n[[axis]]\nlabel = \"A\"\nkind = \"rotary\"\n").unwrap();
    assert_eq!(Rig::new(&none, None).unwrap_err(), SetupError::NoKinematics);
    // Meshes with bad coordinates.
    let soup =
        Soup { positions: vec![v(0.0, 0.0, 0.0), v(f64::NAN, 0.0, 0.0), v(0.0, 1.0, 0.0)], triangles: vec![[0, 1, 2]] };
    let e = Cell::from_soups(&[Soup::default(), soup]).unwrap_err();
    assert!(e.to_string().starts_with("obstacle mesh 2: "), "{e}");
    // A DH chain cannot lift by itself, nor along a rotary axis.
    let arm = Arc::new(Rig::new(&machine(ARM), None).unwrap());
    let checker = Checker::new(Arc::new(Cell::empty()), arm, CheckOptions::default());
    assert!(matches!(
        Planner::new(checker.clone(), PlanOptions { lift: LiftRule::Axis(0), step: 1.0 }),
        Err(PlanError::NoLift(_))
    ));
    assert!(matches!(
        Planner::new(checker.clone(), PlanOptions { lift: LiftRule::Radial, step: 1.0 }),
        Err(PlanError::NoLift(_))
    ));
    // ... but along its slide (which moves the tool along the tool axis).
    Planner::new(checker, PlanOptions { lift: LiftRule::Axis(2), step: 1.0 }).unwrap();
}

/// A cell large enough to be built as two hierarchies answers like brute force.
#[test]
fn large_cells_in_two_halves_answer_exactly() {
    let mut rng = Pcg64::seed_from_u64(9);
    let tris: Vec<[DVec3; 3]> = (0..120_000)
        .map(|_| {
            let c = v(rng.gen_range(0.0..1000.0), rng.gen_range(0.0..1000.0), rng.gen_range(0.0..20.0));
            [0, 1, 2].map(|_| c + v(rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0)))
        })
        .collect();
    let cell = Cell::from_triangles(tris.clone());
    for _ in 0..3 {
        let p = v(rng.gen_range(0.0..1000.0), rng.gen_range(0.0..1000.0), rng.gen_range(20.0..40.0));
        let q = v(rng.gen_range(0.0..1000.0), rng.gen_range(0.0..1000.0), rng.gen_range(20.0..40.0));
        let brute = tris.iter().map(|t| ref_segment_triangle(p, q, t)).fold(f64::INFINITY, f64::min);
        let exact = cell.segment_distance(p, q, 100.0, -1.0);
        let best_first = cell.segment_min(p, q, 100.0, 0.001);
        assert!((exact - brute).abs() < 1e-6, "{exact} {brute}");
        assert!(best_first >= brute - 1e-6 && best_first <= brute + 0.001 + 1e-6, "{best_first} {brute}");
    }
}
