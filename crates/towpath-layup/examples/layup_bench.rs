//! Benchmark driver for `bench/layup.py` (run by hand, not in CI):
//!
//! `cargo run --release -p towpath-layup --example layup_bench -- OUT_DIR [REPEATS]`
//!
//! 1. Accuracy study in the form of seed 001 Tables 2–3 on analytic surfaces (cylinder, sphere,
//!    cone) for a grid of D_l2s × L_seg: tessellation + trace time, distance deviation split into
//!    normal and geodesic parts, angle deviation. Printed as JSON (`accuracy.json`).
//! 2. 200k-triangle cylinder and sphere meshes (OBJ) with deterministic start points and
//!    directions (`starts_*.json`), 1 m geodesics traced by towpath (`towpath_*.json`: polylines
//!    and the median time per trace), for `bench/layup.py` to compare with potpourri3d.
//! 3. A ±45° field ply on the 200k cylinder: angle deviation against the exact design direction.
//! 4. A 2 m² doubly curved NURBS mold tessellated to about 200k triangles (`dome.stl`) for the
//!    full-ply timing through the CLI.

use std::time::Instant;

use glam::DVec3;
use serde_json::json;
use towpath_geom::surface::{tessellate, tessellate_analytic, Analytic, Nurbs, Surface, Tessellation};
use towpath_geom::{io, BuildOptions, Mesh};
use towpath_layup::accuracy::{deviation, Reference};
use towpath_layup::boundary::Region;
use towpath_layup::field::{DirectionField, Rosette};
use towpath_layup::ply::{plan, PlySpec};
use towpath_layup::trace::{trace_both, walk, Located, Steering, WalkOptions};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

/// Small deterministic generator (xorshift) so starts are the same in every run.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(args.get(1).cloned().unwrap_or_else(|| "bench/out".into()));
    let repeats: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    std::fs::create_dir_all(&out).expect("output directory");

    // 1. Accuracy study.
    let cases = [
        ("cylinder", "cylinder:r=300,l=1000", DVec3::new(300.0, 0.0, 500.0), DVec3::new(0.0, 1.0, 1.0), true),
        ("sphere", "sphere:r=500", DVec3::new(400.0, 30.0, 200.0), DVec3::new(0.0, 1.0, 0.3), false),
        ("cone", "cone:r0=300,r1=150,l=600", DVec3::new(240.0, 60.0, 200.0), DVec3::new(0.0, 1.0, 0.5), false),
    ];
    let mut rows = Vec::new();
    for (name, desc, p0, d0, field_course) in cases {
        let s = Analytic::parse(desc).expect("surface");
        for (mode, smooth) in [("smooth normals, midpoint", true), ("face normals, entry point (seed 001)", false)] {
            for d_l2s in [0.05, 0.2, 0.5, 1.0] {
                for l_seg in [10.0, 20.0, 65.0, 110.0] {
                    let t0 = Instant::now();
                    let soup = tessellate_analytic(&s, &Tessellation::Chord { d_l2s, l_seg }).expect("tessellation");
                    let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).expect("mesh");
                    let start = Located::new(&mesh, mesh.closest_point(p0).expect("start"));
                    let rosette = Rosette { axis: DVec3::Z, angle: 45f64.to_radians() };
                    let steer = if field_course { Steering::Field(&rosette) } else { Steering::Geodesic };
                    let opts = WalkOptions {
                        max_length: 500.0,
                        midpoint: smooth,
                        smooth_normals: smooth,
                        ..WalkOptions::default()
                    };
                    let path = trace_both(&mesh, start, d0, steer, &opts, |_| false).expect("trace");
                    let secs = t0.elapsed().as_secs_f64();
                    let reference = Reference::new(s, start.p, path.points[path.start_index].d).expect("reference");
                    let dev = deviation(&reference, &path.points, path.points[path.start_index].s);
                    rows.push(json!({"surface": name, "mode": mode, "d_l2s": d_l2s, "l_seg": l_seg, "triangles": mesh.num_faces(),
                    "length": path.length(), "seconds": secs, "deviation": dev}));
                }
            }
        }
    }
    std::fs::write(out.join("accuracy.json"), serde_json::to_string_pretty(&rows).expect("json")).expect("write");

    // 2. 200k meshes, starts and towpath traces.
    for (name, desc) in [("cylinder", "cylinder:r=300,l=1000"), ("sphere", "sphere:r=500")] {
        let s = Analytic::parse(desc).expect("surface");
        let soup = tessellate_analytic(&s, &Tessellation::Triangles(200_000)).expect("tessellation");
        let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).expect("mesh");
        io::write_path(&out.join(format!("{name}.obj")), &mesh.to_soup()).expect("write mesh");
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut starts = Vec::new();
        for _ in 0..20 {
            let (p, d) = if name == "cylinder" {
                // Directions within ±40° of the hoop, starting so that 1 m stays on the tube.
                let phi = rng.next() * std::f64::consts::TAU;
                let a = (rng.next() * 80.0 - 40.0).to_radians();
                let axial = 1000.0 * a.sin();
                let z = 500.0 - 0.5 * axial;
                let p = DVec3::new(300.0 * phi.cos(), 300.0 * phi.sin(), z);
                let e_phi = DVec3::new(-phi.sin(), phi.cos(), 0.0);
                (p, e_phi * a.cos() + DVec3::Z * a.sin())
            } else {
                let u = rng.next() * 2.0 - 1.0;
                let th = rng.next() * std::f64::consts::TAU;
                let r = (1.0 - u * u).sqrt();
                let n = DVec3::new(r * th.cos(), r * th.sin(), u);
                let t = n.any_orthonormal_vector();
                let b = n.cross(t);
                let g = rng.next() * std::f64::consts::TAU;
                (n * 500.0, t * g.cos() + b * g.sin())
            };
            let sp = mesh.closest_point(p).expect("start");
            let loc = Located::new(&mesh, sp);
            let d = (d - loc.n * d.dot(loc.n)).normalize();
            starts.push((sp, loc, d));
        }
        let starts_json: Vec<_> = starts
            .iter()
            .map(|(sp, loc, d)| json!({"face": sp.face, "bary": sp.bary.to_array(), "point": loc.p.to_array(), "direction": d.to_array()}))
            .collect();
        std::fs::write(out.join(format!("starts_{name}.json")), serde_json::to_string(&starts_json).expect("json"))
            .expect("write");
        let opts = WalkOptions::up_to(1000.0);
        let mut polylines = Vec::new();
        let mut times = Vec::new();
        for (_, loc, d) in &starts {
            let mut pts = Vec::new();
            let mut per = Vec::new();
            for _ in 0..repeats {
                let t0 = Instant::now();
                let (w, _) = walk(&mesh, *loc, *d, Steering::Geodesic, &opts, |_| false);
                per.push(t0.elapsed().as_secs_f64());
                pts = w;
            }
            times.push(median(per));
            let mut line = vec![loc.p.to_array()];
            line.extend(pts.iter().map(|q| q.p.to_array()));
            polylines.push(line);
        }
        std::fs::write(
            out.join(format!("towpath_{name}.json")),
            serde_json::to_string(
                &json!({"triangles": mesh.num_faces(), "seconds_per_trace": times, "polylines": polylines}),
            )
            .expect("json"),
        )
        .expect("write");
        eprintln!("{name}: {} triangles, median {:.3} ms per 1 m trace", mesh.num_faces(), 1e3 * median(times.clone()));
    }

    // 3. ±45° field plies on the 200k cylinder against the exact design direction.
    let cyl = Analytic::parse("cylinder:r=300,l=1000").expect("surface");
    let soup = tessellate_analytic(&cyl, &Tessellation::Triangles(200_000)).expect("tessellation");
    let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).expect("mesh");
    let region = Region::whole(&mesh);
    let mut ply_rows = Vec::new();
    for angle in [45.0f64, -45.0] {
        let field = Rosette { axis: DVec3::Z, angle: angle.to_radians() };
        let spec = PlySpec::new(6.35, 16);
        let t0 = Instant::now();
        let ply = plan(&mesh, &field, &region, &spec, &mut |_| {}).expect("ply");
        let secs = t0.elapsed().as_secs_f64();
        let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
        for c in &ply.courses {
            for (i, w) in c.points.windows(2).enumerate() {
                if !(c.on_surface[i] && c.on_surface[i + 1]) {
                    continue;
                }
                let seg = w[1].p - w[0].p;
                if seg.length() < 1e-6 {
                    continue;
                }
                let mid = (w[0].p + w[1].p) * 0.5;
                let exact = cyl.closest(mid);
                let design = field.direction(exact.point, exact.normal).expect("direction");
                let seg_t = (seg - exact.normal * seg.dot(exact.normal)).normalize();
                let a = seg_t.dot(design).abs().clamp(0.0, 1.0).acos().to_degrees();
                sum += a;
                n += 1;
                max = max.max(a);
            }
        }
        ply_rows.push(
            json!({"angle": angle, "courses": ply.courses.len(), "mean_angle_deviation_deg": sum / n.max(1) as f64,
            "max_angle_deviation_deg": max, "coverage_percent": ply.quality.coverage_percent, "seconds": secs}),
        );
    }
    std::fs::write(out.join("ply_angle.json"), serde_json::to_string_pretty(&ply_rows).expect("json")).expect("write");

    // 4. Doubly curved mold: a bicubic patch 1.42 m × 1.42 m with a 150 mm crown and a twist.
    let n = 6;
    let size = 1420.0;
    let grid: Vec<Vec<DVec3>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let (x, y) = (size * i as f64 / (n - 1) as f64, size * j as f64 / (n - 1) as f64);
                    let (u, v) = (x / size - 0.5, y / size - 0.5);
                    DVec3::new(x, y, 150.0 * (1.0 - 4.0 * u * u) * (1.0 - 4.0 * v * v) + 60.0 * u * v * 4.0)
                })
                .collect()
        })
        .collect();
    let patch = Nurbs::clamped(3, 3, &grid).expect("patch");
    std::fs::write(out.join("dome.json"), serde_json::to_string(&patch).expect("json")).expect("write");
    let soup = tessellate(&patch, &Tessellation::Triangles(200_000)).expect("tessellation");
    let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).expect("mesh");
    io::write_path(&out.join("dome.stl"), &mesh.to_soup()).expect("write");
    eprintln!("dome: {} triangles, {:.3} m2", mesh.num_faces(), mesh.area() / 1e6);
}
