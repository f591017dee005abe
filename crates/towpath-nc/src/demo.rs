//! Built-in demo parts modelled on Doherty et al. (2022) §4.5, and large generated parts for benchmarks.
//!
//! Each part is a program in the reference dialect for one of two machines: a planar gantry
//! (X, Y, Z, heading C) and a mandrel machine (X along the mandrel, Z radial, heading C, mandrel
//! A). Plies are rectangles of the surface (the plan, or the unrolled cylinder) filled with
//! parallel courses of 8 tows of 6.35 mm at the ply angle; each tow is cut where its centre
//! line leaves the rectangle (so angled courses drop tows one by one). The programs are laid
//! the way Doherty et al.'s test programs were planned badly: every course in the same direction,
//! plies in an illogical order.

use towpath_machine::{Axis, AxisKind, Machine};

/// Tows per course in the demo parts.
pub const TOWS: u32 = 8;
/// Tow width of the demo parts, mm.
pub const TOW_WIDTH: f64 = 6.35;
/// Stand-off of approach and retract, mm.
const STANDOFF: f64 = 25.0;
/// Longest move written on-part, mm.
const MAX_STEP: f64 = 200.0;

/// A ply: a rectangle of the surface and a fibre angle.
#[derive(Clone, Debug, PartialEq)]
pub struct PlySpec {
    /// Label written in the ply marker.
    pub label: String,
    /// Rectangle `[u0, v0, u1, v1]` in surface coordinates (mm).
    pub rect: [f64; 4],
    /// Fibre angle from the first surface axis, degrees.
    pub angle: f64,
}

/// The surface the part is laid on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// A flat table: u = X, v = Y.
    Plane,
    /// A cylinder on a mandrel of this radius: u = X, v = arc length (A = v / r).
    Cylinder(f64),
}

/// A demo part: a machine and a program.
#[derive(Clone, Debug)]
pub struct DemoPart {
    /// Short file-friendly name.
    pub name: String,
    /// What it is.
    pub description: String,
    /// The figure of Doherty et al. (2022) it is modelled on, with the published savings (off-part %, total %).
    pub seed: Option<(&'static str, f64, f64)>,
    /// The machine.
    pub machine: Machine,
    /// The program text.
    pub program: String,
    /// The cell for motion safety: the mold tool, stringers, fixtures (empty for the parts
    /// without obstacles).
    pub obstacles: Vec<Obstacle>,
}

/// One mesh of a demo part's cell, in the part frame (mm).
#[derive(Clone, Debug)]
pub struct Obstacle {
    /// File-friendly name (`tool`, `stringer`, `clamp`, `flange`).
    pub name: String,
    /// The triangles.
    pub triangles: Vec<[[f64; 3]; 3]>,
}

/// An axis-aligned box `[x0, y0, z0]`–`[x1, y1, z1]` as 12 triangles.
pub fn box_mesh(lo: [f64; 3], hi: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let c = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    // Each face as a quad of corner indices (bit 0: x, bit 1: y, bit 2: z).
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    faces.iter().flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]]).collect()
}

/// A flat rectangle at height `z` as 2 triangles.
pub fn plate_mesh(x: [f64; 2], y: [f64; 2], z: f64) -> Vec<[[f64; 3]; 3]> {
    let p = |i: usize, j: usize| [x[i], y[j], z];
    vec![[p(0, 0), p(1, 0), p(1, 1)], [p(0, 0), p(1, 1), p(0, 1)]]
}

/// A cylinder about the X axis: radius `r` from `x0` to `x1`, `n` facets round and rings of at
/// most 100 mm along (so that no triangle is long and thin), each facet's corners on the
/// radius (so the facets lie just inside it).
pub fn cylinder_mesh(r: f64, x0: f64, x1: f64, n: usize) -> Vec<[[f64; 3]; 3]> {
    let rings = ((x1 - x0).abs() / 100.0).ceil().max(1.0) as usize;
    let at = |i: usize, k: usize| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        [x0 + (x1 - x0) * i as f64 / rings as f64, r * a.cos(), r * a.sin()]
    };
    (0..rings)
        .flat_map(|i| {
            (0..n).flat_map(move |k| {
                [[at(i, k), at(i + 1, k), at(i + 1, k + 1)], [at(i, k), at(i + 1, k + 1), at(i, k + 1)]]
            })
        })
        .collect()
}

/// A flange about the X axis: a ring from radius `r0` to `r1`, between `x0` and `x1`, `n`
/// facets round (both faces and the outer rim).
pub fn flange_mesh(r0: f64, r1: f64, x0: f64, x1: f64, n: usize) -> Vec<[[f64; 3]; 3]> {
    let at = |x: f64, r: f64, k: usize| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        [x, r * a.cos(), r * a.sin()]
    };
    let mut t = cylinder_mesh(r1, x0, x1, n);
    for x in [x0, x1] {
        for k in 0..n {
            t.push([at(x, r0, k), at(x, r1, k), at(x, r1, k + 1)]);
            t.push([at(x, r0, k), at(x, r1, k + 1), at(x, r0, k + 1)]);
        }
    }
    t
}

fn axis(label: &str, kind: AxisKind, weight: f64, v: f64, a: f64) -> Axis {
    let mut x = Axis::new(label, kind);
    x.weight = weight;
    x.max_velocity = Some(v);
    x.max_acceleration = Some(a);
    x
}

/// The planar gantry: X, Y, Z and a continuous heading axis C.
pub fn gantry() -> Machine {
    let mut c = axis("C", AxisKind::Continuous, 0.5, 180.0, 720.0);
    c.heading = true;
    Machine {
        name: "gantry-afp".into(),
        axes: vec![
            axis("X", AxisKind::Linear, 1.0, 1000.0, 2000.0),
            axis("Y", AxisKind::Linear, 1.0, 1000.0, 2000.0),
            axis("Z", AxisKind::Linear, 1.0, 500.0, 1000.0),
            c,
        ],
        dh: Vec::new(),
        tool_offset: None,
        head: None,
    }
}

/// The mandrel machine: X along the mandrel, Z radial, heading C, mandrel A about +X.
pub fn mandrel_machine() -> Machine {
    let mut c = axis("C", AxisKind::Continuous, 0.5, 180.0, 720.0);
    c.heading = true;
    let mut a = axis("A", AxisKind::Mandrel, 5.0, 90.0, 180.0);
    a.direction = Some([1.0, 0.0, 0.0]);
    Machine {
        name: "mandrel-afp".into(),
        axes: vec![
            axis("X", AxisKind::Linear, 1.0, 1000.0, 2000.0),
            axis("Z", AxisKind::Linear, 1.0, 500.0, 1000.0),
            c,
            a,
        ],
        dh: Vec::new(),
        tool_offset: None,
        head: None,
    }
}

/// One course: centre-line points in surface coordinates and tow events at point indices.
struct CourseGeom {
    points: Vec<[f64; 2]>,
    /// (point index, restart?, mask) in order.
    events: Vec<(usize, bool, u64)>,
    heading: f64,
}

/// Clips the line `o + t d` to a rectangle: the parameter interval inside it.
fn clip(o: [f64; 2], d: [f64; 2], r: [f64; 4]) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..2 {
        let (lo, hi) = (r[k], r[k + 2]);
        if d[k].abs() < 1e-12 {
            if o[k] < lo || o[k] > hi {
                return None;
            }
        } else {
            let (a, b) = ((lo - o[k]) / d[k], (hi - o[k]) / d[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t1 - t0 > 1e-6).then_some((t0, t1))
}

/// Courses filling a ply, in order of their offset, each laid in the +direction.
fn ply_courses(p: &PlySpec) -> Vec<CourseGeom> {
    let w = TOW_WIDTH * TOWS as f64;
    let th = p.angle.to_radians();
    let d = [th.cos(), th.sin()];
    let n = [-d[1], d[0]];
    let r = p.rect;
    let centre = [(r[0] + r[2]) / 2.0, (r[1] + r[3]) / 2.0];
    // Extent of the rectangle across the courses.
    let corners = [[r[0], r[1]], [r[2], r[1]], [r[2], r[3]], [r[0], r[3]]];
    let across: Vec<f64> = corners.iter().map(|c| (c[0] - centre[0]) * n[0] + (c[1] - centre[1]) * n[1]).collect();
    let (lo, hi) = (
        across.iter().cloned().fold(f64::INFINITY, f64::min),
        across.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let count = ((hi - lo) / w).ceil() as usize;
    let start = (lo + hi) / 2.0 - (count as f64 - 1.0) * w / 2.0;
    let mut out = Vec::new();
    for k in 0..count {
        let off = start + k as f64 * w;
        let o = [centre[0] + n[0] * off, centre[1] + n[1] * off];
        // Each tow lane's interval along the course.
        let mut lanes: Vec<(u32, f64, f64)> = Vec::new();
        for t in 0..TOWS {
            let lane = (t as f64 - (TOWS as f64 - 1.0) / 2.0) * TOW_WIDTH;
            let lo_ = [o[0] + n[0] * lane, o[1] + n[1] * lane];
            if let Some((a, b)) = clip(lo_, d, r) {
                lanes.push((t, a, b));
            }
        }
        if lanes.is_empty() {
            continue;
        }
        let t_start = lanes.iter().map(|l| l.1).fold(f64::INFINITY, f64::min);
        let t_end = lanes.iter().map(|l| l.2).fold(f64::NEG_INFINITY, f64::max);
        // Stations: every tow event and regular steps.
        let mut ts: Vec<f64> = lanes.iter().flat_map(|l| [l.1, l.2]).collect();
        let steps = ((t_end - t_start) / MAX_STEP).ceil().max(1.0) as usize;
        for s in 0..=steps {
            ts.push(t_start + (t_end - t_start) * s as f64 / steps as f64);
        }
        ts.sort_by(f64::total_cmp);
        ts.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
        let points: Vec<[f64; 2]> = ts.iter().map(|&t| [o[0] + d[0] * t, o[1] + d[1] * t]).collect();
        let idx = |t: f64| ts.iter().position(|&x| (x - t).abs() < 1e-6).unwrap_or(0);
        let mut events: Vec<(usize, bool, u64)> = Vec::new();
        for (i, _) in ts.iter().enumerate() {
            let restart: u64 = lanes.iter().filter(|l| idx(l.1) == i).map(|l| 1u64 << l.0).sum();
            let cut: u64 = lanes.iter().filter(|l| idx(l.2) == i).map(|l| 1u64 << l.0).sum();
            if cut != 0 {
                events.push((i, false, cut));
            }
            if restart != 0 {
                events.push((i, true, restart));
            }
        }
        out.push(CourseGeom { points, events, heading: p.angle.rem_euclid(360.0) });
    }
    out
}

fn num(v: f64) -> String {
    crate::reverse::fmt_num(v, 3)
}

/// Axis words of a surface point at a height above it.
fn words(surface: Surface, p: [f64; 2], z: f64, heading: f64) -> String {
    match surface {
        Surface::Plane => format!("X{} Y{} Z{} C{}", num(p[0]), num(p[1]), num(z), num(heading)),
        Surface::Cylinder(r) => {
            format!("X{} Z{} C{} A{}", num(p[0]), num(r + z), num(heading), num((p[1] / r).to_degrees()))
        }
    }
}

/// Writes a program in the reference dialect: plies in the given order, each ply's courses in
/// their natural order, every course in the same direction.
pub fn program(title: &str, surface: Surface, plies: &[PlySpec]) -> String {
    let mut s = String::new();
    let home = match surface {
        Surface::Plane => "G0 Z100".to_string(),
        Surface::Cylinder(r) => format!("G0 Z{}", num(r + 100.0)),
    };
    s.push_str(&format!("%\n(towpath demo part: {title})\n(G21 mm, absolute)\nG21 G90\n{home}\n"));
    for (pi, ply) in plies.iter().enumerate() {
        s.push_str(&format!("(PLY {} {} {} deg)\n", pi + 1, ply.label, num(ply.angle)));
        for (ci, c) in ply_courses(ply).iter().enumerate() {
            let first = c.points[0];
            s.push_str(&format!("(COURSE {})\n", ci + 1));
            s.push_str(&format!("G0 {}\n", words(surface, first, STANDOFF, c.heading)));
            s.push_str(&format!("G1 {} F3000\n", words(surface, first, 0.0, c.heading)));
            s.push_str("M20\n");
            for (i, p) in c.points.iter().enumerate() {
                if i > 0 {
                    let feed = if i == 1 { " F6000" } else { "" };
                    s.push_str(&format!("G1 {}{feed}\n", words(surface, *p, 0.0, c.heading)));
                }
                for &(_, restart, mask) in c.events.iter().filter(|e| e.0 == i) {
                    s.push_str(&format!("{} P{mask}\n", if restart { "M60" } else { "M61" }));
                }
            }
            s.push_str("M21\n");
            let last = c.points[c.points.len() - 1];
            s.push_str(&format!("G1 {} F3000\n", words(surface, last, STANDOFF, c.heading)));
        }
    }
    s.push_str(&format!("(END OF PART)\n{home}\nM30\n%\n"));
    s
}

fn ply(label: &str, rect: [f64; 4], angle: f64) -> PlySpec {
    PlySpec { label: label.into(), rect, angle }
}

/// Doherty et al.'s (2022) §4.5 planar parts: a 1200 × 800 base ply and three non-intersecting pad-ups
/// placed badly, at one angle.
fn planar(angle: f64, equidistant: bool) -> Vec<PlySpec> {
    let pads: [[f64; 4]; 3] = if equidistant {
        [[80.0, 300.0, 330.0, 500.0], [475.0, 300.0, 725.0, 500.0], [870.0, 300.0, 1120.0, 500.0]]
    } else {
        [[850.0, 520.0, 1120.0, 740.0], [80.0, 60.0, 330.0, 260.0], [820.0, 80.0, 1100.0, 300.0]]
    };
    let mut v = vec![ply("base", [0.0, 0.0, 1200.0, 800.0], angle)];
    // Badly sequenced: the far pad first, then the one by the origin, then far again.
    let order: [usize; 3] = if equidistant { [2, 0, 1] } else { [0, 1, 2] };
    for (k, &i) in order.iter().enumerate() {
        v.push(ply(&format!("pad-up {}", k + 1), pads[i], angle));
    }
    v
}

/// All built-in demo parts.
pub fn demo_parts() -> Vec<DemoPart> {
    // A barrel section: radius 400 mm, 3 m long.
    let r = 400.0;
    let circ = 2.0 * std::f64::consts::PI * r;
    let g = gantry();
    let m = mandrel_machine();
    let part = |name: &str, desc: &str, seed, machine: &Machine, surface, plies: Vec<PlySpec>| DemoPart {
        name: name.into(),
        description: desc.into(),
        seed,
        machine: machine.clone(),
        program: program(name, surface, &plies),
        obstacles: Vec::new(),
    };
    let obstacle = |name: &str, triangles| Obstacle { name: name.into(), triangles };
    vec![
        part(
            "planar-0",
            "planar, base ply and three pad-ups, 0° courses",
            Some(("Fig. 7", 67.9, 38.1)),
            &g,
            Surface::Plane,
            planar(0.0, false),
        ),
        part(
            "planar-0-equidistant",
            "planar, base ply and three equidistant pad-ups, 0° courses",
            Some(("Fig. 8", 65.0, 36.7)),
            &g,
            Surface::Plane,
            planar(0.0, true),
        ),
        part(
            "planar-45",
            "planar, base ply and three pad-ups, 45° courses",
            Some(("Fig. 9", 57.5, 35.6)),
            &g,
            Surface::Plane,
            planar(45.0, false),
        ),
        part(
            "planar-90",
            "planar, base ply and three pad-ups, 90° courses",
            Some(("Fig. 10", 56.2, 34.9)),
            &g,
            Surface::Plane,
            planar(90.0, false),
        ),
        part(
            "cylinder-1-ply",
            "cylinder, one ply of axial courses",
            Some(("Fig. 11", 83.5, 44.6)),
            &m,
            Surface::Cylinder(r),
            vec![ply("axial", [0.0, 0.0, 3000.0, circ], 0.0)],
        ),
        part(
            "cylinder-2-plies",
            "cylinder, two non-intersecting plies",
            Some(("Fig. 12", 83.3, 45.1)),
            &m,
            Surface::Cylinder(r),
            vec![ply("left band", [0.0, 0.0, 1400.0, circ], 0.0), ply("right band", [1600.0, 0.0, 3000.0, circ], 0.0)],
        ),
        part(
            "cylinder-base-3-pads",
            "cylinder, base ply and three pad-ups of different angles",
            Some(("Fig. 13", f64::NAN, f64::NAN)),
            &m,
            Surface::Cylinder(r),
            vec![
                ply("base", [0.0, 0.0, 3000.0, circ], 0.0),
                ply("pad-up 0 deg", [2200.0, 1200.0, 2800.0, 1900.0], 0.0),
                ply("pad-up 90 deg", [200.0, 200.0, 600.0, 900.0], 90.0),
                ply("pad-up 45 deg", [1200.0, 1400.0, 1800.0, 2100.0], 45.0),
            ],
        ),
        // Parts in a cell (motion safety, docs/motion.md): the program's transits at the
        // 25 mm standoff run straight through the obstacles, so the input collides.
        DemoPart {
            obstacles: vec![
                obstacle("tool", plate_mesh([-100.0, 1300.0], [-100.0, 900.0], 0.0)),
                obstacle("stringer", box_mesh([575.0, -100.0, 0.0], [625.0, 900.0, 60.0])),
                obstacle("clamp", box_mesh([-70.0, 370.0, 0.0], [-15.0, 430.0, 50.0])),
            ],
            ..part(
                "planar-stringer",
                "planar tool with a 60 mm stringer across it and a clamp, two skins and two pad-ups",
                None,
                &g,
                Surface::Plane,
                vec![
                    ply("left skin", [0.0, 0.0, 550.0, 800.0], 0.0),
                    ply("right skin", [650.0, 0.0, 1200.0, 800.0], 0.0),
                    ply("pad-up right", [700.0, 300.0, 1000.0, 500.0], 90.0),
                    ply("pad-up left", [100.0, 300.0, 400.0, 500.0], 90.0),
                ],
            )
        },
        DemoPart {
            obstacles: vec![
                obstacle("mandrel", cylinder_mesh(r, -100.0, 3100.0, 256)),
                obstacle("flange", flange_mesh(380.0, 470.0, 1490.0, 1510.0, 256)),
            ],
            ..part(
                "cylinder-flange",
                "mandrel with a 70 mm flange between two bands",
                None,
                &m,
                Surface::Cylinder(r),
                vec![
                    ply("left band", [0.0, 0.0, 1400.0, circ], 0.0),
                    ply("right band", [1600.0, 0.0, 3000.0, circ], 0.0),
                ],
            )
        },
    ]
}

/// A large stacked panel for benchmarks: `plies` plies of about `courses` courses each, angles
/// cycling 0°, 45°, −45°, 90°, each a square of its own size and place, so that plies overlap
/// each other everywhere (the hard case for precedence).
pub fn stacked_panel(plies: usize, courses: usize) -> String {
    let w = TOW_WIDTH * TOWS as f64;
    let angles = [0.0, 45.0, -45.0, 90.0];
    let mut specs = Vec::with_capacity(plies);
    for p in 0..plies {
        let a: f64 = angles[p % 4];
        let th = a.to_radians();
        let side = courses as f64 * w / (th.sin().abs() + th.cos().abs()) - 1.0;
        // Deterministic jitter of the ply's place.
        let jx = ((p * 7919) % 401) as f64 - 200.0;
        let jy = ((p * 104_729) % 401) as f64 - 200.0;
        let (cx, cy) = (3000.0 + jx, 3000.0 + jy);
        specs.push(ply(
            &format!("stack {a} deg"),
            [cx - side / 2.0, cy - side / 2.0, cx + side / 2.0, cy + side / 2.0],
            a,
        ));
    }
    program("stacked panel", Surface::Plane, &specs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angled_courses_drop_tows_one_by_one() {
        let cs = ply_courses(&ply("p", [0.0, 0.0, 500.0, 300.0], 45.0));
        assert!(cs.len() > 5);
        // A middle course cuts its tows at several points.
        let c = &cs[cs.len() / 2];
        let cuts = c.events.iter().filter(|e| !e.1).count();
        assert!(cuts > 1, "{:?}", c.events);
        let restarted: u64 = c.events.iter().filter(|e| e.1).map(|e| e.2).fold(0, |a, b| a | b);
        let cut: u64 = c.events.iter().filter(|e| !e.1).map(|e| e.2).fold(0, |a, b| a | b);
        assert_eq!(restarted, cut);
    }

    #[test]
    fn zero_degree_ply_has_the_expected_course_count() {
        let cs = ply_courses(&ply("p", [0.0, 0.0, 1200.0, 800.0], 0.0));
        assert_eq!(cs.len(), (800.0f64 / 50.8).ceil() as usize);
        assert!(cs.iter().all(|c| c.events.len() == 2));
    }
}
