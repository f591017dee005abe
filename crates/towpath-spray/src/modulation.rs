//! Speed modulation: the gun's speed along every pass adjusted, segment by segment, so that the
//! thickness over the part comes as close to the target as the passes allow.
//!
//! The pass planner chooses a spacing and one speed per patch from the 1-D raster model
//! ([`spacing`](crate::spacing)); on curved multi-patch parts that model does not hold where two
//! patches meet (rasters at an angle, passes of one patch reaching over the other), and stripes
//! that are too thin or too thick follow the seams. Thickness is linear in the time the gun
//! spends on each segment of the path (the deposition integral of [`deposition`](crate::deposition)),
//! so scaling the duration of spray segment j by s_j gives the thickness `A s` at the sample
//! points, A holding each segment's [`influence`]. The scales minimise the weighted least-squares
//! error plus a smoothness term between consecutive segments of a pass (a robot cannot change
//! speed in a jump):
//!
//! ```text
//! min  Σ_i w_i (Σ_j A_ij s_j − T)² / T²  +  μ Σ_(j,k consecutive) (s_j − s_k)²
//! s.t. 1/F ≤ s_j ≤ F
//! ```
//!
//! with w_i the area of sample point i (a quarter inside the edge band one spray radius wide,
//! where thickness falls off whatever the speed), T the target thickness and F the largest speed
//! change (`--max-speed-change`, default 3: speeds between a third of and three times the planned speed).
//! The box-constrained quadratic is solved by accelerated projected gradient (Beck & Teboulle
//! 2009, FISTA) from s = 1. This is the dwell-time formulation of spray and deposition path
//! planning (e.g. Atkar et al. 2005 optimise the speed profile along a pass for uniform coverage); here
//! it is solved over the whole part at once, seams included.
//!
//! The sample points are coarse (cells of a fifth of the spray radius, one point per cell and
//! normal direction), which keeps the cost independent of the mesh's resolution.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use towpath_geom::Mesh;

use crate::deposition::{influence, Gun, Pose, SamplePoints};
use crate::error::SprayError;
use crate::thickness::band_mask;

/// Default largest speed change F (speeds between v/F and v·F).
pub const DEFAULT_MAX_SPEED_CHANGE: f64 = 3.0;
/// Accelerated projected-gradient iterations.
pub const ITERATIONS: usize = 400;
/// Weight of a sample point inside the edge band, relative to its area.
pub const BAND_WEIGHT: f64 = 0.25;
/// Smoothness weight relative to the mean diagonal of the data term.
pub const SMOOTHNESS: f64 = 2.0;
/// Sample cell size as a share of the spray radius.
pub const CELL: f64 = 0.2;

/// What the modulation did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ModulationReport {
    /// Spray segments whose speed was adjusted.
    pub segments: usize,
    /// Coarse sample points.
    pub points: usize,
    /// RMS deviation from the target relative to it, on the coarse points (weighted, edge band
    /// at a quarter), before.
    pub rms_before: f64,
    /// The same after.
    pub rms_after: f64,
    /// Smallest speed factor applied (new speed / planned speed).
    pub min_speed_factor: f64,
    /// Largest speed factor applied.
    pub max_speed_factor: f64,
    /// Spray time before (s).
    pub spray_time_before_s: f64,
    /// Spray time after (s).
    pub spray_time_after_s: f64,
}

/// Coarse sample points: points inside the triangles at most `cell` apart
/// ([`SamplePoints::new`]), merged per grid cell of side `cell` and per direction of the normal
/// (its largest component and sign), area-weighted.
pub fn coarse_points(mesh: &Mesh, cell: f64) -> Result<SamplePoints, SprayError> {
    let fine = SamplePoints::new(mesh, cell)?;
    let mut index: HashMap<(i64, i64, i64, u8), usize> = HashMap::new();
    let mut sums: Vec<(DVec3, DVec3, f64)> = Vec::new();
    let mut faces: Vec<u32> = Vec::new();
    for i in fine.vertices..fine.len() {
        let (c, n, a) = (fine.positions[i], fine.normals[i], fine.weights[i]);
        if !(a > 0.0 && c.is_finite() && n.is_finite()) {
            continue;
        }
        let na = n.abs();
        let axis = if na.x >= na.y && na.x >= na.z {
            0
        } else if na.y >= na.z {
            1
        } else {
            2
        };
        let sign = u8::from(n[axis] < 0.0);
        let g = (c / cell).floor();
        let key = (g.x as i64, g.y as i64, g.z as i64, axis as u8 * 2 + sign);
        let k = *index.entry(key).or_insert_with(|| {
            sums.push((DVec3::ZERO, DVec3::ZERO, 0.0));
            faces.push(fine.faces[i]);
            sums.len() - 1
        });
        sums[k].0 += c * a;
        sums[k].1 += n * a;
        sums[k].2 += a;
    }
    let mut s = SamplePoints::default();
    for ((pw, nw, w), f) in sums.into_iter().zip(faces) {
        s.positions.push(pw / w);
        s.normals.push(nw.try_normalize().unwrap_or(DVec3::Z));
        s.weights.push(w);
        s.faces.push(f);
    }
    Ok(s)
}

/// Adjusts the durations of the spray segments of `poses` (and so every later time stamp) as
/// the module docs say. `max_change` ≤ 1 leaves the path as it is.
pub fn modulate(
    mesh: &Mesh,
    gun: &Gun,
    poses: &mut [Pose],
    target: f64,
    max_change: f64,
) -> Result<ModulationReport, SprayError> {
    let points = coarse_points(mesh, gun.radius * CELL)?;
    let inf = influence(gun, poses, &points)?;
    let nseg = inf.segments.len();
    let spray_time: f64 = inf.segments.iter().map(|&j| poses[j as usize + 1].time - poses[j as usize].time).sum();
    let mut report = ModulationReport {
        segments: nseg,
        points: points.len(),
        min_speed_factor: 1.0,
        max_speed_factor: 1.0,
        spray_time_before_s: spray_time,
        spray_time_after_s: spray_time,
        ..ModulationReport::default()
    };
    if nseg == 0 || points.is_empty() || !(target > 0.0) {
        return Ok(report);
    }
    let in_band = band_mask(mesh, &points, gun.radius);
    let total: f64 = points.weights.iter().sum();
    // w_i / T², normalised to sum one.
    let w: Vec<f64> = points
        .weights
        .iter()
        .zip(&in_band)
        .map(|(&a, &b)| a * if b { BAND_WEIGHT } else { 1.0 } / total / (target * target))
        .collect();
    // Pairs of consecutive segments of one pass.
    let pairs: Vec<(usize, usize)> = (1..nseg)
        .filter(|&k| {
            let (a, b) = (inf.segments[k - 1] as usize, inf.segments[k] as usize);
            b == a + 1 && poses[a].pass.is_some() && poses[a].pass == poses[b].pass
        })
        .map(|k| (k - 1, k))
        .collect();
    let m = Sparse::new(&inf.columns, points.len());
    let rms = |t: &[f64]| -> f64 {
        let ws: f64 = w.iter().sum();
        (t.iter().zip(&w).map(|(&x, &wi)| wi * (x - target) * (x - target)).sum::<f64>() / ws).sqrt()
    };
    // Data-term Hessian: H = 2 AᵀWA; its mean diagonal scales the smoothness weight.
    let diag_mean = (0..nseg).map(|j| m.col(j).map(|(i, a)| w[i] * a * a).sum::<f64>()).sum::<f64>() / nseg as f64;
    let mu = SMOOTHNESS * diag_mean;
    // Lipschitz constant of the gradient: power iteration on H (data part) plus the path
    // Laplacian's bound 4·2μ.
    let mut v = vec![1.0; nseg];
    let mut lambda = 0.0;
    for _ in 0..30 {
        let av = m.times(&v);
        let wav: Vec<f64> = av.iter().zip(&w).map(|(a, wi)| 2.0 * a * wi).collect();
        let hv = m.transpose_times(&wav);
        let norm = hv.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm > 0.0) {
            break;
        }
        lambda = norm / v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v = hv.iter().map(|x| x / norm).collect();
    }
    let lip = 1.05 * lambda + 8.0 * mu;
    if !(lip > 0.0 && lip.is_finite()) {
        return Ok(report);
    }
    let (lo, hi) = (1.0 / max_change.max(1.0), max_change.max(1.0));
    let t0 = m.times(&vec![1.0; nseg]);
    report.rms_before = rms(&t0) / target;
    if hi <= 1.0 {
        report.rms_after = report.rms_before;
        return Ok(report);
    }
    // FISTA with projection on the box; stops early when the objective has stalled.
    let objective = |s: &[f64], t: &[f64]| -> f64 {
        let data: f64 = t.iter().zip(&w).map(|(&x, &wi)| wi * (x - target) * (x - target)).sum();
        data + mu * pairs.iter().map(|&(a, b)| (s[a] - s[b]) * (s[a] - s[b])).sum::<f64>()
    };
    let mut x = vec![1.0; nseg];
    let mut y = x.clone();
    let mut tk = 1.0f64;
    let mut last = objective(&x, &t0);
    for it in 1..=ITERATIONS {
        let ty = m.times(&y);
        let wr: Vec<f64> = ty.iter().zip(&w).map(|(&t, &wi)| 2.0 * wi * (t - target)).collect();
        let mut g = m.transpose_times(&wr);
        for &(a, b) in &pairs {
            let d = 2.0 * mu * (y[a] - y[b]);
            g[a] += d;
            g[b] -= d;
        }
        let xn: Vec<f64> = y.iter().zip(&g).map(|(&yj, &gj)| (yj - gj / lip).clamp(lo, hi)).collect();
        let tn = 0.5 * (1.0 + (1.0 + 4.0 * tk * tk).sqrt());
        let beta = (tk - 1.0) / tn;
        y = xn.iter().zip(&x).map(|(&a, &b)| a + beta * (a - b)).collect();
        x = xn;
        tk = tn;
        if it % 50 == 0 {
            let f = objective(&x, &m.times(&x));
            if !(f < last * (1.0 - 1e-4)) {
                break;
            }
            last = f;
        }
    }
    let t1 = m.times(&x);
    report.rms_after = rms(&t1) / target;
    if !(report.rms_after < report.rms_before) {
        report.rms_after = report.rms_before;
        return Ok(report);
    }
    // New time stamps.
    let mut scale = vec![1.0; poses.len()];
    for (&j, &s) in inf.segments.iter().zip(&x) {
        scale[j as usize] = s;
    }
    let old: Vec<f64> = poses.iter().map(|p| p.time).collect();
    for k in 1..poses.len() {
        poses[k].time = poses[k - 1].time + (old[k] - old[k - 1]) * scale[k - 1];
    }
    report.spray_time_after_s =
        inf.segments.iter().zip(&x).map(|(&j, &s)| s * (old[j as usize + 1] - old[j as usize])).sum();
    report.min_speed_factor = x.iter().fold(f64::INFINITY, |m, &s| m.min(1.0 / s));
    report.max_speed_factor = x.iter().fold(0.0f64, |m, &s| m.max(1.0 / s));
    Ok(report)
}

/// A sparse matrix kept both by column (segments) and by row (points), for parallel products.
struct Sparse {
    col_start: Vec<usize>,
    col_rows: Vec<u32>,
    col_vals: Vec<f64>,
    row_start: Vec<usize>,
    row_cols: Vec<u32>,
    row_vals: Vec<f64>,
}

impl Sparse {
    fn new(columns: &[Vec<(u32, f64)>], rows: usize) -> Sparse {
        let mut col_start = vec![0];
        let (mut col_rows, mut col_vals) = (Vec::new(), Vec::new());
        let mut count = vec![0usize; rows + 1];
        for c in columns {
            for &(i, a) in c {
                col_rows.push(i);
                col_vals.push(a);
                count[i as usize + 1] += 1;
            }
            col_start.push(col_rows.len());
        }
        for i in 0..rows {
            count[i + 1] += count[i];
        }
        let row_start = count.clone();
        let mut fill = count;
        let mut row_cols = vec![0u32; col_rows.len()];
        let mut row_vals = vec![0.0; col_rows.len()];
        for (j, c) in columns.iter().enumerate() {
            for &(i, a) in c {
                let k = &mut fill[i as usize];
                row_cols[*k] = j as u32;
                row_vals[*k] = a;
                *k += 1;
            }
        }
        Sparse { col_start, col_rows, col_vals, row_start, row_cols, row_vals }
    }

    fn col(&self, j: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.col_start[j]..self.col_start[j + 1];
        self.col_rows[r.clone()].iter().zip(&self.col_vals[r]).map(|(&i, &a)| (i as usize, a))
    }

    /// A·s (one value per point).
    fn times(&self, s: &[f64]) -> Vec<f64> {
        (0..self.row_start.len() - 1)
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                let r = self.row_start[i]..self.row_start[i + 1];
                self.row_cols[r.clone()].iter().zip(&self.row_vals[r]).map(|(&j, &a)| a * s[j as usize]).sum()
            })
            .collect()
    }

    /// Aᵀ·r (one value per segment).
    fn transpose_times(&self, r: &[f64]) -> Vec<f64> {
        (0..self.col_start.len() - 1)
            .into_par_iter()
            .with_min_len(64)
            .map(|j| self.col(j).map(|(i, a)| a * r[i]).sum())
            .collect()
    }
}
