//! Quality maps a path designer checks before sending a ply to the machine: per point the angle
//! deviation from the design direction, the geodesic curvature and steering radius (flagged
//! below a minimum); between neighbouring courses the gap/overlap width; per ply the coverage,
//! gap and overlap areas, minimum steering radius and maximum angle deviation.

use glam::DVec3;
use rayon::prelude::*;
use rstar::primitives::GeomWithData;
use rstar::RTree;
use serde::Serialize;
use towpath_geom::Mesh;

use crate::boundary::Region;
use crate::course::Course;
use crate::field::DirectionField;
use crate::laid::LaidMap;
use crate::ply::PlySpec;
use crate::section::Band;
use crate::trace::{walk, PathPoint, Steering, WalkOptions};

/// Per-point figures of one course (same length as its points).
#[derive(Debug, Clone, Default, Serialize)]
pub struct CourseQuality {
    /// Angle between the course direction and the design direction, degrees.
    pub angle_deviation_deg: Vec<f64>,
    /// Signed geodesic curvature (1/mm, positive turning left).
    pub geodesic_curvature: Vec<f64>,
    /// Steering radius 1/|κ_g| (mm); `None` where straight.
    pub steering_radius: Vec<Option<f64>>,
    /// Gap (+) or overlap (−) width to the left neighbour, sampled every `gap_step` along the
    /// course: (arc length, width).
    pub gap_to_left: Vec<[f64; 2]>,
}

/// Figures of a whole ply.
#[derive(Debug, Clone, Default, Serialize)]
pub struct PlyQuality {
    /// Per-course details, by course id.
    pub courses: Vec<CourseQuality>,
    /// Ply area (mm²).
    pub ply_area: f64,
    /// Share of the ply area covered by laid tows (%), from area-weighted samples.
    pub coverage_percent: f64,
    /// Area of gaps between neighbouring courses (mm²).
    pub gap_area: f64,
    /// Area of overlaps between neighbouring courses (mm²).
    pub overlap_area: f64,
    /// Widest gap (mm).
    pub max_gap: f64,
    /// Widest overlap (mm).
    pub max_overlap: f64,
    /// Smallest steering radius over laid points (mm); `None` if every course is straight.
    pub min_steering_radius: Option<f64>,
    /// The minimum the spec asked for (mm).
    pub min_steering_radius_limit: f64,
    /// Points below the minimum steering radius.
    pub points_below_min_radius: usize,
    /// Largest angle deviation (degrees).
    pub max_angle_deviation_deg: f64,
    /// Mean angle deviation (degrees).
    pub mean_angle_deviation_deg: f64,
    /// Total course length (mm) and laid tow length (mm).
    pub course_length: f64,
    /// Sum over tows of laid length (mm).
    pub tow_length: f64,
}

/// Window half-length for curvature estimates: a few tow widths, so facet noise averages out.
fn curvature_window(spec: &PlySpec) -> f64 {
    (2.0 * spec.tow_width).max(5.0)
}

/// Angle deviation and geodesic curvature of one course.
pub fn course_figures(c: &Course, field: &dyn DirectionField, spec: &PlySpec) -> CourseQuality {
    let pts = &c.points;
    let h = curvature_window(spec);
    let mut q = CourseQuality::default();
    let (mut j, mut k) = (0usize, 0usize);
    // Arc-length range of the run of on-surface (or run-out) points containing point i.
    let on_at = |x: usize| c.on_surface.get(x).copied().unwrap_or(true);
    let mut runs: Vec<(f64, f64)> = Vec::with_capacity(pts.len());
    let mut lo = 0;
    for i in 0..pts.len() {
        if i + 1 == pts.len() || on_at(i + 1) != on_at(i) {
            runs.extend(std::iter::repeat_n((pts[lo].s, pts[i].s), i + 1 - lo));
            lo = i + 1;
        }
    }
    let run_bounds = |i: usize| runs.get(i).copied().unwrap_or((0.0, 0.0));
    for (i, p) in pts.iter().enumerate() {
        let dev = field.direction(p.p, p.n).map_or(0.0, |v| v.dot(p.d).abs().clamp(0.0, 1.0).acos().to_degrees());
        q.angle_deviation_deg.push(dev);
        // The window stays on the same side of any run-out boundary (a run-out is straight).
        let on = |x: usize| c.on_surface.get(x).copied().unwrap_or(true);
        while j < i && (pts[j].s < p.s - h || on(j) != on(i)) {
            j += 1;
        }
        if k < i || on(k) != on(i) {
            k = i;
        }
        while k + 1 < pts.len() && pts[k + 1].s <= p.s + h && on(k + 1) == on(i) {
            k += 1;
        }
        let (a, b) = (&pts[j], &pts[k]);
        let ds = b.s - a.s;
        let kappa = if ds >= 0.5 * h {
            (b.d - a.d).dot(p.n.cross(p.d)) / ds
        } else {
            // Points sparser than the window (large triangles crossed in few steps): directions
            // interpolated at the window's ends, within the same run of on- or off-surface points.
            let (lo, hi) = run_bounds(i);
            let (sa, sb) = ((p.s - h).max(lo), (p.s + h).min(hi));
            if sb - sa > 1e-9 {
                let (da, db) = (crate::course::frame_at(pts, sa).2, crate::course::frame_at(pts, sb).2);
                (db - da).dot(p.n.cross(p.d)) / (sb - sa)
            } else {
                0.0
            }
        };
        q.geodesic_curvature.push(kappa);
        q.steering_radius.push((kappa.abs() > 1e-9).then(|| 1.0 / kappa.abs()));
    }
    q
}

type Indexed = GeomWithData<[f64; 3], u32>;

struct Nearest {
    tree: RTree<Indexed>,
    pts: Vec<PathPoint>,
}

impl Nearest {
    fn new(pts: &[PathPoint]) -> Nearest {
        let items: Vec<Indexed> = pts.iter().enumerate().map(|(i, q)| Indexed::new(q.p.to_array(), i as u32)).collect();
        Nearest { tree: RTree::bulk_load(items), pts: pts.to_vec() }
    }
    fn length(&self) -> f64 {
        self.pts.last().map_or(0.0, |q| q.s)
    }

    /// Foot of perpendicular on the polyline near p: (point, normal, arc length, direction).
    fn foot_frame(&self, p: DVec3) -> Option<(DVec3, DVec3, f64, DVec3)> {
        let i = self.tree.nearest_neighbor(&p.to_array())?.data as usize;
        let mut best: Option<(f64, DVec3, DVec3, f64, DVec3)> = None;
        for (a, b) in [(i.saturating_sub(1), i), (i, (i + 1).min(self.pts.len() - 1))] {
            let (qa, qb) = (&self.pts[a], &self.pts[b]);
            let ab = qb.p - qa.p;
            let l2 = ab.length_squared();
            let t = if l2 > 0.0 { ((p - qa.p).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
            let f = qa.p + ab * t;
            let d = f.distance(p);
            if best.is_none_or(|x| d < x.0) {
                let dir = qa.d.lerp(qb.d, t).normalize_or_zero();
                best = Some((d, f, qa.n.lerp(qb.n, t).normalize_or_zero(), qa.s + (qb.s - qa.s) * t, dir));
            }
        }
        best.map(|(_, f, n, s, dir)| (f, n, s, dir))
    }
}

/// Surface distance from course `c` at arc length `s`, walked perpendicular to the fiber to the
/// left, to where the walk crosses the neighbour's centreline; with the neighbour's arc length
/// there. `None` when the walk leaves the mesh or does not cross within `reach`.
fn spacing_to(mesh: &Mesh, c: &Course, near: &Nearest, s: f64, reach: f64) -> Option<(f64, f64)> {
    let (p, _, d) = c.frame_at(s);
    let start = crate::course::locate(mesh, p, crate::course::face_hint(&c.points, s))?;
    let b = start.n.cross(d);
    let opts = WalkOptions::up_to(reach);
    // Side of x relative to the neighbour: > 0 left of it.
    let side = |x: DVec3| -> Option<(f64, f64)> {
        let (f, n, sf, dir) = near.foot_frame(x)?;
        // A foot at the neighbour's very end is no perpendicular foot: no spacing there.
        if sf <= 1e-9 || sf >= near.length() - 1e-9 {
            return None;
        }
        Some(((x - f).dot(n.cross(dir)), sf))
    };
    let (mut prev_x, mut prev_side) = (start.p, side(start.p)?.0);
    if prev_side >= 0.0 {
        return None; // not to the right of the neighbour: not its left neighbour here
    }
    // The chord to the neighbour bounds where the crossing can be: test sides only from there on.
    let chord = near.foot_frame(start.p).map_or(0.0, |f| f.0.distance(start.p));
    let (w, _) = walk(mesh, start, b, Steering::Geodesic, &opts, |q| {
        q.s >= 0.9 * chord && side(q.p).is_none_or(|(sd, _)| sd >= 0.0)
    });
    let mut prev_s = 0.0;
    let mut prev_known = true;
    for q in &w {
        if q.s < 0.9 * chord {
            prev_x = q.p;
            prev_s = q.s;
            prev_known = false;
            continue;
        }
        let (sd, sf) = side(q.p)?;
        if sd >= 0.0 {
            if !prev_known {
                prev_side = side(prev_x)?.0;
            }
            let t = if prev_side < 0.0 { prev_side / (prev_side - sd) } else { 0.0 };
            return Some((prev_s + t * (q.s - prev_s), sf));
        }
        prev_x = q.p;
        prev_side = sd;
        prev_s = q.s;
        prev_known = true;
    }
    None
}

/// Assesses a ply: per-point angle and steering figures, gaps and overlaps between neighbours,
/// coverage of the ply area.
pub fn assess(
    mesh: &Mesh,
    field: &dyn DirectionField,
    region: &Region,
    spec: &PlySpec,
    courses: &[Course],
) -> PlyQuality {
    let mut pq = PlyQuality { min_steering_radius_limit: spec.min_steering_radius, ..PlyQuality::default() };
    angles_and_steering(&mut pq, field, spec, courses);
    gaps_and_overlaps(&mut pq, mesh, spec, courses);
    let (area, covered) = coverage(mesh, region, spec, courses);
    pq.ply_area = area;
    pq.coverage_percent = covered;
    pq
}

/// Angle deviation and steering figures of every course (per point and per ply), lengths.
fn angles_and_steering(pq: &mut PlyQuality, field: &dyn DirectionField, spec: &PlySpec, courses: &[Course]) {
    let nt = spec.tows;
    let mut angle_sum = 0.0;
    let mut angle_n = 0usize;
    for c in courses {
        let mut q = course_figures(c, field, spec);
        for (i, p) in c.points.iter().enumerate() {
            // Only where at least one tow is laid.
            if !(0..nt).any(|k| c.laid(k, p.s)) {
                continue;
            }
            let a = q.angle_deviation_deg[i];
            pq.max_angle_deviation_deg = pq.max_angle_deviation_deg.max(a);
            angle_sum += a;
            angle_n += 1;
            if let Some(r) = q.steering_radius[i] {
                pq.min_steering_radius = Some(pq.min_steering_radius.map_or(r, |m: f64| m.min(r)));
                if r < spec.min_steering_radius {
                    pq.points_below_min_radius += 1;
                }
            }
        }
        pq.course_length += c.length();
        pq.tow_length += c.tows.iter().flatten().map(|iv| iv[1] - iv[0]).sum::<f64>();
        q.gap_to_left.clear();
        pq.courses.push(q);
    }
    if angle_n > 0 {
        pq.mean_angle_deviation_deg = angle_sum / angle_n as f64;
    }
}

/// Gaps and overlaps between each course and its left neighbour, where both edge tows are laid:
/// a geodesic walked from the course's centreline perpendicular to the fiber, to where it
/// crosses the neighbour's centreline; the spacing minus one course width is the gap (+) or
/// overlap (−). The last and first courses are tried as a pair too (closed surfaces).
fn gaps_and_overlaps(pq: &mut PlyQuality, mesh: &Mesh, spec: &PlySpec, courses: &[Course]) {
    let w = spec.tow_width * spec.tows as f64;
    let nt = spec.tows;
    let step = (0.1 * w).clamp(2.0, 10.0);
    let mut pairs: Vec<(usize, usize)> = (0..courses.len().saturating_sub(1)).map(|i| (i, i + 1)).collect();
    if courses.len() > 2 {
        pairs.push((courses.len() - 1, 0));
    }
    let per_pair: Vec<(usize, Vec<[f64; 2]>, f64)> = pairs
        .par_iter()
        .map(|&(i, j)| {
            let (c, nb) = (&courses[i], &courses[j]);
            let near = Nearest::new(&nb.points);
            let len = c.length();
            let count = (len / step).ceil() as usize;
            let ds = len / count.max(1) as f64;
            let mut out = Vec::new();
            for k in 0..=count {
                let s = len * k as f64 / count.max(1) as f64;
                if !c.laid(nt - 1, s) || !c.on_surface_at(s) {
                    continue;
                }
                let Some((spacing, sf)) = spacing_to(mesh, c, &near, s, 1.5 * w) else { continue };
                if !nb.laid(0, sf) || !nb.on_surface_at(sf) {
                    continue;
                }
                out.push([s, spacing - w]);
            }
            (i, out, ds)
        })
        .collect();
    for (i, widths, ds) in per_pair {
        for &[s, width] in &widths {
            let _ = s;
            if width > 0.0 {
                pq.gap_area += width * ds;
                pq.max_gap = pq.max_gap.max(width);
            } else {
                pq.overlap_area += -width * ds;
                pq.max_overlap = pq.max_overlap.max(-width);
            }
        }
        pq.courses[i].gap_to_left.extend(widths);
    }
}

/// Coverage: area-weighted samples inside the ply, each checked against the laid tows of the
/// nearest course stations. Returns the ply area and the covered share (%).
fn coverage(mesh: &Mesh, region: &Region, spec: &PlySpec, courses: &[Course]) -> (f64, f64) {
    let laid = LaidMap::new(courses, Band { tow_width: spec.tow_width, tows: spec.tows });
    // Samples: every face split into m × m sub-triangles (m from the face size and a spacing of
    // half a tow width, within a budget), one sample at each sub-triangle's centroid.
    let nf = mesh.num_faces();
    let budget = 50_000.0;
    let mut h = 0.5 * spec.tow_width;
    let edge_max = |f: u32| {
        let c = mesh.corners(f);
        c[0].distance(c[1]).max(c[1].distance(c[2])).max(c[2].distance(c[0]))
    };
    let count_at = |h: f64| (0..nf as u32).map(|f| (edge_max(f) / h).ceil().clamp(1.0, 64.0).powi(2)).sum::<f64>();
    let mut stride = 1usize;
    while count_at(h) > budget && h < 1e6 {
        h *= 1.5;
        if (edge_max(0) / h) < 1.0 && count_at(h) > budget {
            stride = ((count_at(h) / budget).ceil() as usize).max(1);
            break;
        }
    }
    let faces: Vec<u32> = (0..nf as u32).step_by(stride).collect();
    let hits: Vec<(f64, f64)> = faces
        .par_iter()
        .map(|&f| {
            let c = mesh.corners(f);
            let nf = mesh.face_normal(f);
            let m = (edge_max(f) / h).ceil().clamp(1.0, 64.0) as usize;
            let a = mesh.face_area(f) / (m * m) as f64;
            let (mut area, mut covered) = (0.0, 0.0);
            for i in 0..m {
                for j in 0..(m - i) {
                    // Upward and (where it exists) downward sub-triangle centroids.
                    let mut pts = vec![(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0)];
                    if i + j + 1 < m {
                        pts.push((i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0));
                    }
                    for (u, v) in pts {
                        let (u, v) = (u / m as f64, v / m as f64);
                        let x = c[0] * (1.0 - u - v) + c[1] * u + c[2] * v;
                        if region.has_curve() && region.curve_distance(x, nf) < 0.0 {
                            continue;
                        }
                        area += a;
                        if laid.covers(x, 0.0) {
                            covered += a;
                        }
                    }
                }
            }
            (area, covered)
        })
        .collect();
    let (mut area, mut covered) = (0.0, 0.0);
    for (a, c) in hits {
        area += a;
        covered += c;
    }
    (area * stride as f64, if area > 0.0 { 100.0 * covered / area } else { 0.0 })
}
