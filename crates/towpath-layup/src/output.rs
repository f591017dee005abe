//! Writing courses: a JSON document (per course: points, normals, directions, per-tow laid
//! intervals and restart/cut events, quality), a CSV table for quick plotting, and a G-code
//! program through a simple post-processor in the towpath reference dialect
//! (`docs/layup-gcode.md` describes the exact shape).

use std::fmt::Write as _;

use glam::DVec3;
use serde::Serialize;

use crate::course::TowEvent;
use crate::ply::{Method, Ply};
use crate::quality::PlyQuality;

/// Description of what was generated, written at the top of every output.
#[derive(Debug, Clone, Serialize)]
pub struct Meta {
    /// The surface as given (file or analytic description).
    pub surface: String,
    /// Ply angle (degrees).
    pub angle_deg: f64,
    /// How the design direction was given (`axis`, `guides`, `orientations`).
    pub direction_source: String,
    /// Tow width (mm).
    pub tow_width: f64,
    /// Tows per course.
    pub tows: usize,
    /// Coverage rule (0, 50, 100).
    pub coverage_percent: u32,
    /// Course method.
    pub method: Method,
    /// Ply number in programs.
    pub ply_number: usize,
    /// Units the surface and lengths were given in (every output is in millimetres).
    pub input_units: crate::units::Units,
}

#[derive(Serialize)]
struct CourseOut<'a> {
    id: usize,
    side: i8,
    offset_index: usize,
    length: f64,
    points: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    directions: Vec<[f64; 3]>,
    arc_length: Vec<f64>,
    on_surface: &'a [bool],
    tows: Vec<TowOut<'a>>,
    events: Vec<EventOut>,
    angle_deviation_deg: &'a [f64],
    steering_radius: &'a [Option<f64>],
    gap_to_left: &'a [[f64; 2]],
}

#[derive(Serialize)]
struct TowOut<'a> {
    tow: usize,
    laid: &'a [[f64; 2]],
}

#[derive(Serialize)]
struct EventOut {
    s: f64,
    point: [f64; 3],
    restart_mask: u64,
    cut_mask: u64,
    restart: Vec<usize>,
    cut: Vec<usize>,
}

#[derive(Serialize)]
struct Summary<'a> {
    courses: usize,
    n1: usize,
    n2: usize,
    n_estimate: [usize; 2],
    section_width: f64,
    seconds: f64,
    timings: crate::ply::Timings,
    #[serde(flatten)]
    quality: QualitySummary<'a>,
}

#[derive(Serialize)]
struct QualitySummary<'a> {
    ply_area: f64,
    coverage_percent: f64,
    gap_area: f64,
    overlap_area: f64,
    max_gap: f64,
    max_overlap: f64,
    min_steering_radius: Option<f64>,
    min_steering_radius_limit: f64,
    points_below_min_radius: usize,
    max_angle_deviation_deg: f64,
    mean_angle_deviation_deg: f64,
    course_length: f64,
    tow_length: f64,
    #[serde(skip)]
    _q: std::marker::PhantomData<&'a ()>,
}

fn bits(mask: u64) -> Vec<usize> {
    (0..64).filter(|k| mask & (1u64 << k) != 0).collect()
}

/// The summary figures of a ply as a JSON value (for `--json`).
pub fn summary(ply: &Ply) -> serde_json::Value {
    serde_json::to_value(Summary {
        courses: ply.courses.len(),
        n1: ply.n1,
        n2: ply.n2,
        n_estimate: ply.n_estimate,
        section_width: ply.section_width,
        seconds: ply.seconds,
        timings: ply.timings,
        quality: quality_summary(&ply.quality),
    })
    .unwrap_or(serde_json::Value::Null)
}

fn quality_summary(q: &PlyQuality) -> QualitySummary<'_> {
    QualitySummary {
        ply_area: q.ply_area,
        coverage_percent: q.coverage_percent,
        gap_area: q.gap_area,
        overlap_area: q.overlap_area,
        max_gap: q.max_gap,
        max_overlap: q.max_overlap,
        min_steering_radius: q.min_steering_radius,
        min_steering_radius_limit: q.min_steering_radius_limit,
        points_below_min_radius: q.points_below_min_radius,
        max_angle_deviation_deg: q.max_angle_deviation_deg,
        mean_angle_deviation_deg: q.mean_angle_deviation_deg,
        course_length: q.course_length,
        tow_length: q.tow_length,
        _q: std::marker::PhantomData,
    }
}

/// The full courses document.
pub fn to_json(ply: &Ply, meta: &Meta) -> serde_json::Value {
    let empty_q = crate::quality::CourseQuality::default();
    let courses: Vec<CourseOut<'_>> = ply
        .courses
        .iter()
        .map(|c| {
            let q = ply.quality.courses.get(c.id).unwrap_or(&empty_q);
            CourseOut {
                id: c.id,
                side: c.side,
                offset_index: c.offset_index,
                length: c.length(),
                points: c.points.iter().map(|p| p.p.to_array()).collect(),
                normals: c.points.iter().map(|p| p.n.to_array()).collect(),
                directions: c.points.iter().map(|p| p.d.to_array()).collect(),
                arc_length: c.points.iter().map(|p| p.s).collect(),
                on_surface: &c.on_surface,
                tows: c.tows.iter().enumerate().map(|(k, ivs)| TowOut { tow: k, laid: ivs }).collect(),
                events: c
                    .events()
                    .into_iter()
                    .map(|e| EventOut {
                        s: e.s,
                        point: c.frame_at(e.s).0.to_array(),
                        restart_mask: e.restart,
                        cut_mask: e.cut,
                        restart: bits(e.restart),
                        cut: bits(e.cut),
                    })
                    .collect(),
                angle_deviation_deg: &q.angle_deviation_deg,
                steering_radius: &q.steering_radius,
                gap_to_left: &q.gap_to_left,
            }
        })
        .collect();
    serde_json::json!({
        "format": "towpath-courses",
        "version": 1,
        "meta": meta,
        "summary": summary(ply),
        "courses": courses,
    })
}

/// CSV: one row per centreline point.
pub fn to_csv(ply: &Ply) -> String {
    let mut out = String::from(
        "course,point,s,x,y,z,nx,ny,nz,dx,dy,dz,on_surface,tows_laid_mask,angle_deviation_deg,steering_radius\n",
    );
    for c in &ply.courses {
        let q = ply.quality.courses.get(c.id);
        for (i, p) in c.points.iter().enumerate() {
            let mut mask = 0u64;
            for k in 0..c.tows.len() {
                if c.laid(k, p.s) {
                    mask |= 1 << k.min(63);
                }
            }
            let dev = q.and_then(|q| q.angle_deviation_deg.get(i)).copied().unwrap_or(0.0);
            let rad = q.and_then(|q| q.steering_radius.get(i).copied().flatten());
            let _ = writeln!(
                out,
                "{},{},{:.4},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{},{},{:.4},{}",
                c.id,
                i,
                p.s,
                p.p.x,
                p.p.y,
                p.p.z,
                p.n.x,
                p.n.y,
                p.n.z,
                p.d.x,
                p.d.y,
                p.d.z,
                u8::from(c.on_surface.get(i).copied().unwrap_or(true)),
                mask,
                dev,
                rad.map_or(String::new(), |r| format!("{r:.1}"))
            );
        }
    }
    out
}

/// Post-processor settings.
#[derive(Debug, Clone, Copy)]
pub struct Post {
    /// Approach/retract clearance along the normal (mm).
    pub clearance: f64,
    /// Lift along the normal after the roller leaves (mm).
    pub lift: f64,
    /// Feed rate of layup moves (mm/min).
    pub feed: f64,
}

impl Default for Post {
    fn default() -> Self {
        Post { clearance: 50.0, lift: 5.0, feed: 6000.0 }
    }
}

/// Head orientation A, B, C (degrees) of a frame with the fiber direction as x and the surface
/// normal as z: R = Rx(A)·Ry(B)·Rz(C), columns (d, n × d, n). A and B tilt the tool axis onto the
/// normal (n = (sin B, −sin A cos B, cos A cos B)); C turns the head about the tool axis last, so
/// C is the heading: the same point laid the other way (d → −d) is C ± 180° with A and B
/// unchanged, which is how `towpath optimize --bidirectional` reverses a course. Singular where
/// the normal lies along ±X (B = ±90°): there A is taken as 0 and C carries the whole turn.
pub fn abc(n: DVec3, d: DVec3) -> [f64; 3] {
    let z = n.normalize_or_zero();
    let x = (d - z * d.dot(z)).normalize_or_zero();
    let y = z.cross(x);
    // R = [x y z] (columns). Row 0 of Rx(A)·Ry(B)·Rz(C) is (cos B cos C, −cos B sin C, sin B);
    // column 2 is (sin B, −sin A cos B, cos A cos B).
    let b = z.x.clamp(-1.0, 1.0).asin();
    let cb = (z.y * z.y + z.z * z.z).sqrt();
    let (a, c) = if cb > 1e-12 {
        ((-z.y).atan2(z.z), (-y.x).atan2(x.x))
    } else {
        // Gimbal lock: with A = 0, R = Ry(±90°)·Rz(C) has x = (0, sin C, ∓cos C) and
        // y = (0, cos C, ±sin C).
        (0.0, x.y.atan2(y.y))
    };
    [a.to_degrees(), b.to_degrees(), c.to_degrees()]
}

/// Keeps an angle within ±180° of the previous one (continuous rotary motion).
fn unwrap(prev: f64, a: f64) -> f64 {
    let mut x = a;
    while x - prev > 180.0 {
        x -= 360.0;
    }
    while x - prev < -180.0 {
        x += 360.0;
    }
    x
}

fn axis_words(p: DVec3, r: [f64; 3]) -> String {
    format!("X{:.3} Y{:.3} Z{:.3} A{:.3} B{:.3} C{:.3}", p.x, p.y, p.z, r[0], r[1], r[2])
}

/// The ply as a G-code program in the reference dialect: per course an approach above the start
/// along the normal (G0), contact (G1), roller on (M20), tow restarts (`M60 P<mask>`) and cuts
/// (`M61 P<mask>`) at their positions between feed moves (G1), roller off (M21), a lift along the
/// normal (G1) and a retract (G0).
pub fn to_gcode(ply: &Ply, meta: &Meta, post: &Post) -> String {
    let mut g = String::new();
    let _ = writeln!(
        g,
        "(towpath layup: surface {} angle {} tows {} x {} mm coverage {} percent method {:?})",
        meta.surface.replace(['(', ')'], ""),
        meta.angle_deg,
        meta.tows,
        meta.tow_width,
        meta.coverage_percent,
        meta.method
    );
    let _ = writeln!(g, "(PLY {} ANGLE={} COURSES={})", meta.ply_number, meta.angle_deg, ply.courses.len());
    let mut prev_abc: Option<[f64; 3]> = None;
    for c in &ply.courses {
        let _ = writeln!(g, "(COURSE {} SIDE={} LENGTH={:.3})", c.id + 1, c.side, c.length());
        let mut rot = |n: DVec3, d: DVec3| -> [f64; 3] {
            let r = abc(n, d);
            let r = match prev_abc {
                Some(p) => [unwrap(p[0], r[0]), unwrap(p[1], r[1]), unwrap(p[2], r[2])],
                None => r,
            };
            prev_abc = Some(r);
            r
        };
        let Some(first) = c.points.first() else { continue };
        let r0 = rot(first.n, first.d);
        let _ = writeln!(g, "G0 {}", axis_words(first.p + first.n * post.clearance, r0));
        let _ = writeln!(g, "G1 {} F{:.0}", axis_words(first.p, r0), post.feed);
        let _ = writeln!(g, "M20");
        let events: Vec<TowEvent> = c.events();
        let mut ei = 0;
        let emit_events = |g: &mut String, upto: f64, ei: &mut usize, rot: &mut dyn FnMut(DVec3, DVec3) -> [f64; 3]| {
            while *ei < events.len() && events[*ei].s <= upto + 1e-9 {
                let e = events[*ei];
                let (p, n, d) = c.frame_at(e.s);
                let r = rot(n, d);
                let _ = writeln!(g, "G1 {}", axis_words(p, r));
                if e.cut != 0 {
                    let _ = writeln!(g, "M61 P{}", e.cut);
                }
                if e.restart != 0 {
                    let _ = writeln!(g, "M60 P{}", e.restart);
                }
                *ei += 1;
            }
        };
        for (i, p) in c.points.iter().enumerate() {
            emit_events(&mut g, p.s, &mut ei, &mut rot);
            if i == 0 {
                continue;
            }
            // Skip a point that coincides with the event just written.
            let r = rot(p.n, p.d);
            let _ = writeln!(g, "G1 {}", axis_words(p.p, r));
        }
        emit_events(&mut g, f64::INFINITY, &mut ei, &mut rot);
        let last = c.points[c.points.len() - 1];
        let rl = rot(last.n, last.d);
        let _ = writeln!(g, "M21");
        let _ = writeln!(g, "G1 {}", axis_words(last.p + last.n * post.lift, rl));
        let _ = writeln!(g, "G0 {}", axis_words(last.p + last.n * post.clearance, rl));
    }
    let _ = writeln!(g, "M30");
    g
}
