//! The independent verifier of an ordering. It shares no code with the ordering beyond the
//! geometry primitives: it checks that every input piece is done exactly once, with the same
//! geometry (an open stroke as drawn or, where allowed, backwards; a closed contour in its drawn
//! direction, started anywhere along it), that operations come in their order, that explicit
//! hierarchy pairs hold, and that no piece comes after a closed contour it lies inside, with its
//! own containment test (winding number over every flattened vertex of the inner piece) rather
//! than the optimizer's.

use crate::geom::{bbox_of, dist, seg_dist2, signed_area, Path, P2};
use crate::model::{travel, Drawing, Placement};

/// What the verifier found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Verification {
    /// Pieces checked.
    pub pieces: usize,
    /// Input pieces not done (ids).
    pub missing: Vec<String>,
    /// Input pieces done more than once (ids).
    pub repeated: Vec<String>,
    /// Pieces whose geometry differs from the input, with the reason.
    pub geometry: Vec<String>,
    /// Precedence pairs broken (containment, hierarchy, operation order), described.
    pub precedence: Vec<String>,
    /// Travel of the ordering (from the start, if any).
    pub travel: f64,
}

impl Verification {
    /// True when nothing is wrong.
    pub fn ok(&self) -> bool {
        self.missing.is_empty() && self.repeated.is_empty() && self.geometry.is_empty() && self.precedence.is_empty()
    }

    /// A one-paragraph description of what is wrong (empty when ok).
    pub fn problems(&self) -> String {
        let mut out = Vec::new();
        let mut list = |what: &str, v: &[String]| {
            if !v.is_empty() {
                let shown: Vec<&str> = v.iter().take(5).map(|s| s.as_str()).collect();
                out.push(format!("{} {what}: {}{}", v.len(), shown.join("; "), if v.len() > 5 { "; …" } else { "" }));
            }
        };
        list("pieces missing", &self.missing);
        list("pieces repeated", &self.repeated);
        list("pieces changed", &self.geometry);
        list("precedence violations", &self.precedence);
        out.join("; ")
    }
}

/// What the verifier needs to know of the rules.
#[derive(Clone, Copy, Debug)]
pub struct Rules {
    /// Pieces inside closed contours first.
    pub inner_first: bool,
    /// Operations may mix (else in their listed order, and containment only within one).
    pub mix_operations: bool,
    /// Open strokes may be reversed.
    pub reverse: bool,
    /// Geometric tolerance (flattening; "on the boundary").
    pub tolerance: f64,
    /// Where the tool starts.
    pub start: Option<P2>,
}

fn seg_dist(p: P2, a: P2, b: P2) -> f64 {
    seg_dist2(p, a, b).sqrt()
}

/// Every `step`-th point of `a` (at most 256 of them, the last one too): the points of `a`
/// whose distance to the other path is checked.
fn samples(a: &[P2]) -> impl Iterator<Item = &P2> {
    let step = a.len().div_ceil(256).max(1);
    a.iter().step_by(step)
}

/// Largest distance from a sample of `a`'s points to the polyline `b`.
fn one_sided(a: &[P2], b: &[P2]) -> f64 {
    let mut worst: f64 = 0.0;
    for p in samples(a) {
        let mut best = f64::INFINITY;
        if b.len() == 1 {
            best = seg_dist(*p, b[0], b[0]);
        }
        for w in b.windows(2) {
            best = best.min(seg_dist(*p, w[0], w[1]));
        }
        worst = worst.max(best);
    }
    worst
}

/// Whether `one_sided(a, b) <= eps`, found without pricing every segment: each sample needs
/// only one segment of `b` within `eps`, and the search for it starts at the segment that held
/// the previous sample and widens both ways (consecutive samples of the same geometry lie on
/// nearby segments, whichever way and from wherever the path was drawn). O(samples) when the
/// geometry is the same; `one_sided` then prices the failure.
fn within(a: &[P2], b: &[P2], eps: f64) -> bool {
    if b.len() == 1 {
        return samples(a).all(|p| seg_dist(*p, b[0], b[0]) <= eps);
    }
    let m = b.len() - 1;
    let mut hint = 0usize;
    'points: for p in samples(a) {
        for k in 0..m {
            // hint, hint + 1, hint - 1, hint + 2, … around the polyline's segments
            let off = k.div_ceil(2) % m;
            let s = if k % 2 == 1 { (hint + off) % m } else { (hint + m - off) % m };
            if seg_dist(*p, b[s], b[s + 1]) <= eps {
                hint = s;
                continue 'points;
            }
        }
        return false;
    }
    true
}

fn same_geometry(orig: &Path, done: &Path, reversed: bool, may_reverse: bool, tol: f64) -> Result<(), String> {
    if orig.closed != done.closed {
        return Err("open/closed changed".into());
    }
    let (lo, ld) = (orig.length(), done.length());
    let scale = 1.0 + lo.abs();
    let eps = 4.0 * tol + 1e-9 * scale;
    if (lo - ld).abs() > 1e-6 * scale + tol {
        return Err(format!("length {ld} instead of {lo}"));
    }
    let fo = orig.flatten(tol);
    let fd = done.flatten(tol);
    if !within(&fd, &fo, eps) || !within(&fo, &fd, eps) {
        let h = one_sided(&fd, &fo).max(one_sided(&fo, &fd));
        return Err(format!("lies up to {h:.3e} off the original"));
    }
    if orig.closed {
        if dist(done.start, done.end()) > eps {
            return Err("closed contour does not end where it starts".into());
        }
        let (ao, ad) = (signed_area(&fo), signed_area(&fd));
        if ao.abs() > eps * eps && ao.signum() != ad.signum() {
            return Err("closed contour runs the other way".into());
        }
    } else {
        let fwd = dist(done.start, orig.start) <= eps && dist(done.end(), orig.end()) <= eps;
        let back = dist(done.start, orig.end()) <= eps && dist(done.end(), orig.start) <= eps;
        if reversed && !may_reverse {
            return Err("reversed, which is not allowed".into());
        }
        let consistent = if reversed { back } else { fwd };
        if !consistent {
            return Err("ends do not match the original".into());
        }
    }
    Ok(())
}

/// Winding number of `poly` around `p`, or `None` when `p` is on the boundary (within `tol`).
fn winding(p: P2, poly: &[P2], tol: f64) -> Option<i32> {
    let n = poly.len();
    let mut w = 0;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if seg_dist(p, a, b) <= tol {
            return None;
        }
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
        if a[1] <= p[1] {
            if b[1] > p[1] && cross > 0.0 {
                w += 1;
            }
        } else if b[1] <= p[1] && cross < 0.0 {
            w -= 1;
        }
    }
    Some(w)
}

/// Verifies `done` (placements in order) against the input drawing.
pub fn verify(drawing: &Drawing, done: &[Placement], rules: &Rules) -> Verification {
    let n = drawing.pieces.len();
    let mut v = Verification { pieces: done.len(), travel: travel(rules.start, done), ..Verification::default() };
    let mut pos = vec![usize::MAX; n];
    for (k, p) in done.iter().enumerate() {
        let Some(piece) = drawing.pieces.get(p.piece) else {
            v.geometry.push(format!("placement {k} names piece {} of {n}", p.piece));
            continue;
        };
        if pos[p.piece] != usize::MAX {
            v.repeated.push(piece.id.clone());
            continue;
        }
        pos[p.piece] = k;
        if piece.fixed && p.path != piece.path {
            v.geometry.push(format!("{}: must be done as drawn", piece.id));
        }
        if let Err(e) =
            same_geometry(&piece.path, &p.path, p.reversed, rules.reverse && piece.reversible, rules.tolerance)
        {
            v.geometry.push(format!("{}: {e}", piece.id));
        }
        if let Some(l) = &p.lead_in {
            if dist(l.end(), p.path.start) > 1e-9 * (1.0 + p.path.length()) {
                v.geometry.push(format!("{}: lead-in does not end at the entry", piece.id));
            }
        }
    }
    for (i, piece) in drawing.pieces.iter().enumerate() {
        if pos[i] == usize::MAX {
            v.missing.push(piece.id.clone());
        }
    }
    let name = |i: usize| drawing.pieces[i].id.clone();
    // Operations in order.
    if !rules.mix_operations {
        let mut last = 0;
        for p in done {
            let op = drawing.pieces.get(p.piece).map_or(0, |x| x.operation);
            if op < last {
                v.precedence.push(format!("{} (operation {}) after operation {}", name(p.piece), op, last));
            }
            last = last.max(op);
        }
    }
    for &(a, b) in &drawing.hierarchy {
        if a < n && b < n && pos[a] != usize::MAX && pos[b] != usize::MAX && pos[a] > pos[b] {
            v.precedence.push(format!("{} must come before {}", name(a), name(b)));
        }
    }
    if rules.inner_first {
        let tol = rules.tolerance;
        let flat: Vec<Vec<P2>> = drawing
            .pieces
            .iter()
            .map(|p| {
                let mut f = p.path.flatten(tol);
                if p.path.closed && f.len() > 1 {
                    f.pop();
                }
                f
            })
            .collect();
        let boxes: Vec<[f64; 4]> = flat.iter().map(|f| bbox_of(f)).collect();
        let areas: Vec<f64> = drawing
            .pieces
            .iter()
            .zip(&flat)
            .map(|(p, f)| if p.path.closed { signed_area(f).abs() } else { 0.0 })
            .collect();
        let mut by_x: Vec<usize> = (0..n).filter(|&i| boxes[i][0].is_finite()).collect();
        by_x.sort_by(|&a, &b| boxes[a][0].total_cmp(&boxes[b][0]));
        let xs: Vec<f64> = by_x.iter().map(|&i| boxes[i][0]).collect();
        for c in 0..n {
            if !drawing.pieces[c].path.closed || flat[c].len() < 3 || areas[c] <= 0.0 {
                continue;
            }
            let cb = boxes[c];
            let lo = xs.partition_point(|&x| x < cb[0] - tol);
            for &a in &by_x[lo..] {
                if boxes[a][0] > cb[2] + tol {
                    break;
                }
                let ab = boxes[a];
                if a == c || ab[1] < cb[1] - tol || ab[2] > cb[2] + tol || ab[3] > cb[3] + tol {
                    continue;
                }
                if !rules.mix_operations && drawing.pieces[a].operation != drawing.pieces[c].operation {
                    continue;
                }
                if drawing.pieces[a].path.closed && areas[a] >= areas[c] * (1.0 - 1e-9) {
                    continue;
                }
                let mut strictly = false;
                let inside = flat[a].iter().all(|&p| match winding(p, &flat[c], tol) {
                    None => true,
                    Some(0) => false,
                    Some(_) => {
                        strictly = true;
                        true
                    }
                });
                if inside
                    && (strictly || drawing.pieces[a].path.closed)
                    && pos[a] != usize::MAX
                    && pos[c] != usize::MAX
                    && pos[a] > pos[c]
                {
                    v.precedence.push(format!("{} lies inside {} but comes after it", name(a), name(c)));
                }
            }
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy closed polyline of `n` points.
    fn loop_points(n: usize) -> Vec<P2> {
        (0..=n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
                let r = 50.0 + 5.0 * (7.0 * a).sin();
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn within_agrees_with_the_full_distance() {
        let a = loop_points(700);
        // the same loop reversed and started elsewhere
        let mut b: Vec<P2> = a[..700].to_vec();
        b.rotate_left(333);
        b.reverse();
        b.push(b[0]);
        assert!(within(&a, &b, 1e-9) && within(&b, &a, 1e-9));
        assert!(one_sided(&a, &b) <= 1e-9);
        // moved by 0.3: within 0.5, not within 0.2, as the full scan says
        let moved: Vec<P2> = b.iter().map(|p| [p[0] + 0.3, p[1]]).collect();
        let h = one_sided(&a, &moved);
        assert!(h > 0.2 && h <= 0.3 + 1e-9, "{h}");
        for eps in [0.1, 0.2, 0.29, 0.31, 0.5] {
            assert_eq!(within(&a, &moved, eps), h <= eps, "eps {eps}");
        }
        // one point of a far off: found however far from the hint
        let mut bent = a.clone();
        bent[402] = [0.0, 0.0]; // a sampled point (every third)
        let h = one_sided(&bent, &a);
        assert!(h > 10.0);
        assert!(!within(&bent, &a, 1.0) && within(&bent, &a, h + 1e-9));
        // a single point
        assert!(within(&[[1.0, 1.0]], &[[1.0, 1.5]], 0.5) && !within(&[[1.0, 1.0]], &[[1.0, 1.5]], 0.4));
    }
}
