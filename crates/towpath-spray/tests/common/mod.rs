//! Meshes and parameters shared by the integration tests.
#![allow(dead_code)]

use std::time::Duration;

use glam::DVec3;
use towpath_geom::surface::{tessellate_analytic, Analytic, Tessellation};
use towpath_geom::{BuildOptions, Mesh, Soup};
use towpath_spray::{Gun, Profile, SeqOptions, SprayParams};

/// A mesh of an analytic surface with about `tris` triangles.
pub fn analytic(desc: &str, tris: usize) -> Mesh {
    let s = tessellate_analytic(&Analytic::parse(desc).unwrap(), &Tessellation::Triangles(tris)).unwrap();
    Mesh::build(&s, &BuildOptions::default()).unwrap().0
}

/// A closed box `[0,a]×[0,b]×[0,c]`, each face an n × n grid of quads.
pub fn box_mesh(a: f64, b: f64, c: f64, n: usize) -> Mesh {
    let mut soup = Soup { positions: Vec::new(), triangles: Vec::new() };
    // Each face: origin, two edge vectors (right-handed so the normal points out).
    let faces = [
        (DVec3::ZERO, DVec3::new(0.0, b, 0.0), DVec3::new(a, 0.0, 0.0)), // z = 0, normal -z
        (DVec3::new(0.0, 0.0, c), DVec3::new(a, 0.0, 0.0), DVec3::new(0.0, b, 0.0)), // z = c, +z
        (DVec3::ZERO, DVec3::new(a, 0.0, 0.0), DVec3::new(0.0, 0.0, c)), // y = 0, -y
        (DVec3::new(0.0, b, 0.0), DVec3::new(0.0, 0.0, c), DVec3::new(a, 0.0, 0.0)), // y = b, +y
        (DVec3::ZERO, DVec3::new(0.0, 0.0, c), DVec3::new(0.0, b, 0.0)), // x = 0, -x
        (DVec3::new(a, 0.0, 0.0), DVec3::new(0.0, b, 0.0), DVec3::new(0.0, 0.0, c)), // x = a, +x
    ];
    for (o, u, v) in faces {
        let base = soup.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                soup.positions.push(o + u * (i as f64 / n as f64) + v * (j as f64 / n as f64));
            }
        }
        let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                soup.triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                soup.triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    Mesh::build(&soup, &BuildOptions::default()).unwrap().0
}

/// A flat plate `[0,a]×[0,b]` at z = 0 with a rectangular hole `[x0,x1]×[y0,y1]`, on a grid of
/// square cells of side `cell` (cells inside the hole left out).
pub fn plate_with_hole(a: f64, b: f64, hole: [f64; 4], cell: f64) -> Mesh {
    let (nx, ny) = ((a / cell).round() as usize, (b / cell).round() as usize);
    let mut soup = Soup { positions: Vec::new(), triangles: Vec::new() };
    for j in 0..=ny {
        for i in 0..=nx {
            soup.positions.push(DVec3::new(i as f64 * cell, j as f64 * cell, 0.0));
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    for j in 0..ny {
        for i in 0..nx {
            let (cx, cy) = ((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell);
            if cx > hole[0] && cx < hole[1] && cy > hole[2] && cy < hole[3] {
                continue;
            }
            soup.triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            soup.triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::build(&soup, &BuildOptions::default()).unwrap().0
}

/// The gun of most tests: standoff 200, radius 50, β = 2, 500 mm³/s.
pub fn gun() -> Gun {
    Gun { standoff: 200.0, radius: 50.0, profile: Profile::Beta { beta: 2.0 }, flow: 500.0 }
}

/// Parameters with a deterministic sequencing budget.
pub fn params(target: f64) -> SprayParams {
    let mut p = SprayParams::new(gun(), target);
    p.seq = SeqOptions { time_limit: None, iterations: Some(200), threads: 1, seed: 1, ..SeqOptions::default() };
    p.seq.time_limit = Some(Duration::from_secs(30));
    p
}
