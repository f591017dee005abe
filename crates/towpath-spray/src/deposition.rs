//! The spray-cone deposition model and the thickness any path leaves on a mesh.
//!
//! A gun at position g with unit axis a (pointing from the gun towards the part) sprays a cone
//! whose footprint on a plane square to the axis at the standoff h is a disk of radius R with
//! the flux profile q(r) of [`Profile`] (normalised to one over the disk). With volume flow F
//! (mm³/s of material that stays on the part), a surface point p with unit normal n receives
//! material at the rate (mm/s)
//!
//! ```text
//! ṫ(p) = F · q(r_eq) · (h/z)² · cos θ / cos θ₀,      v = p − g,  z = v·a,  ρ = |v − z a|,
//! r_eq = ρ · h / z,   cos θ = −v·n / |v|,   cos θ₀ = z / |v|
//! ```
//!
//! that is: the footprint scales with the distance along the axis (a point at axial distance z
//! and radial distance ρ sees the part of the profile at r = ρh/z), the flux falls as the
//! inverse square of the distance, and the material landing on a tilted surface element spreads
//! over 1/cos θ more area than on the reference plane (θ the angle between the spray ray and the
//! normal; θ₀ that of the same ray on the reference plane, so that on that plane the correction
//! is exactly one). This is the point-source spray cone of Antonio et al. (1997) and Conner et
//! al. (2005); Tewolde & Sheng (2008) §II model the tool by such a cone. The model treats a
//! point as reached when 0 < z ≤ 2h, r_eq < R and cos θ > 0 (it faces the gun); shadowing by
//! other parts of the surface is not modelled.
//!
//! The thickness left by a path is the time integral of ṫ along it: spray segments (from a pose
//! with `spray` set to the next pose, position and axis interpolated linearly) are cut into
//! steps of at most R/12 (and of at most R/12 of arc at the standoff when the axis turns), each
//! step sprayed at its midpoint for its share of the segment's time.

use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use towpath_geom::Mesh;

use crate::error::{positive, SprayError};
use crate::profile::Profile;

/// Default volume flow: 500 mm³/s (30 cm³/min) of material that stays on the part.
pub const DEFAULT_FLOW: f64 = 500.0;

/// The spray reaches points up to this many standoffs along its axis.
pub const REACH: f64 = 2.0;

/// Integration steps per footprint radius along a spray segment.
pub const STEPS_PER_RADIUS: f64 = 12.0;

/// The spray gun and the material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gun {
    /// Standoff h (mm): distance from the gun to the surface along the axis.
    pub standoff: f64,
    /// Footprint radius R (mm) at the standoff on a plane square to the axis.
    pub radius: f64,
    /// Flux profile across the footprint.
    pub profile: Profile,
    /// Volume flow F (mm³/s) of material that stays on the part.
    pub flow: f64,
}

impl Gun {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SprayError> {
        positive("the standoff", self.standoff)?;
        positive("the spray radius", self.radius)?;
        positive("the material flow", self.flow)?;
        self.profile.validate(self.radius)
    }

    /// Thickness rate (µm/s) at surface point `p` with unit normal `n` from a gun at `g` with
    /// unit axis `a` (see the module docs).
    pub fn rate(&self, g: DVec3, a: DVec3, p: DVec3, n: DVec3) -> f64 {
        let k = self.profile.kernel(self.radius);
        let h = self.standoff;
        let v = p - g;
        let z = v.dot(a);
        if !(z > 0.0 && z <= REACH * h) {
            return 0.0;
        }
        let rho2 = (v.length_squared() - z * z).max(0.0);
        let r2 = rho2 * (h / z) * (h / z);
        let q = k.density(r2);
        let vn = -v.dot(n);
        if q == 0.0 || !(vn > 0.0) {
            return 0.0;
        }
        1000.0 * self.flow * q * (h / z) * (h / z) * vn / z
    }

    /// Thickness (µm) of an endless raster of straight passes `spacing` apart at `speed` on a
    /// plane square to the gun at the standoff, averaged over the plane: all the material lands,
    /// so it is F / (v·d).
    pub fn raster_mean(&self, spacing: f64, speed: f64) -> f64 {
        1000.0 * self.flow / (speed * spacing)
    }

    /// The speed at which a raster at `spacing` leaves `thickness` µm on average.
    pub fn speed_for(&self, thickness_um: f64, spacing: f64) -> f64 {
        1000.0 * self.flow / (thickness_um * spacing)
    }
}

/// One pose of a spray path: where the gun is, where it points, when, and whether it sprays
/// from this pose to the next.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Gun position (mm).
    pub position: DVec3,
    /// Unit axis from the gun towards the surface.
    pub axis: DVec3,
    /// Seconds from the start of the path.
    pub time: f64,
    /// True when the spray is on from this pose to the next.
    pub spray: bool,
    /// The patch being sprayed (none on transits).
    pub patch: Option<u32>,
    /// The pass being sprayed (none on transits).
    pub pass: Option<u32>,
}

/// Points where thickness is evaluated: the mesh vertices (first), then points inside every
/// triangle (the centroids of a regular n × n subdivision, n chosen so that no sub-triangle
/// edge is longer than the sampling spacing), each carrying its share of the area.
#[derive(Debug, Clone, Default)]
pub struct SamplePoints {
    /// Positions.
    pub positions: Vec<DVec3>,
    /// Unit normals (vertex normals for vertices, face normals inside triangles).
    pub normals: Vec<DVec3>,
    /// Area each point stands for (0 for vertices: they are shown, not counted).
    pub weights: Vec<f64>,
    /// The face a point lies in (`u32::MAX` for vertices).
    pub faces: Vec<u32>,
    /// How many of the points (the first ones) are mesh vertices.
    pub vertices: usize,
}

/// Most points [`SamplePoints::new`] places inside triangles.
pub const MAX_SAMPLES: usize = 8_000_000;

impl SamplePoints {
    /// The mesh's vertices and points inside its triangles at most `spacing` apart.
    pub fn new(mesh: &Mesh, spacing: f64) -> Result<SamplePoints, SprayError> {
        let nf = mesh.num_faces();
        let subdiv: Vec<u32> = (0..nf as u32)
            .map(|f| {
                let c = mesh.corners(f);
                let l = c[0].distance(c[1]).max(c[1].distance(c[2])).max(c[2].distance(c[0]));
                ((l / spacing).ceil().clamp(1.0, 4096.0)) as u32
            })
            .collect();
        let total: usize = subdiv.iter().map(|&n| (n as usize) * (n as usize)).sum();
        if total > MAX_SAMPLES {
            return Err(SprayError::TooLarge {
                what: format!("{total} thickness sample points (at most {MAX_SAMPLES})"),
            });
        }
        let nv = mesh.positions().len();
        let mut s = SamplePoints {
            positions: Vec::with_capacity(nv + total),
            normals: Vec::with_capacity(nv + total),
            weights: Vec::with_capacity(nv + total),
            faces: Vec::with_capacity(nv + total),
            vertices: nv,
        };
        for v in 0..nv as u32 {
            s.positions.push(mesh.positions()[v as usize]);
            s.normals.push(mesh.vertex_normal(v));
            s.weights.push(0.0);
            s.faces.push(u32::MAX);
        }
        for f in 0..nf as u32 {
            let [a, b, c] = mesh.corners(f);
            let n = subdiv[f as usize];
            let w = mesh.face_area(f) / (n as f64 * n as f64);
            let nrm = mesh.face_normal(f);
            let nf64 = n as f64;
            let mut push = |u: f64, v: f64| {
                s.positions.push(a + (b - a) * u + (c - a) * v);
                s.normals.push(nrm);
                s.weights.push(w);
                s.faces.push(f);
            };
            for i in 0..n {
                for j in 0..n - i {
                    push((3 * i + 1) as f64 / (3.0 * nf64), (3 * j + 1) as f64 / (3.0 * nf64));
                    if i + j + 2 <= n {
                        push((3 * i + 2) as f64 / (3.0 * nf64), (3 * j + 2) as f64 / (3.0 * nf64));
                    }
                }
            }
        }
        Ok(s)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
}

/// One integration step of a spray segment.
#[derive(Debug, Clone, Copy)]
struct Step {
    g: DVec3,
    a: DVec3,
    /// 1000 · F · h² · Δt: the constant factor of the step's contribution.
    c: f64,
    /// Index of the pose that starts the step's segment.
    segment: u32,
}

/// The per-step deposition formula of the module docs, with the gun's constants.
struct Cone {
    kernel: crate::profile::Kernel,
    r2max: f64,
    h2: f64,
    reach: f64,
    /// Radius of the footprint at `reach`.
    base: f64,
}

impl Cone {
    fn new(gun: &Gun) -> Cone {
        let kernel = gun.profile.kernel(gun.radius);
        let reach = REACH * gun.standoff;
        Cone { r2max: kernel.radius2(), kernel, h2: gun.standoff * gun.standoff, reach, base: gun.radius * REACH }
    }

    /// A box holding everything a step's cone reaches: from the gun to the disk of radius
    /// `base` at `reach` along the axis.
    fn bounds(&self, st: &Step) -> (DVec3, DVec3) {
        let c = st.g + st.a * self.reach;
        let ext = DVec3::new(
            self.base * (1.0 - st.a.x * st.a.x).max(0.0).sqrt(),
            self.base * (1.0 - st.a.y * st.a.y).max(0.0).sqrt(),
            self.base * (1.0 - st.a.z * st.a.z).max(0.0).sqrt(),
        );
        (st.g.min(c - ext), st.g.max(c + ext))
    }

    /// Thickness (µm) one step leaves at point `p` with unit normal `n`.
    #[inline]
    fn amount(&self, st: &Step, p: DVec3, n: DVec3) -> f64 {
        let v = p - st.g;
        let z = v.dot(st.a);
        if !(z > 0.0 && z <= self.reach) {
            return 0.0;
        }
        let inv_z = 1.0 / z;
        let rho2 = v.length_squared() - z * z;
        let r2 = rho2 * self.h2 * inv_z * inv_z;
        if !(r2 < self.r2max) {
            return 0.0;
        }
        let vn = -v.dot(n);
        if !(vn > 0.0) {
            return 0.0;
        }
        st.c * self.kernel.density(r2.max(0.0)) * vn * inv_z * inv_z * inv_z
    }
}

/// Checks a path: finite positions, unit axes, time stamps that never decrease.
pub fn validate_path(poses: &[Pose]) -> Result<(), SprayError> {
    for (i, p) in poses.iter().enumerate() {
        let bad = |m: &str| SprayError::BadPath { index: i, message: m.to_string() };
        if !(p.position.is_finite() && p.axis.is_finite() && p.time.is_finite()) {
            return Err(bad("a coordinate, axis component or time is not a finite number"));
        }
        if (p.axis.length() - 1.0).abs() > 1e-6 {
            return Err(bad("the axis is not a unit vector"));
        }
        if i > 0 && p.time < poses[i - 1].time {
            return Err(bad("the time stamp is earlier than the previous pose's"));
        }
    }
    Ok(())
}

/// Cuts the spray segments of a path into integration steps.
fn steps(gun: &Gun, poses: &[Pose]) -> Vec<Step> {
    let delta = gun.radius / STEPS_PER_RADIUS;
    let h = gun.standoff;
    let mut out = Vec::new();
    for (segment, w) in poses.windows(2).enumerate() {
        let (p0, p1) = (&w[0], &w[1]);
        let dt = p1.time - p0.time;
        if !p0.spray || !(dt > 0.0) {
            continue;
        }
        let len = p0.position.distance(p1.position);
        let turn = p0.axis.dot(p1.axis).clamp(-1.0, 1.0).acos() * h;
        let m = ((len.max(turn) / delta).ceil() as usize).clamp(1, 1_000_000);
        let c = 1000.0 * gun.flow * h * h * dt / m as f64;
        for k in 0..m {
            let s = (k as f64 + 0.5) / m as f64;
            let g = p0.position.lerp(p1.position, s);
            let a = p0.axis.lerp(p1.axis, s).try_normalize().unwrap_or(p0.axis);
            out.push(Step { g, a, c, segment: segment as u32 });
        }
    }
    out
}

/// Most steps a path may be cut into for simulation.
pub const MAX_STEPS: usize = 50_000_000;

/// The thickness (µm) a path leaves at every sample point. Deterministic: the result does not
/// depend on the number of threads.
pub fn simulate(gun: &Gun, poses: &[Pose], points: &SamplePoints) -> Result<Vec<f64>, SprayError> {
    gun.validate()?;
    validate_path(poses)?;
    let steps = steps(gun, poses);
    if steps.len() > MAX_STEPS {
        return Err(SprayError::TooLarge { what: format!("{} integration steps (at most {MAX_STEPS})", steps.len()) });
    }
    let np = points.len();
    if np == 0 || steps.is_empty() {
        return Ok(vec![0.0; np]);
    }
    let grid = Grid::new(&points.positions, gun.radius);
    // Scatter: every step to the non-empty cells its cone's bounding box touches.
    let cone = Cone::new(gun);
    let mut pairs: Vec<(u32, u32)> = steps
        .par_iter()
        .enumerate()
        .fold(Vec::new, |mut acc, (si, st)| {
            let (lo, hi) = cone.bounds(st);
            grid.for_cells(lo, hi, |cell| acc.push((cell, si as u32)));
            acc
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    pairs.par_sort_unstable();
    // Gather: every cell's points against its steps, in step order.
    let mut bounds: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < pairs.len() {
        let mut j = i + 1;
        while j < pairs.len() && pairs[j].0 == pairs[i].0 {
            j += 1;
        }
        bounds.push((i, j));
        i = j;
    }
    let results: Vec<(u32, Vec<f64>)> = bounds
        .par_iter()
        .map(|&(i, j)| {
            let cell = pairs[i].0;
            let pts = grid.points(cell);
            let mut vals = vec![0.0; pts.len()];
            for &(_, si) in &pairs[i..j] {
                let st = steps[si as usize];
                for (slot, &pi) in pts.iter().enumerate() {
                    let pi = pi as usize;
                    vals[slot] += cone.amount(&st, points.positions[pi], points.normals[pi]);
                }
            }
            (cell, vals)
        })
        .collect();
    let mut out = vec![0.0; np];
    for (cell, vals) in results {
        for (&pi, v) in grid.points(cell).iter().zip(vals) {
            out[pi as usize] = v;
        }
    }
    Ok(out)
}

/// What each spray segment of a path leaves at the sample points, as the path is timed. The
/// thickness of the path is the sum of the columns, and a segment sprayed for s times as long
/// leaves s times its column: the model is linear in the segments' durations.
#[derive(Debug, Clone, Default)]
pub struct Influence {
    /// The pose index that starts each segment (its spray runs to the next pose).
    pub segments: Vec<u32>,
    /// Per segment: (sample point, thickness in µm), points in increasing order.
    pub columns: Vec<Vec<(u32, f64)>>,
}

/// The [`Influence`] of every spray segment of `poses` on `points`.
pub fn influence(gun: &Gun, poses: &[Pose], points: &SamplePoints) -> Result<Influence, SprayError> {
    gun.validate()?;
    validate_path(poses)?;
    let steps = steps(gun, poses);
    if steps.len() > MAX_STEPS {
        return Err(SprayError::TooLarge { what: format!("{} integration steps (at most {MAX_STEPS})", steps.len()) });
    }
    if points.is_empty() || steps.is_empty() {
        return Ok(Influence::default());
    }
    // Steps come in segment order: cut them into runs of one segment.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < steps.len() {
        let mut j = i + 1;
        while j < steps.len() && steps[j].segment == steps[i].segment {
            j += 1;
        }
        runs.push((i, j));
        i = j;
    }
    let grid = Grid::new(&points.positions, gun.radius);
    let cone = Cone::new(gun);
    let columns: Vec<Vec<(u32, f64)>> = runs
        .par_iter()
        .map(|&(i, j)| {
            let mut col: Vec<(u32, f64)> = Vec::new();
            for st in &steps[i..j] {
                let (lo, hi) = cone.bounds(st);
                grid.for_cells(lo, hi, |cell| {
                    for &pi in grid.points(cell) {
                        let v = cone.amount(st, points.positions[pi as usize], points.normals[pi as usize]);
                        if v > 0.0 {
                            col.push((pi, v));
                        }
                    }
                });
            }
            col.sort_unstable_by_key(|e| e.0);
            col.dedup_by(|b, a| {
                if a.0 == b.0 {
                    a.1 += b.1;
                    true
                } else {
                    false
                }
            });
            col
        })
        .collect();
    Ok(Influence { segments: runs.iter().map(|&(i, _)| steps[i].segment).collect(), columns })
}

/// A uniform grid of points (cells of about one footprint radius), for finding the points a
/// spray cone may reach.
struct Grid {
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Most cells of the point grid.
const MAX_CELLS: f64 = 4_000_000.0;

impl Grid {
    fn new(points: &[DVec3], radius: f64) -> Grid {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in points {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let ext = (hi - lo).max(DVec3::splat(1e-9));
        let mut cell = radius.max(1e-9);
        while (ext.x / cell + 1.0) * (ext.y / cell + 1.0) * (ext.z / cell + 1.0) > MAX_CELLS {
            cell *= 1.25;
        }
        let dims = [(ext.x / cell) as usize + 1, (ext.y / cell) as usize + 1, (ext.z / cell) as usize + 1];
        let n = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; n + 1];
        let idx: Vec<usize> = points
            .iter()
            .map(|p| {
                let c = ((*p - lo) / cell).floor();
                let ix = (c.x.max(0.0) as usize).min(dims[0] - 1);
                let iy = (c.y.max(0.0) as usize).min(dims[1] - 1);
                let iz = (c.z.max(0.0) as usize).min(dims[2] - 1);
                (iz * dims[1] + iy) * dims[0] + ix
            })
            .collect();
        for &c in &idx {
            start[c + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; points.len()];
        for (i, &c) in idx.iter().enumerate() {
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        Grid { lo, cell, dims, start, items }
    }

    fn points(&self, cell: u32) -> &[u32] {
        &self.items[self.start[cell as usize] as usize..self.start[cell as usize + 1] as usize]
    }

    /// Calls `f` with every non-empty cell overlapping the box [lo, hi].
    fn for_cells(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u32)) {
        let range = |l: f64, h: f64, d: usize| -> Option<(usize, usize)> {
            let a = (l / self.cell).floor();
            let b = (h / self.cell).floor();
            if b < 0.0 || a > (d - 1) as f64 || !(a <= b) {
                return None;
            }
            Some((a.max(0.0) as usize, (b as usize).min(d - 1)))
        };
        let (l, h) = (lo - self.lo, hi - self.lo);
        let (Some(rx), Some(ry), Some(rz)) =
            (range(l.x, h.x, self.dims[0]), range(l.y, h.y, self.dims[1]), range(l.z, h.z, self.dims[2]))
        else {
            return;
        };
        for iz in rz.0..=rz.1 {
            for iy in ry.0..=ry.1 {
                let row = (iz * self.dims[1] + iy) * self.dims[0];
                for ix in rx.0..=rx.1 {
                    let c = row + ix;
                    if self.start[c + 1] > self.start[c] {
                        f(c as u32);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gun() -> Gun {
        Gun { standoff: 200.0, radius: 50.0, profile: Profile::Beta { beta: 2.0 }, flow: 500.0 }
    }

    #[test]
    fn rate_on_the_reference_plane_is_the_profile() {
        let g = gun();
        let k = g.profile.kernel(g.radius);
        let gp = DVec3::new(0.0, 0.0, 200.0);
        for x in [0.0, 10.0, 30.0, 49.0] {
            let r = g.rate(gp, -DVec3::Z, DVec3::new(x, 0.0, 0.0), DVec3::Z);
            assert!((r - 1000.0 * g.flow * k.density(x * x)).abs() < 1e-9 * r.max(1.0), "{x}");
        }
        assert_eq!(g.rate(gp, -DVec3::Z, DVec3::new(51.0, 0.0, 0.0), DVec3::Z), 0.0);
        // facing away
        assert_eq!(g.rate(gp, -DVec3::Z, DVec3::ZERO, -DVec3::Z), 0.0);
    }

    #[test]
    fn a_farther_plane_gets_the_same_material_spread_wider() {
        // All the material of a still gun lands on any plane square to it within reach: the
        // integral of the rate over the plane is F whatever the distance.
        let g = gun();
        for dist in [150.0, 200.0, 330.0] {
            let gp = DVec3::new(0.0, 0.0, dist);
            let n = 400;
            let half = 50.0 * dist / 200.0 * 1.01;
            let dx = 2.0 * half / n as f64;
            let mut total = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let p = DVec3::new(-half + (i as f64 + 0.5) * dx, -half + (j as f64 + 0.5) * dx, 0.0);
                    total += g.rate(gp, -DVec3::Z, p, DVec3::Z) * dx * dx;
                }
            }
            // µm·mm²/s = 1e-3 mm³/s
            assert!((total / 1000.0 - g.flow).abs() < 2e-3 * g.flow, "{dist}: {}", total / 1000.0);
        }
    }

    #[test]
    fn grid_simulation_matches_direct_sum() {
        // A short path over a bumpy sheet: simulate() against a brute-force double loop.
        let g = gun();
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        for i in 0..40 {
            for j in 0..30 {
                let (x, y) = (i as f64 * 7.0 - 140.0, j as f64 * 7.0 - 100.0);
                let z = 0.1 * x + 15.0 * (y / 60.0).sin();
                positions.push(DVec3::new(x, y, z));
                normals.push(DVec3::new(-0.1, -0.25 * (y / 60.0).cos(), 1.0).normalize());
            }
        }
        let n = positions.len();
        let pts = SamplePoints { positions, normals, weights: vec![1.0; n], faces: vec![0; n], vertices: 0 };
        let poses = vec![
            Pose {
                position: DVec3::new(-150.0, 0.0, 200.0),
                axis: -DVec3::Z,
                time: 0.0,
                spray: true,
                patch: None,
                pass: None,
            },
            Pose {
                position: DVec3::new(120.0, 30.0, 220.0),
                axis: DVec3::new(0.2, 0.0, -1.0).normalize(),
                time: 0.5,
                spray: false,
                patch: None,
                pass: None,
            },
            Pose {
                position: DVec3::new(100.0, -60.0, 200.0),
                axis: -DVec3::Z,
                time: 0.7,
                spray: true,
                patch: None,
                pass: None,
            },
            Pose {
                position: DVec3::new(-100.0, -60.0, 180.0),
                axis: -DVec3::Z,
                time: 1.1,
                spray: false,
                patch: None,
                pass: None,
            },
        ];
        let got = simulate(&g, &poses, &pts).unwrap();
        let st = steps(&g, &poses);
        for i in 0..n {
            // s.c / (1000 F h²) is the step's Δt
            let dt = |s: &Step| s.c / (1000.0 * g.flow * g.standoff * g.standoff);
            let want: f64 = st.iter().map(|s| g.rate(s.g, s.a, pts.positions[i], pts.normals[i]) * dt(s)).sum();
            assert!((got[i] - want).abs() <= 1e-9 * want.abs().max(1e-9), "{i}: {} vs {want}", got[i]);
        }
        assert!(got.iter().any(|&t| t > 0.0));
    }

    #[test]
    fn bad_paths_are_refused() {
        let g = gun();
        let p = Pose { position: DVec3::ZERO, axis: -DVec3::Z, time: 1.0, spray: true, patch: None, pass: None };
        let pts = SamplePoints::default();
        let mut q = p;
        q.time = 0.5;
        assert!(matches!(simulate(&g, &[p, q], &pts), Err(SprayError::BadPath { index: 1, .. })));
        let mut q = p;
        q.axis = DVec3::new(0.0, 0.0, -2.0);
        assert!(matches!(simulate(&g, &[q], &pts), Err(SprayError::BadPath { index: 0, .. })));
        let mut q = p;
        q.position.x = f64::NAN;
        assert!(simulate(&g, &[p, q], &pts).is_err());
    }
}
