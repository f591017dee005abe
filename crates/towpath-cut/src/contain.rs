//! Containment: which closed contours each piece lies inside. A hole lies inside its part's
//! outer contour, a part inside the hole or sheet around it; each must be cut before the
//! contour around it, or it drops out (or moves) before it is cut.
//!
//! A piece lies inside a closed contour when its box lies in the contour's box, every tested
//! point of it (its flattened vertices, at most [`MAX_TESTED_POINTS`] spread along it) is inside
//! the contour or on its boundary (touching is allowed; "on" means within the tolerance), and it
//! is smaller: a closed piece must enclose less area, so two copies of one contour are not each
//! other's holes. The test is a crossing-number point-in-polygon with an explicit on-boundary
//! check first. Candidate contours come from an R-tree of boxes.

use rstar::{RTree, RTreeObject, AABB};

use crate::geom::{bbox_of, seg_dist2, signed_area, BBox, P2};
use crate::model::Drawing;

/// At most this many points of a piece are tested against a contour around it.
pub const MAX_TESTED_POINTS: usize = 64;

/// Where `p` lies relative to a closed polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Strictly inside.
    Inside,
    /// Within the tolerance of the boundary.
    On,
    /// Strictly outside.
    Outside,
}

/// Point in polygon by crossing number, with the boundary (within `tol`) reported as `On`.
pub fn side(p: P2, poly: &[P2], tol: f64) -> Side {
    let n = poly.len();
    let mut inside = false;
    let t2 = tol * tol;
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        if seg_dist2(p, a, b) <= t2 {
            return Side::On;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    if inside {
        Side::Inside
    } else {
        Side::Outside
    }
}

struct Boxed {
    piece: usize,
    bbox: BBox,
}

impl RTreeObject for Boxed {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        AABB::from_corners([self.bbox[0], self.bbox[1]], [self.bbox[2], self.bbox[3]])
    }
}

/// Flattened pieces, their boxes and areas, computed once.
pub struct Shapes {
    /// Flattened points of each piece (closed ones without the repeated start).
    pub points: Vec<Vec<P2>>,
    /// Box of each piece.
    pub bbox: Vec<BBox>,
    /// Absolute area of each closed piece (0 for open ones).
    pub area: Vec<f64>,
    /// Whether each piece is closed.
    pub closed: Vec<bool>,
}

impl Shapes {
    /// Flattens every piece within `tol`.
    pub fn new(drawing: &Drawing, tol: f64) -> Shapes {
        let mut points = Vec::with_capacity(drawing.pieces.len());
        let mut bbox = Vec::with_capacity(drawing.pieces.len());
        let mut area = Vec::with_capacity(drawing.pieces.len());
        let mut closed = Vec::with_capacity(drawing.pieces.len());
        for piece in &drawing.pieces {
            let mut pts = piece.path.flatten(tol);
            if piece.path.closed && pts.len() > 1 {
                pts.pop();
            }
            bbox.push(bbox_of(&pts));
            area.push(if piece.path.closed { signed_area(&pts).abs() } else { 0.0 });
            closed.push(piece.path.closed);
            points.push(pts);
        }
        Shapes { points, bbox, area, closed }
    }
}

/// For every piece, the closed pieces it lies inside (with `only_same_operation`, only those of
/// its own operation).
pub fn containers(drawing: &Drawing, shapes: &Shapes, tol: f64, only_same_operation: bool) -> Vec<Vec<usize>> {
    let n = drawing.pieces.len();
    let boxes: Vec<Boxed> = (0..n)
        .filter(|&i| shapes.closed[i] && shapes.points[i].len() >= 3 && shapes.area[i] > 0.0)
        .map(|i| Boxed { piece: i, bbox: shapes.bbox[i] })
        .collect();
    let mut out = vec![Vec::new(); n];
    if boxes.is_empty() {
        return out;
    }
    let tree = RTree::bulk_load(boxes);
    for (a, found) in out.iter_mut().enumerate() {
        let b = shapes.bbox[a];
        if !b[0].is_finite() {
            continue;
        }
        let pts = &shapes.points[a];
        let step = pts.len().div_ceil(MAX_TESTED_POINTS).max(1);
        let env = AABB::from_corners([b[0] + tol, b[1] + tol], [b[2] - tol, b[3] - tol]);
        let env = if b[2] - b[0] > 2.0 * tol && b[3] - b[1] > 2.0 * tol {
            env
        } else {
            AABB::from_corners([b[0], b[1]], [b[2], b[3]])
        };
        for c in tree.locate_in_envelope_intersecting(&env) {
            let k = c.piece;
            if k == a || (only_same_operation && drawing.pieces[k].operation != drawing.pieces[a].operation) {
                continue;
            }
            let cb = c.bbox;
            if b[0] < cb[0] - tol || b[1] < cb[1] - tol || b[2] > cb[2] + tol || b[3] > cb[3] + tol {
                continue;
            }
            if shapes.closed[a] && shapes.area[a] >= shapes.area[k] * (1.0 - 1e-9) {
                continue;
            }
            let poly = &shapes.points[k];
            let mut any_inside = false;
            let mut ok = true;
            for p in pts.iter().step_by(step) {
                match side(*p, poly, tol) {
                    Side::Outside => {
                        ok = false;
                        break;
                    }
                    Side::Inside => any_inside = true,
                    Side::On => {}
                }
            }
            if ok && (any_inside || shapes.closed[a]) {
                found.push(k);
            }
        }
        found.sort_unstable();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_of_square() {
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        assert_eq!(side([5.0, 5.0], &sq, 1e-9), Side::Inside);
        assert_eq!(side([10.0, 5.0], &sq, 1e-9), Side::On);
        assert_eq!(side([0.0, 0.0], &sq, 1e-9), Side::On);
        assert_eq!(side([11.0, 5.0], &sq, 1e-9), Side::Outside);
        assert_eq!(side([-1.0, 0.0], &sq, 1e-9), Side::Outside);
    }
}
