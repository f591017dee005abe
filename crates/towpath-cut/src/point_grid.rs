//! A uniform grid over 2-D points for k-nearest queries: the points of a drawing are spread over
//! the sheet, so cells of about two points each answer a query from a few rings of cells. On
//! 100,000 strokes it builds the stroke search's neighbour lists several times faster than an
//! R-tree's nearest-neighbour iterator.

use crate::geom::P2;

/// Points binned into square cells.
pub struct PointGrid {
    lo: P2,
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
    pts: Vec<P2>,
}

/// Most cells of a grid.
const MAX_CELLS: usize = 1 << 22;

impl PointGrid {
    /// A grid over `pts` (their ids are their indices).
    pub fn new(pts: Vec<P2>) -> PointGrid {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts.iter().filter(|p| p[0].is_finite() && p[1].is_finite()) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if lo[0] > hi[0] {
            lo = [0.0, 0.0];
            hi = [0.0, 0.0];
        }
        let (w, h) = ((hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9));
        let mut cell = (2.0 * w * h / pts.len().max(1) as f64).sqrt().max(w.max(h) / 2048.0).max(1e-9);
        while ((w / cell) as usize + 1).saturating_mul((h / cell) as usize + 1) > MAX_CELLS {
            cell *= 1.5;
        }
        let (nx, ny) = ((w / cell) as usize + 1, (h / cell) as usize + 1);
        let mut g = PointGrid { lo, cell, nx, ny, start: vec![0; nx * ny + 1], items: vec![0; pts.len()], pts };
        let idx: Vec<usize> = g.pts.iter().map(|&p| g.cell_index(p)).collect();
        for &c in &idx {
            g.start[c + 1] += 1;
        }
        for c in 0..nx * ny {
            g.start[c + 1] += g.start[c];
        }
        let mut fill = g.start.clone();
        for (i, &c) in idx.iter().enumerate() {
            g.items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        g
    }

    fn cell_xy(&self, p: P2) -> (usize, usize) {
        let f = |v: f64, lo: f64, n: usize| -> usize {
            let c = ((v - lo) / self.cell).floor();
            if c.is_nan() || c < 0.0 {
                0
            } else {
                (c as usize).min(n - 1)
            }
        };
        (f(p[0], self.lo[0], self.nx), f(p[1], self.lo[1], self.ny))
    }

    fn cell_index(&self, p: P2) -> usize {
        let (x, y) = self.cell_xy(p);
        y * self.nx + x
    }

    /// The `k` points nearest `q` as (squared distance, id), nearest first (ties by id).
    pub fn nearest(&self, q: P2, k: usize, out: &mut Vec<(f64, u32)>) {
        out.clear();
        if k == 0 || self.pts.is_empty() {
            return;
        }
        let (cx, cy) = self.cell_xy(q);
        let rings = self.nx.max(self.ny);
        for r in 0..=rings {
            let (x0, x1) = (cx as isize - r as isize, cx as isize + r as isize);
            let (y0, y1) = (cy as isize - r as isize, cy as isize + r as isize);
            let visit = |x: isize, y: isize, out: &mut Vec<(f64, u32)>| {
                if x < 0 || y < 0 || x >= self.nx as isize || y >= self.ny as isize {
                    return;
                }
                let c = y as usize * self.nx + x as usize;
                for &i in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                    let p = self.pts[i as usize];
                    out.push(((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]), i));
                }
            };
            for y in y0.max(0)..=y1.min(self.ny as isize - 1) {
                if y == y0 || y == y1 {
                    for x in x0.max(0)..=x1.min(self.nx as isize - 1) {
                        visit(x, y, out);
                    }
                } else {
                    // inside rows only the ring's two edge cells
                    visit(x0, y, out);
                    if x1 != x0 {
                        visit(x1, y, out);
                    }
                }
            }
            if out.len() >= k {
                if out.len() > 2 * k {
                    out.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    out.truncate(k);
                }
                let kth = out.iter().map(|e| e.0).fold(f64::NEG_INFINITY, f64::max);
                // every point outside the (2r+1)² block is at least this far from q
                let bx0 = self.lo[0] + x0 as f64 * self.cell;
                let bx1 = self.lo[0] + (x1 + 1) as f64 * self.cell;
                let by0 = self.lo[1] + y0 as f64 * self.cell;
                let by1 = self.lo[1] + (y1 + 1) as f64 * self.cell;
                let bound = (q[0] - bx0).min(bx1 - q[0]).min(q[1] - by0).min(by1 - q[1]);
                if bound > 0.0 && kth < bound * bound {
                    break;
                }
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.truncate(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_matches_brute_force() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        // uniform points plus a tight cluster and duplicates
        let mut pts: Vec<P2> = (0..3000).map(|_| [rnd() * 1000.0, rnd() * 300.0]).collect();
        pts.extend((0..500).map(|_| [500.0 + rnd(), 150.0 + rnd()]));
        pts.extend([[10.0, 10.0]; 5]);
        let g = PointGrid::new(pts.clone());
        let mut out = Vec::new();
        for qi in 0..200 {
            let q = if qi % 4 == 0 { [rnd() * 1400.0 - 200.0, rnd() * 500.0 - 100.0] } else { pts[qi * 17] };
            for k in [1, 7, 40] {
                g.nearest(q, k, &mut out);
                let mut all: Vec<(f64, u32)> = pts
                    .iter()
                    .enumerate()
                    .map(|(i, p)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2), i as u32))
                    .collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                all.truncate(k);
                assert_eq!(out, all, "query {q:?}, k {k}");
            }
        }
        let empty = PointGrid::new(Vec::new());
        empty.nearest([0.0, 0.0], 3, &mut out);
        assert!(out.is_empty());
    }
}
