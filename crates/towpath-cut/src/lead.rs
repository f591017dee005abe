//! Lead-ins: a short approach move ending at a closed contour's entry, on the scrap side, so
//! the pierce mark and the start of the kerf fall in the material that is thrown away: outside
//! an outer contour, inside a hole. A contour's side follows from its nesting depth (the number
//! of closed contours around it: even for a part's outer contour, odd for a hole) and its
//! drawn orientation.

use crate::geom::{signed_area, Path, Place, Seg, P2};

/// The lead-in's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeadKind {
    /// A straight line square to the contour.
    Line,
    /// A quarter circle ending tangent to the contour.
    Arc,
}

/// A lead-in of a length (a line's length, an arc's radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeadIn {
    /// Length of the line or radius of the arc, in drawing units.
    pub length: f64,
    /// Line or arc.
    pub kind: LeadKind,
}

/// The unit normal at a contour point pointing to its scrap side; `tangent` is the direction
/// of travel there, `poly` the contour flattened, `depth` its nesting depth.
pub fn scrap_normal(poly: &[P2], depth: usize, tangent: P2) -> P2 {
    let ccw = signed_area(poly) > 0.0;
    let right = [tangent[1], -tangent[0]];
    let outside = if ccw { right } else { [-right[0], -right[1]] };
    if depth % 2 == 0 {
        outside
    } else {
        [-outside[0], -outside[1]]
    }
}

/// The lead-in ending at `path`'s point `at`.
pub fn lead_in(path: &Path, at: Place, poly: &[P2], depth: usize, lead: &LeadIn, tangent: P2) -> Path {
    let e = path.point(at);
    let n = scrap_normal(poly, depth, tangent);
    let l = lead.length;
    match lead.kind {
        LeadKind::Line => Path { start: [e[0] + l * n[0], e[1] + l * n[1]], segs: vec![Seg::Line(e)], closed: false },
        LeadKind::Arc => {
            // Centre one radius off on the scrap side; start a quarter turn before the entry.
            let c = [e[0] + l * n[0], e[1] + l * n[1]];
            let s = [c[0] - l * tangent[0], c[1] - l * tangent[1]];
            // Signed quarter turn from (s - c) = -t to (e - c) = -n.
            let cross = tangent[0] * n[1] - tangent[1] * n[0];
            let bulge = if cross >= 0.0 {
                (std::f64::consts::FRAC_PI_2 / 4.0).tan()
            } else {
                -(std::f64::consts::FRAC_PI_2 / 4.0).tan()
            };
            Path { start: s, segs: vec![Seg::Arc { to: e, bulge }], closed: false }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contain::{side, Side};
    use crate::geom::seg_point;

    fn square(ccw: bool) -> (Path, Vec<P2>) {
        let mut pts = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        if !ccw {
            pts.reverse();
        }
        (Path::polyline(&pts, true).unwrap(), pts)
    }

    #[test]
    fn lead_ins_start_on_the_scrap_side() {
        for ccw in [true, false] {
            let (path, poly) = square(ccw);
            let at = Place { seg: 0, t: 0.5 };
            let p = path.point(at);
            let q = path.point(Place { seg: 0, t: 0.6 });
            let t = [(q[0] - p[0]) / crate::geom::dist(p, q), (q[1] - p[1]) / crate::geom::dist(p, q)];
            for kind in [LeadKind::Line, LeadKind::Arc] {
                let lead = LeadIn { length: 1.0, kind };
                let outer = lead_in(&path, at, &poly, 0, &lead, t);
                assert_eq!(side(outer.start, &poly, 1e-9), Side::Outside, "{kind:?} ccw={ccw}");
                assert!(crate::geom::dist(outer.end(), p) < 1e-12);
                let hole = lead_in(&path, at, &poly, 1, &lead, t);
                assert_eq!(side(hole.start, &poly, 1e-9), Side::Inside, "{kind:?} ccw={ccw}");
                if kind == LeadKind::Arc {
                    // Tangent at the end is the contour's direction of travel.
                    let a = seg_point(hole.start, &hole.segs[0], 0.999_999);
                    let d = [p[0] - a[0], p[1] - a[1]];
                    let dl = d[0].hypot(d[1]);
                    assert!((d[0] / dl - t[0]).abs() < 1e-3 && (d[1] / dl - t[1]).abs() < 1e-3);
                }
            }
        }
    }
}
