//! Contour-parallel toolpaths and toolpath cells (Castelino et al. 2003 §4.1, Fig. 3).
//!
//! For one tool and one feature, the feature's region (its boundary less its islands) is
//! offset inward by the tool radius, then again and again by the step-over, each time from the
//! original boundary (offset distances r, r + s, r + 2s, ...), until nothing is left; the
//! offsetting is done by `cavalier_contours` (exact lines and arcs). Each offset level is a set
//! of regions (an outer loop with the loops round the islands inside it). A region that splits
//! between levels ends its **toolpath cell**; each piece it splits into starts a new cell whose
//! parent is the one that split. A cell is machined as a whole once entered: its loops one after
//! the other, each entered at its point nearest the previous exit, joined by short feed moves.

use cavalier_contours::polyline::{PlineSource, PlineSourceMut, Polyline};
use cavalier_contours::shape_algorithms::{Shape, ShapeOffsetOptions};

use crate::contain::{side, Side};
use crate::geom::{dist, signed_area, Path, Place, Seg, P2};
use crate::mill::part::{Feature, Part};

/// One offset level's region: an outer loop (counter-clockwise) and the loops round islands
/// inside it (clockwise).
#[derive(Clone, Debug)]
pub struct Region {
    /// The outer loop.
    pub outer: Path,
    /// Loops round islands.
    pub holes: Vec<Path>,
}

/// A toolpath cell: concentric regions machined in one go.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Name: the feature's id and a letter per cell (as in the paper's Fig. 3: "3a", "3b").
    pub id: String,
    /// Feature index.
    pub feature: usize,
    /// Regions from the outermost level inward.
    pub levels: Vec<Region>,
    /// The cell it split off from (index in the tool's list).
    pub parent: Option<usize>,
}

/// Where the offsetting stops (levels per feature).
pub const MAX_LEVELS: usize = 10_000;

fn to_pline(p: &Path) -> Polyline<f64> {
    let mut pl = Polyline::new_closed();
    let mut prev = p.start;
    for s in &p.segs {
        let bulge = match s {
            Seg::Arc { bulge, .. } => *bulge,
            _ => 0.0,
        };
        if let Seg::Cubic { .. } = s {
            let mut f = Vec::new();
            crate::geom::seg_flatten(prev, s, 1e-3, &mut f);
            pl.add(prev[0], prev[1], 0.0);
            for q in f.iter().take(f.len().saturating_sub(1)) {
                pl.add(q[0], q[1], 0.0);
            }
        } else {
            pl.add(prev[0], prev[1], bulge);
        }
        prev = s.end();
    }
    pl
}

fn from_pline(pl: &Polyline<f64>) -> Option<Path> {
    let n = pl.vertex_count();
    if n < 2 {
        return None;
    }
    let v: Vec<_> = pl.iter_vertexes().collect();
    let start = [v[0].x, v[0].y];
    let mut segs = Vec::with_capacity(n);
    for i in 0..n {
        let to = if i + 1 < n { [v[i + 1].x, v[i + 1].y] } else { start };
        let b = v[i].bulge;
        segs.push(if b == 0.0 { Seg::Line(to) } else { Seg::Arc { to, bulge: b } });
    }
    Some(Path { start, segs, closed: true })
}

fn flat(p: &Path) -> Vec<P2> {
    let mut f = p.flatten(1e-3);
    f.pop();
    f
}

fn inside(p: P2, loop_: &Path) -> bool {
    side(p, &flat(loop_), 1e-9) == Side::Inside
}

/// The regions of one offset level.
fn regions(shape: &Shape<f64>) -> Vec<Region> {
    let mut out: Vec<Region> = shape
        .ccw_plines
        .iter()
        .filter_map(|p| from_pline(&p.polyline))
        .map(|outer| Region { outer, holes: Vec::new() })
        .collect();
    let areas: Vec<f64> = out.iter().map(|r| signed_area(&flat(&r.outer)).abs()).collect();
    for h in &shape.cw_plines {
        let Some(hole) = from_pline(&h.polyline) else { continue };
        let q = hole.start;
        let owner = (0..out.len()).filter(|&k| inside(q, &out[k].outer)).min_by(|&a, &b| areas[a].total_cmp(&areas[b]));
        if let Some(k) = owner {
            out[k].holes.push(hole);
        }
    }
    out
}

/// The offset levels of a feature for a tool: regions per level.
pub fn offset_levels(feature: &Feature, radius: f64, step_over: f64) -> Vec<Vec<Region>> {
    let mut plines = vec![to_pline(&feature.boundary)];
    plines.extend(feature.islands.iter().map(to_pline));
    let shape = Shape::from_plines(plines);
    let mut levels = Vec::new();
    for k in 0..MAX_LEVELS {
        let d = radius + step_over * k as f64;
        let off = shape.parallel_offset(d, ShapeOffsetOptions::default());
        let rs = regions(&off);
        if rs.is_empty() {
            break;
        }
        levels.push(rs);
    }
    levels
}

/// The toolpath cells of one tool over the features it machines, features in the tool's order.
pub fn cells_for_tool(part: &Part, tool: usize) -> Vec<Cell> {
    let t = &part.tools[tool];
    let mut cells: Vec<Cell> = Vec::new();
    for &f in &t.features {
        let feature = &part.features[f];
        let levels = offset_levels(feature, t.radius, t.step_over);
        let first_cell = cells.len();
        // cell index of each region of the previous level
        let mut prev_cell: Vec<usize> = Vec::new();
        let mut prev_level: Vec<Region> = Vec::new();
        for level in levels {
            let mut this_cell = Vec::with_capacity(level.len());
            // Parent region of each region at this level.
            let parents: Vec<Option<usize>> = level
                .iter()
                .map(|r| {
                    let q = r.outer.start;
                    (0..prev_level.len()).find(|&k| inside(q, &prev_level[k].outer))
                })
                .collect();
            for (i, r) in level.iter().enumerate() {
                let children = |p: usize| parents.iter().filter(|x| **x == Some(p)).count();
                let cell = match parents[i] {
                    Some(p) if children(p) == 1 => {
                        let c = prev_cell[p];
                        cells[c].levels.push(r.clone());
                        c
                    }
                    parent => {
                        let n = cells.len() - first_cell;
                        cells.push(Cell {
                            id: format!("{}{}", feature.id, letter(n)),
                            feature: f,
                            levels: vec![r.clone()],
                            parent: parent.map(|p| prev_cell[p]),
                        });
                        cells.len() - 1
                    }
                };
                this_cell.push(cell);
            }
            prev_cell = this_cell;
            prev_level = level;
        }
    }
    cells
}

fn letter(n: usize) -> String {
    let mut s = String::new();
    let mut n = n;
    loop {
        s.insert(0, (b'a' + (n % 26) as u8) as char);
        if n < 26 {
            break;
        }
        n = n / 26 - 1;
    }
    s
}

/// A cell machined from one entry: its moves in order (loops and the feed links between them).
#[derive(Clone, Debug)]
pub struct CellPath {
    /// Loops and links in machining order.
    pub moves: Vec<Path>,
}

impl CellPath {
    /// Where the tool plunges.
    pub fn entry(&self) -> P2 {
        self.moves.first().map_or([0.0, 0.0], |m| m.start)
    }
    /// Where it retracts.
    pub fn exit(&self) -> P2 {
        self.moves.last().map_or([0.0, 0.0], |m| m.end())
    }
    /// Cutting length (loops and links).
    pub fn length(&self) -> f64 {
        self.moves.iter().map(|m| m.length()).sum()
    }
}

/// The cell machined from `entry` on its outermost loop: outside-in (loop after loop inward),
/// or inside-out (the same loops and links in reverse order, each loop still in its own
/// direction), so the entry fixes the exit (the paper's Fig. 4).
pub fn cell_path(cell: &Cell, entry: Place, inside_out: bool) -> CellPath {
    let mut moves = Vec::new();
    let Some(first) = cell.levels.first() else { return CellPath { moves } };
    let mut cur = first.outer.point(entry);
    for (k, region) in cell.levels.iter().enumerate() {
        let mut loops: Vec<&Path> = vec![&region.outer];
        let mut holes: Vec<&Path> = region.holes.iter().collect();
        // Islands nearest first, each from the exit of the one before.
        let mut at = cur;
        let mut ordered = Vec::new();
        while !holes.is_empty() {
            let (i, _) = holes
                .iter()
                .enumerate()
                .map(|(i, h)| (i, dist(at, h.point(h.closest_place(at, 1e-3)))))
                .fold((0, f64::INFINITY), |b, x| if x.1 < b.1 { x } else { b });
            let h = holes.remove(i);
            at = h.point(h.closest_place(at, 1e-3));
            ordered.push(h);
        }
        loops.extend(ordered);
        for (j, lp) in loops.into_iter().enumerate() {
            let place = if k == 0 && j == 0 { entry } else { lp.closest_place(cur, 1e-3) };
            let started = lp.started_at(place);
            if dist(cur, started.start) > 0.0 {
                moves.push(Path { start: cur, segs: vec![Seg::Line(started.start)], closed: false });
            }
            cur = started.end();
            moves.push(started);
        }
    }
    if inside_out {
        moves.reverse();
        for m in moves.iter_mut() {
            if !m.closed {
                *m = m.reversed();
            }
        }
    }
    CellPath { moves }
}
