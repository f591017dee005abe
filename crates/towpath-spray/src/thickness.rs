//! The thickness map of a path on a part: per vertex (for display) and at points inside every
//! triangle (for the statistics), and the statistics over the part without its edge band.

use glam::DVec3;
use rayon::prelude::*;
use rstar::{primitives::Line, PointDistance, RTree};
use serde::Serialize;
use towpath_geom::{Mesh, NO_FACE};

use crate::deposition::{simulate, Gun, Pose, SamplePoints};
use crate::error::SprayError;

/// Statistics of thickness over a set of sample points, weighted by the area each stands for.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ThicknessStats {
    /// Area-weighted mean (µm).
    pub mean: f64,
    /// Smallest value (µm).
    pub min: f64,
    /// Largest value (µm).
    pub max: f64,
    /// RMS deviation from the mean, relative to the mean.
    pub rms_rel: f64,
    /// Share of the area within ±20 % of the target.
    pub within_20pct: f64,
    /// Area covered by the points (mm²).
    pub area_mm2: f64,
    /// Number of points.
    pub points: usize,
}

impl ThicknessStats {
    /// Statistics of `values` weighted by `weights`, over the points where `keep` is true.
    pub fn of(values: &[f64], weights: &[f64], keep: impl Fn(usize) -> bool, target: f64) -> ThicknessStats {
        let (mut w, mut s, mut mn, mut mx, mut n, mut ok) = (0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY, 0, 0.0);
        for i in 0..values.len() {
            if !keep(i) || !(weights[i] > 0.0) {
                continue;
            }
            let v = values[i];
            w += weights[i];
            s += weights[i] * v;
            mn = mn.min(v);
            mx = mx.max(v);
            n += 1;
            if (v - target).abs() <= 0.2 * target {
                ok += weights[i];
            }
        }
        if n == 0 || !(w > 0.0) {
            return ThicknessStats::default();
        }
        let mean = s / w;
        let mut var = 0.0;
        for i in 0..values.len() {
            if keep(i) && weights[i] > 0.0 {
                var += weights[i] * (values[i] - mean) * (values[i] - mean);
            }
        }
        let rms_rel = if mean > 0.0 { (var / w).sqrt() / mean } else { 0.0 };
        ThicknessStats { mean, min: mn, max: mx, rms_rel, within_20pct: ok / w, area_mm2: w, points: n }
    }
}

/// Predicted thickness on a part.
#[derive(Debug, Clone)]
pub struct ThicknessMap {
    /// Thickness at every mesh vertex (µm), in vertex order.
    pub vertex: Vec<f64>,
    /// The sample points (vertices first, then points inside triangles).
    pub points: SamplePoints,
    /// Thickness at every sample point (µm).
    pub values: Vec<f64>,
    /// Which sample points lie in the edge band.
    pub in_band: Vec<bool>,
    /// Width of the edge band (mm).
    pub band: f64,
    /// Statistics without the edge band.
    pub interior: ThicknessStats,
    /// Statistics over the whole part.
    pub whole: ThicknessStats,
    /// Triangles with a sample point below 1 % of the target (not really covered).
    pub uncovered_triangles: usize,
    /// The target thickness (µm).
    pub target: f64,
}

impl ThicknessMap {
    /// Simulates `poses` on `mesh`, with sample points inside triangles at most `spacing` apart,
    /// and computes the statistics without a band of width `band` along the mesh boundary.
    pub fn compute(
        mesh: &Mesh,
        gun: &Gun,
        poses: &[Pose],
        target: f64,
        spacing: f64,
        band: f64,
    ) -> Result<ThicknessMap, SprayError> {
        let points = SamplePoints::new(mesh, spacing)?;
        let values = simulate(gun, poses, &points)?;
        let in_band = band_mask(mesh, &points, band);
        let interior = ThicknessStats::of(&values, &points.weights, |i| !in_band[i], target);
        let whole = ThicknessStats::of(&values, &points.weights, |_| true, target);
        let mut thin = vec![false; mesh.num_faces()];
        for i in points.vertices..points.len() {
            if values[i] < 0.01 * target {
                thin[points.faces[i] as usize] = true;
            }
        }
        let uncovered_triangles = thin.iter().filter(|&&t| t).count();
        let vertex = values[..points.vertices].to_vec();
        Ok(ThicknessMap { vertex, points, values, in_band, band, interior, whole, uncovered_triangles, target })
    }
}

/// Marks the points within `band` of the mesh's boundary edges.
pub fn band_mask(mesh: &Mesh, points: &SamplePoints, band: f64) -> Vec<bool> {
    let mut segs = Vec::new();
    for f in 0..mesh.num_faces() as u32 {
        let c = mesh.corners(f);
        for k in 0..3 {
            if mesh.neighbor(f, k) == NO_FACE {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                segs.push(Line::new(a.to_array(), b.to_array()));
            }
        }
    }
    if segs.is_empty() || !(band > 0.0) {
        return vec![false; points.len()];
    }
    let tree = RTree::bulk_load(segs);
    let b2 = band * band;
    points
        .positions
        .par_iter()
        .map(|p: &DVec3| {
            let q = p.to_array();
            tree.nearest_neighbor(&q).is_some_and(|s| s.distance_2(&q) < b2)
        })
        .collect()
}
