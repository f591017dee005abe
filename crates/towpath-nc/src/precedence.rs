//! Precedence between courses, from their footprints.
//!
//! - The **course rule** (the default): a course comes after every course of an earlier ply
//!   whose footprint it overlaps. [`course_precedence`] returns a small set of edges whose
//!   transitive closure is exactly that relation: a grid of cells keeps, per cell, the courses
//!   laid over it, latest ply on top; a course that covers a whole cell hides the courses
//!   below it (they overlap it, so they come before it already), and candidates are resolved
//!   latest ply first, skipping those already implied.
//! - The **precedence network of Doherty et al. (2022)** ([`precedence_sets`]): consecutive plies that do not
//!   intersect are joined into one precedence set; each set comes after the one before.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use rayon::prelude::*;

/// A small multiplicative hasher for grid keys (the default SipHash dominates otherwise).
#[derive(Default, Clone, Copy)]
pub(crate) struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// A hash map keyed by grid cells.
pub(crate) type CellMap<V> = HashMap<(i64, i64), V, BuildHasherDefault<CellHasher>>;

use crate::error::NcError;
use crate::footprint::{Footprints, Frame, Quad};

/// A uniform grid over the footprint frame (periodic in its second coordinate if the frame is).
#[derive(Clone, Debug)]
pub(crate) struct Grid {
    size: f64,
    /// Cell height and number of rows for a periodic frame.
    rows: Option<(f64, i64)>,
    /// Cell index bounds of all footprints: (i0, j0, columns, rows).
    bounds: (i64, i64, i64, i64),
}

/// Per-cell values: a dense array over the grid's bounds when it is not too large, else a map.
pub(crate) struct CellStore<V> {
    bounds: (i64, i64, i64, i64),
    dense: Vec<V>,
    sparse: CellMap<V>,
}

/// Largest dense cell store, in cells.
const MAX_DENSE_CELLS: i64 = 2_000_000;

/// Most (rectangle, cell) incidences a grid may hold: the cells grow until the footprints' pieces
/// touch no more than this many (so its memory stays bounded whatever the widths and lengths).
pub const MAX_CELL_HITS: u64 = 8_000_000;

/// Most grid entries a precedence search may visit before giving up (seconds of work): about 30
/// times what the benchmark's 100-ply, 10,000-course panel needs for course precedence
/// (3.4·10⁷; the demo parts need at most 3·10⁴), so only footprints piled up by the thousand
/// over one place reach it.
pub const MAX_VISITS: u64 = 1_000_000_000;

/// Counts the grid entries a search visits, across threads, and says when to stop.
pub(crate) struct Budget {
    used: std::sync::atomic::AtomicU64,
    limit: u64,
}

impl Budget {
    pub(crate) fn new(limit: u64) -> Self {
        Budget { used: std::sync::atomic::AtomicU64::new(0), limit }
    }

    /// Adds `n` visits; false once the limit is passed.
    #[inline]
    pub(crate) fn spend(&self, n: u64) -> bool {
        self.used.fetch_add(n, std::sync::atomic::Ordering::Relaxed).saturating_add(n) <= self.limit
    }

    pub(crate) fn exceeded(&self) -> bool {
        self.used.load(std::sync::atomic::Ordering::Relaxed) > self.limit
    }

    /// The error for a search that ran out of budget.
    pub(crate) fn error(&self, what: &str) -> NcError {
        NcError::WorkLimit {
            what: what.into(),
            limit: self.limit,
            unit: "footprint comparisons".into(),
            advice: "the courses' footprints are piled up far more densely than on any real part (thousands of \
                     courses over the same place); check the program and the course width, or lay ply by ply, \
                     which needs no footprints"
                .into(),
        }
    }
}

impl<V: Default> CellStore<V> {
    pub fn new(grid: &Grid) -> Self {
        let (_, _, nx, ny) = grid.bounds;
        let cells = nx.saturating_mul(ny);
        let dense = if cells > 0 && cells <= MAX_DENSE_CELLS {
            std::iter::repeat_with(V::default).take(cells as usize).collect()
        } else {
            Vec::new()
        };
        CellStore { bounds: grid.bounds, dense, sparse: CellMap::default() }
    }

    #[inline]
    fn index(&self, key: (i64, i64)) -> Option<usize> {
        let (i0, j0, nx, ny) = self.bounds;
        let (i, j) = (key.0 - i0, key.1 - j0);
        (!self.dense.is_empty() && i >= 0 && j >= 0 && i < nx && j < ny).then(|| (i * ny + j) as usize)
    }

    #[inline]
    pub fn get(&self, key: (i64, i64)) -> Option<&V> {
        match self.index(key) {
            Some(k) => self.dense.get(k),
            None => self.sparse.get(&key),
        }
    }

    #[inline]
    pub fn get_mut(&mut self, key: (i64, i64)) -> &mut V {
        match self.index(key) {
            Some(k) => &mut self.dense[k],
            None => self.sparse.entry(key).or_default(),
        }
    }
}

/// One cell a rectangle touches with positive area.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellHit {
    pub key: (i64, i64),
    /// The rectangle covers the whole cell.
    pub full: bool,
}

impl Grid {
    /// A grid with cells `factor` times the median rectangle width, or larger when the
    /// footprints would touch more than `max_hits` cells in all.
    pub fn new(fps: &Footprints, factor: f64, max_hits: u64) -> Self {
        let mut widths: Vec<f64> = fps.courses.iter().flat_map(|f| f.quads.iter().map(|q| 2.0 * q.hw)).collect();
        let mut size = if widths.is_empty() {
            1.0
        } else {
            let mid = widths.len() / 2;
            let (_, m, _) = widths.select_nth_unstable_by(mid, f64::total_cmp);
            (*m * factor).max(1e-3)
        };
        let rows_for = |size: f64| {
            fps.frame.period().map(|p| {
                let n = (p / size).ceil().max(1.0);
                (p / n, n as i64)
            })
        };
        // Cells touched by every rectangle's bounds (at least those `cells` reports).
        let hits = |size: f64| -> u64 {
            let h = rows_for(size).map_or(size, |r| r.0);
            let mut total = 0u64;
            for q in fps.courses.iter().flat_map(|f| f.quads.iter()) {
                let (a, b) = q.bounds();
                let nx = ((b[0] / size).floor() - (a[0] / size).floor() + 1.0).max(1.0);
                let ny = ((b[1] / h).floor() - (a[1] / h).floor() + 1.0).max(1.0);
                total = total.saturating_add((nx * ny).min(u64::MAX as f64 / 4.0) as u64);
                if total > max_hits {
                    break;
                }
            }
            total
        };
        while hits(size) > max_hits && size.is_finite() {
            size *= 2.0;
        }
        let rows = rows_for(size);
        let h = rows.map_or(size, |r| r.0);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in fps.courses.iter().flat_map(|f| f.quads.iter()) {
            let (a, b) = q.bounds();
            for k in 0..2 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        let bounds = if lo[0].is_finite() && hi[0].is_finite() {
            let (i0, i1) = ((lo[0] / size).floor() as i64, (hi[0] / size).floor() as i64);
            let (j0, j1) = match rows {
                Some((_, n)) => (0, n - 1),
                None => ((lo[1] / h).floor() as i64, (hi[1] / h).floor() as i64),
            };
            (i0, j0, i1 - i0 + 1, j1 - j0 + 1)
        } else {
            (0, 0, 0, 0)
        };
        Grid { size, rows, bounds }
    }

    /// The cells a rectangle overlaps with positive area; `whole` is the larger rectangle it is
    /// a piece of, which decides whether a cell is fully covered.
    pub fn cells(&self, q: &Quad, whole: &Quad, out: &mut Vec<CellHit>) {
        out.clear();
        let (lo, hi) = q.bounds();
        let h = self.rows.map_or(self.size, |r| r.0);
        let (i0, i1) = ((lo[0] / self.size).floor() as i64, (hi[0] / self.size).floor() as i64);
        let (j0, j1) = ((lo[1] / h).floor() as i64, (hi[1] / h).floor() as i64);
        // `Grid::new` sized the cells so that every rectangle touches few of them.
        for i in i0..=i1 {
            for j in j0..=j1 {
                let cell = Quad {
                    c: [(i as f64 + 0.5) * self.size, (j as f64 + 0.5) * h],
                    u: [1.0, 0.0],
                    hl: self.size / 2.0,
                    hw: h / 2.0,
                };
                if !q.overlaps(&cell) {
                    continue;
                }
                let full = cell_corners(&cell).iter().all(|p| whole.contains(*p));
                let key = match self.rows {
                    Some((_, n)) => (i, j.rem_euclid(n)),
                    None => (i, j),
                };
                out.push(CellHit { key, full });
            }
        }
    }
}

fn cell_corners(c: &Quad) -> [[f64; 2]; 4] {
    [
        [c.c[0] - c.hl, c.c[1] - c.hw],
        [c.c[0] + c.hl, c.c[1] - c.hw],
        [c.c[0] + c.hl, c.c[1] + c.hw],
        [c.c[0] - c.hl, c.c[1] + c.hw],
    ]
}

#[derive(Clone, Copy, Debug)]
struct Entry {
    course: u32,
    quad: u32,
    ply: u32,
    full: bool,
}

/// Two rectangles of (possibly) different unwrapped copies overlap.
pub(crate) fn quads_overlap(frame: &Frame, a: &Quad, b: &Quad) -> bool {
    match frame.period() {
        None => a.overlaps(b),
        Some(_) => a.overlaps(&b.shifted(frame.unwrap_near(b.c[1], a.c[1]) - b.c[1])),
    }
}

/// A set of course indices, as bits.
#[derive(Clone, Debug, Default)]
struct Bits(Vec<u64>);

impl Bits {
    fn new(n: usize) -> Self {
        Bits(vec![0; n.div_ceil(64)])
    }
    #[inline]
    fn has(&self, i: usize) -> bool {
        self.0.get(i / 64).is_some_and(|w| w >> (i % 64) & 1 == 1)
    }
    #[inline]
    fn set(&mut self, i: usize) {
        if let Some(w) = self.0.get_mut(i / 64) {
            *w |= 1 << (i % 64);
        }
    }
    fn or(&mut self, o: &Bits) {
        for (a, b) in self.0.iter_mut().zip(&o.0) {
            *a |= b;
        }
    }
}

const UNKNOWN: u8 = 0;
const OVERLAP: u8 = 1;

/// Per-thread scratch space of the candidate search.
struct Scratch {
    stamp: Vec<u32>,
    state: Vec<u8>,
    list: Vec<u32>,
    hits: Vec<CellHit>,
}

/// Above this many courses the implied-edge bookkeeping (n² bits, 112 MB at the limit) is
/// skipped; the result is still correct, with more edges.
const MAX_BITSET_COURSES: usize = 30_000;

/// Course-level precedence edges `(before, after)`: `after` overlaps `before`, which belongs to
/// an earlier ply. `plies[p]` lists the courses of ply p. The transitive closure of the edges
/// equals the full relation; most implied edges are left out. Refused
/// ([`NcError::WorkLimit`]) when the footprints are piled up so densely that the search would
/// visit more than [`MAX_VISITS`] grid entries.
pub fn course_precedence(fps: &Footprints, plies: &[Vec<usize>]) -> Result<Vec<(usize, usize)>, NcError> {
    course_precedence_within(fps, plies, Limits::DEFAULT)
}

/// The work and memory bounds of the precedence searches.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limits {
    /// Grid entries a search may visit.
    pub visits: u64,
    /// (rectangle, cell) incidences a grid may hold.
    pub hits: u64,
}

impl Limits {
    pub(crate) const DEFAULT: Limits = Limits { visits: MAX_VISITS, hits: MAX_CELL_HITS };
}

/// [`course_precedence`] under `limits`.
pub(crate) fn course_precedence_within(
    fps: &Footprints,
    plies: &[Vec<usize>],
    limits: Limits,
) -> Result<Vec<(usize, usize)>, NcError> {
    let budget = Budget::new(limits.visits);
    let n = fps.courses.len();
    let mut ply_of = vec![0u32; n];
    for (p, cs) in plies.iter().enumerate() {
        for &c in cs {
            ply_of[c] = p as u32;
        }
    }
    let grid = Grid::new(fps, 0.5, limits.hits);
    let frame = fps.frame;
    let use_bits = n <= MAX_BITSET_COURSES;
    let mut anc: Vec<Bits> = if use_bits { (0..n).map(|_| Bits::default()).collect() } else { Vec::new() };
    let mut cells: CellStore<Vec<Entry>> = CellStore::new(&grid);
    let mut edges = Vec::new();
    for (p, courses) in plies.iter().enumerate() {
        // Every course of this ply against the grid of earlier plies (read-only): in parallel.
        let results: Vec<(usize, Vec<usize>, Bits)> = courses
            .par_iter()
            .map_init(
                || Scratch { stamp: vec![u32::MAX; n], state: vec![0; n], list: Vec::new(), hits: Vec::new() },
                |sc, &c| {
                    let fc = &fps.courses[c];
                    let me = c as u32;
                    sc.list.clear();
                    let mut spent = 0u64;
                    for (qi, q) in fc.quads.iter().enumerate() {
                        grid.cells(q, &fc.moves[fc.move_of[qi] as usize], &mut sc.hits);
                        for h in &sc.hits {
                            let Some(stack) = cells.get(h.key) else { continue };
                            spent += stack.len() as u64 + 1;
                            if spent >= 1 << 16 && !budget.spend(std::mem::take(&mut spent)) {
                                return (c, Vec::new(), Bits::default());
                            }
                            let mut stop: Option<u32> = None;
                            for e in stack.iter().rev() {
                                let pb = e.ply;
                                if stop.is_some_and(|sp| pb < sp) {
                                    break;
                                }
                                let b = e.course as usize;
                                if sc.stamp[b] != me {
                                    sc.stamp[b] = me;
                                    sc.state[b] = UNKNOWN;
                                    sc.list.push(e.course);
                                }
                                if e.full {
                                    // It covers the whole cell, and this course covers part of
                                    // the cell: they overlap; everything below is implied by it.
                                    sc.state[b] = OVERLAP;
                                    stop = Some(pb);
                                } else if sc.state[b] == UNKNOWN
                                    && quads_overlap(&frame, q, &fps.courses[b].quads[e.quad as usize])
                                {
                                    sc.state[b] = OVERLAP;
                                }
                            }
                        }
                    }
                    budget.spend(spent);
                    let mut list: Vec<u32> =
                        sc.list.iter().copied().filter(|&b| sc.state[b as usize] == OVERLAP).collect();
                    list.sort_unstable_by_key(|&b| (std::cmp::Reverse(ply_of[b as usize]), b));
                    let mut mine = if use_bits { Bits::new(n) } else { Bits::default() };
                    let mut preds = Vec::new();
                    for b in list {
                        let bi = b as usize;
                        if use_bits && mine.has(bi) {
                            continue;
                        }
                        preds.push(bi);
                        if use_bits {
                            mine.or(&anc[bi]);
                            mine.set(bi);
                        }
                    }
                    (c, preds, mine)
                },
            )
            .collect();
        if budget.exceeded() {
            return Err(budget.error("course precedence"));
        }
        for (c, preds, bits) in results {
            for b in preds {
                edges.push((b, c));
            }
            if use_bits {
                anc[c] = bits;
            }
        }
        // Lay the ply into the grid.
        let mut covered: Vec<(i64, i64)> = Vec::new();
        let mut hits = Vec::new();
        for &c in courses {
            let fc = &fps.courses[c];
            for (qi, q) in fc.quads.iter().enumerate() {
                grid.cells(q, &fc.moves[fc.move_of[qi] as usize], &mut hits);
                for h in &hits {
                    cells.get_mut(h.key).push(Entry { course: c as u32, quad: qi as u32, ply: p as u32, full: h.full });
                    if h.full {
                        covered.push(h.key);
                    }
                }
            }
        }
        covered.sort_unstable();
        covered.dedup();
        for key in covered {
            cells.get_mut(key).retain(|e| e.ply as usize >= p);
        }
    }
    Ok(edges)
}

/// Doherty et al.'s precedence network: consecutive plies joined while the next ply intersects none
/// of the set's courses. Returns the sets as lists of plies. Refused like
/// [`course_precedence`] beyond [`MAX_VISITS`] grid entries.
pub fn precedence_sets(fps: &Footprints, plies: &[Vec<usize>]) -> Result<Vec<Vec<usize>>, NcError> {
    precedence_sets_within(fps, plies, Limits::DEFAULT)
}

/// [`precedence_sets`] under `limits`.
pub(crate) fn precedence_sets_within(
    fps: &Footprints,
    plies: &[Vec<usize>],
    limits: Limits,
) -> Result<Vec<Vec<usize>>, NcError> {
    let budget = Budget::new(limits.visits);
    let grid = Grid::new(fps, 2.0, limits.hits);
    let frame = fps.frame;
    let mut sets: Vec<Vec<usize>> = Vec::new();
    let mut cells: CellStore<Vec<Entry>> = CellStore::new(&grid);
    let mut touched: Vec<(i64, i64)> = Vec::new();
    let mut hits = Vec::new();
    for (p, courses) in plies.iter().enumerate() {
        let intersects = !sets.is_empty()
            && courses.iter().any(|&c| {
                fps.courses[c].quads.iter().any(|q| {
                    grid.cells(q, q, &mut hits);
                    hits.iter().any(|h| {
                        cells.get(h.key).is_some_and(|stack| {
                            // Out of budget: stop scanning (the error follows).
                            if !budget.spend(stack.len() as u64 + 1) {
                                return true;
                            }
                            stack.iter().any(|e| {
                                quads_overlap(&frame, q, &fps.courses[e.course as usize].quads[e.quad as usize])
                            })
                        })
                    })
                })
            });
        if budget.exceeded() {
            return Err(budget.error("Doherty et al.'s precedence sets"));
        }
        if sets.is_empty() || intersects {
            sets.push(Vec::new());
            for key in touched.drain(..) {
                cells.get_mut(key).clear();
            }
        }
        if let Some(s) = sets.last_mut() {
            s.push(p);
        }
        for &c in courses {
            for (qi, q) in fps.courses[c].quads.iter().enumerate() {
                grid.cells(q, q, &mut hits);
                for h in &hits {
                    cells.get_mut(h.key).push(Entry { course: c as u32, quad: qi as u32, ply: p as u32, full: false });
                    touched.push(h.key);
                }
            }
        }
    }
    Ok(sets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::footprint::Footprint;
    use proptest::prelude::*;

    fn band(a: [f64; 2], b: [f64; 2], w: f64) -> Footprint {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let u = [d[0] / len, d[1] / len];
        let q = Quad { c: [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], u, hl: len / 2.0, hw: w / 2.0 - 0.005 };
        Footprint { quads: vec![q], moves: vec![q], move_of: vec![0], paths: vec![vec![a, b]] }
    }

    /// Reachability over the edges, as a set of pairs.
    fn closure(n: usize, edges: &[(usize, usize)]) -> Vec<Vec<bool>> {
        let mut r = vec![vec![false; n]; n];
        for &(a, b) in edges {
            r[a][b] = true;
        }
        for k in 0..n {
            for i in 0..n {
                if r[i][k] {
                    for j in 0..n {
                        if r[k][j] {
                            r[i][j] = true;
                        }
                    }
                }
            }
        }
        r
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// The reduced edges' closure equals the brute-force relation, and every edge is a real
        /// overlap between plies in order.
        #[test]
        fn reduced_precedence_equals_brute_force(
            seed in proptest::collection::vec((0.0f64..200.0, 0.0f64..200.0, 0.0f64..std::f64::consts::PI, 20.0f64..150.0, 4.0f64..30.0), 4..40),
            per_ply in 2usize..8,
        ) {
            let courses: Vec<Footprint> = seed.iter().map(|&(x, y, a, l, w)| {
                band([x, y], [x + l * a.cos(), y + l * a.sin()], w)
            }).collect();
            let n = courses.len();
            let plies: Vec<Vec<usize>> = (0..n).collect::<Vec<_>>().chunks(per_ply).map(|c| c.to_vec()).collect();
            let fps = Footprints { frame: Frame::Plan, courses };
            let edges = course_precedence(&fps, &plies).unwrap();
            let ply_of = |c: usize| c / per_ply;
            for &(a, b) in &edges {
                prop_assert!(ply_of(a) < ply_of(b));
                prop_assert!(fps.courses[a].overlaps(&fps.courses[b], &fps.frame));
            }
            let r = closure(n, &edges);
            for a in 0..n {
                for b in 0..n {
                    if ply_of(a) < ply_of(b) && fps.courses[a].overlaps(&fps.courses[b], &fps.frame) {
                        prop_assert!(r[a][b], "{a} -> {b} missing");
                    }
                }
            }
        }
    }

    /// The pairs (a, b) with a in an earlier ply than b and overlapping it, by brute force.
    fn relation(fps: &Footprints, ply_of: &dyn Fn(usize) -> usize) -> Vec<Vec<bool>> {
        let n = fps.courses.len();
        let mut r = vec![vec![false; n]; n];
        for a in 0..n {
            for b in 0..n {
                r[a][b] = ply_of(a) < ply_of(b) && fps.courses[a].overlaps(&fps.courses[b], &fps.frame);
            }
        }
        r
    }

    /// A grid budget far too small for the natural cells (0.5 median widths) grows the cells
    /// instead of leaving rectangles out (before, a rectangle over more than 4,000,000 cells was
    /// silently dropped from the grid): the edges' closure is still the brute-force relation,
    /// and the grid holds no more incidences than allowed.
    #[test]
    fn a_small_cell_budget_grows_the_cells_and_keeps_the_relation() {
        // Ply 0: thin bands 2 mm wide across x; ply 1: one huge band crossing some of them and
        // thin bands; ply 2: thin bands over ply 1's.
        let mut courses = Vec::new();
        for k in 0..20 {
            courses.push(band([0.0, 10.0 * k as f64], [300.0, 10.0 * k as f64], 2.0));
        }
        courses.push(band([100.0, -50.0], [100.0, 120.0], 40.0));
        for k in 0..10 {
            courses.push(band([150.0 + 10.0 * k as f64, 0.0], [150.0 + 10.0 * k as f64, 500.0], 2.0));
        }
        for k in 0..10 {
            courses.push(band([145.0 + 10.0 * k as f64, 0.0], [155.0 + 10.0 * k as f64, 400.0], 2.0));
        }
        let plies: Vec<Vec<usize>> = vec![(0..20).collect(), (20..31).collect(), (31..41).collect()];
        let ply_of = |c: usize| {
            if c < 20 {
                0
            } else if c < 31 {
                1
            } else {
                2
            }
        };
        let fps = Footprints { frame: Frame::Plan, courses };
        let want = relation(&fps, &ply_of);
        assert!(want.iter().flatten().filter(|x| **x).count() > 20);
        let small = Limits { visits: MAX_VISITS, hits: 60 };
        let natural = Grid::new(&fps, 0.5, MAX_CELL_HITS);
        let grown = Grid::new(&fps, 0.5, small.hits);
        assert!(grown.size > 4.0 * natural.size, "{} {}", grown.size, natural.size);
        for limits in [Limits::DEFAULT, small] {
            let edges = course_precedence_within(&fps, &plies, limits).unwrap();
            let r = closure(fps.courses.len(), &edges);
            for (a, row) in want.iter().enumerate() {
                for (b, &w) in row.iter().enumerate() {
                    assert_eq!(r[a][b], w, "{a} -> {b} with {limits:?}");
                }
            }
            let sets = precedence_sets_within(&fps, &plies, limits).unwrap();
            assert_eq!(sets, vec![vec![0], vec![1], vec![2]]);
        }
    }

    /// Footprints piled up by the hundred over one place: past the visit budget the searches
    /// stop with a clear refusal instead of running on; within it they give the relation.
    #[test]
    fn searches_past_their_visit_budget_are_refused() {
        let courses: Vec<Footprint> = (0..300).map(|k| band([0.0, 0.001 * k as f64], [100.0, 0.0], 10.0)).collect();
        let plies: Vec<Vec<usize>> = vec![(0..150).collect(), (150..300).collect()];
        let fps = Footprints { frame: Frame::Plan, courses };
        let tight = Limits { visits: 10_000, hits: MAX_CELL_HITS };
        let e = course_precedence_within(&fps, &plies, tight).unwrap_err();
        assert!(matches!(e, NcError::WorkLimit { limit: 10_000, .. }), "{e}");
        assert!(e.to_string().starts_with("course precedence: more than 10000 footprint comparisons"), "{e}");
        let e = precedence_sets_within(&fps, &plies, Limits { visits: 100, hits: MAX_CELL_HITS }).unwrap_err();
        assert!(e.to_string().starts_with("Doherty et al.'s precedence sets: more than 100"), "{e}");
        let edges = course_precedence(&fps, &plies).unwrap();
        let r = closure(300, &edges);
        let want = relation(&fps, &|c| c / 150);
        assert_eq!(r, want);
    }

    #[test]
    fn stacked_plies_give_few_edges() {
        // Ten plies of ten parallel 0° courses exactly over each other: each course needs only
        // the course below it.
        let mut courses = Vec::new();
        let mut plies = Vec::new();
        for p in 0..10 {
            let mut ply = Vec::new();
            for k in 0..10 {
                let y = k as f64 * 50.0;
                courses.push(band([0.0, y], [1000.0, y], 50.0));
                ply.push(p * 10 + k);
            }
            plies.push(ply);
        }
        let fps = Footprints { frame: Frame::Plan, courses };
        let edges = course_precedence(&fps, &plies).unwrap();
        assert_eq!(edges.len(), 90, "{edges:?}");
        assert!(edges.iter().all(|&(a, b)| b == a + 10));
    }

    #[test]
    fn seed_000_sets_join_non_intersecting_plies() {
        let base = band([0.0, 0.0], [1000.0, 0.0], 400.0);
        let pad1 = band([100.0, 0.0], [200.0, 0.0], 50.0);
        let pad2 = band([500.0, 0.0], [600.0, 0.0], 50.0);
        let pad3 = band([150.0, 0.0], [550.0, 0.0], 50.0);
        let fps = Footprints { frame: Frame::Plan, courses: vec![base, pad1, pad2, pad3] };
        let sets = precedence_sets(&fps, &[vec![0], vec![1], vec![2], vec![3]]).unwrap();
        assert_eq!(sets, vec![vec![0], vec![1, 2], vec![3]]);
    }
}
