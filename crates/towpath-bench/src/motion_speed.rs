//! Checking and planning speed of `towpath-motion`: 10,000 transits against a
//! 1,000,000-triangle mold (part of `towpath-bench motion`).
//!
//! The mold is a wavy plate 2000 × 1000 mm (z = 30·sin(x/300)·cos(y/200), 708 × 707 quads,
//! 1,000,912 triangles) with a stringer across it (a box 40 mm wide, 60 mm high) and a fixture
//! clamp (a box 80 × 80 × 120 mm). The machine is a gantry (X, Y, Z, heading C) with a head
//! capsule (radius 30, from 35 to 300 mm above the tool point). Each transit joins two random
//! course ends 25 mm above the surface. Timed, on two threads: building the cell (BVH
//! included), checking every straight transit (least clearance, collision, near miss, limits),
//! and planning every transit (straight, or lifted as little as needed). Medians of RUNS runs.

use std::sync::Arc;
use std::time::Instant;

use crate::stats::{cpu_seconds, machine as machine_line, median};

use towpath_geom::DVec3;
use towpath_machine::Machine;
use towpath_motion::{Cell, CheckOptions, Checker, Contact, Head, PlanOptions, Planner, Rig};

const GANTRY: &str = r#"
name = "gantry"
[[axis]]
label = "X"
kind = "linear"
min = -100.0
max = 2100.0
[[axis]]
label = "Y"
kind = "linear"
min = -100.0
max = 1100.0
[[axis]]
label = "Z"
kind = "linear"
min = -100.0
max = 600.0
[[axis]]
label = "C"
kind = "rotary"
heading = true
min = -200.0
max = 200.0
"#;

fn height(x: f64, y: f64) -> f64 {
    30.0 * (x / 300.0).sin() * (y / 200.0).cos()
}

fn cuboid(lo: DVec3, hi: DVec3, out: &mut Vec<[DVec3; 3]>) {
    let c = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    for f in [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]] {
        out.push([c(f[0]), c(f[1]), c(f[2])]);
        out.push([c(f[0]), c(f[2]), c(f[3])]);
    }
}

fn mold() -> Vec<[DVec3; 3]> {
    let (nx, ny) = (708usize, 707usize);
    let p = |i: usize, j: usize| {
        let (x, y) = (2000.0 * i as f64 / nx as f64, 1000.0 * j as f64 / ny as f64);
        DVec3::new(x, y, height(x, y))
    };
    let mut t = Vec::with_capacity(2 * nx * ny + 24);
    for i in 0..nx {
        for j in 0..ny {
            t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    cuboid(DVec3::new(980.0, 0.0, -40.0), DVec3::new(1020.0, 1000.0, 60.0), &mut t);
    cuboid(DVec3::new(400.0, 600.0, -40.0), DVec3::new(480.0, 680.0, 120.0), &mut t);
    t
}

/// A deterministic stream of numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Runs `f` over `items` on two threads.
fn on_two_threads<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let mid = items.len() / 2;
    std::thread::scope(|s| {
        let a = s.spawn(|| items[..mid].iter().map(&f).collect::<Vec<R>>());
        let b: Vec<R> = items[mid..].iter().map(&f).collect();
        let mut a = a.join().unwrap_or_default();
        a.extend(b);
        a
    })
}

/// Runs the speed benchmark: `runs` runs of `count` transits; returns a Markdown section body.
pub fn run(runs: usize, count: usize) -> anyhow::Result<String> {
    let runs = runs.max(1);
    let tris = mold();
    let machine = Machine::from_toml_str(GANTRY)?;
    let rig = Arc::new(Rig::new(&machine, Some(Head { radius: 30.0, bottom: 35.0, top: 300.0 }))?);
    let mut rng = Lcg(7);
    let mut end = || {
        let (x, y) = (50.0 + 1900.0 * rng.next(), 50.0 + 900.0 * rng.next());
        let on_stringer = (940.0..1060.0).contains(&x) || ((360.0..520.0).contains(&x) && (560.0..720.0).contains(&y));
        let x = if on_stringer { x - 150.0 } else { x };
        vec![x, y, height(x, y) + 25.0, 360.0 * rng.next() - 180.0]
    };
    let pairs: Vec<(Vec<f64>, Vec<f64>)> = (0..count).map(|_| (end(), end())).collect();
    eprintln!("motion speed: mold of {} triangles; {} transits; {runs} runs", tris.len(), pairs.len());
    let (mut build, mut check, mut plan) = (Vec::new(), Vec::new(), Vec::new());
    let (mut cb, mut cc, mut cp) = (Vec::new(), Vec::new(), Vec::new());
    let mut summary = String::new();
    for _ in 0..runs {
        // The caller holds the meshes; building the cell from them is timed.
        let input = tris.clone();
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let cell = Arc::new(Cell::from_triangles(input));
        let (t1, c1) = (Instant::now(), cpu_seconds());
        let checker = Checker::new(cell, rig.clone(), CheckOptions::default());
        let checks = on_two_threads(&pairs, |(a, b)| checker.check(a, b, Contact::None));
        let (t2, c2) = (Instant::now(), cpu_seconds());
        let planner = Planner::new(checker.clone(), PlanOptions::default())?;
        let plans = on_two_threads(&pairs, |(a, b)| planner.plan(a, b));
        let (t3, c3) = (Instant::now(), cpu_seconds());
        build.push((t1 - t0).as_secs_f64());
        check.push((t2 - t1).as_secs_f64());
        plan.push((t3 - t2).as_secs_f64());
        cb.push(c1 - c0);
        cc.push(c2 - c1);
        cp.push(c3 - c2);
        let collisions = checks.iter().filter(|c| c.collision).count();
        let near = checks.iter().filter(|c| c.near_miss).count();
        let lifted = plans.iter().filter(|p| matches!(p, Ok(t) if t.level.is_some())).count();
        let failed = plans.iter().filter(|p| p.is_err()).count();
        summary = format!(
            "Outcome: {collisions} straight transits collide (they cross the stringer or the clamp), {near} are near \
             misses; the planner lifts {lifted}, keeps {} straight and finds no safe transit for {failed} (ends whose \
             head already touches the clamp).",
            plans.len() - lifted - failed
        );
    }
    let (b, c, p) = (median(&build), median(&check), median(&plan));
    let (cb, cc, cp) = (median(&cb), median(&cc), median(&cp));
    let mut md = format!(
        "A wavy plate 2000 × 1000 mm of 1,000,912 triangles with a stringer across it and a fixture clamp \
         ({} triangles), a gantry with a head capsule (radius 30, 35–300 mm above the tool point), {} transits \
         between random course ends 25 mm above the surface; two threads; medians of {runs} runs ({}). CPU time \
         is the process's own (both threads): on a shared machine it shows what the work costs.\n\n",
        tris.len(),
        pairs.len(),
        machine_line()
    );
    md.push_str("| step | wall s | CPU s (both threads) |\n|---|---:|---:|\n");
    for (what, w, cpu) in [
        ("build the cell (Morton order, two BVHs built side by side)", b, cb),
        ("check every straight transit (least clearance, collision, near miss, limits)", c, cc),
        ("plan every transit (straight or lifted to the least clearing level)", p, cp),
        ("build + check", b + c, cb + cc),
        ("build + plan", b + p, cb + cp),
    ] {
        md.push_str(&format!("| {what} | {w:.3} | {cpu:.3} |\n"));
    }
    md.push_str(&format!("\n{summary}\n"));
    Ok(md)
}
