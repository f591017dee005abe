//! The ordering job: pieces become tasks of a `towpath_seq::Problem` and the solver picks the
//! order, each closed contour's entry and each open stroke's direction, under precedence.
//!
//! - **Modes.** An open stroke has one mode, or two (forwards, backwards) when it may be
//!   reversed. A closed contour has one mode per entry candidate: its vertices (segment ends)
//!   and, with [`EntryMode::Any`], points at a spacing along it, at most
//!   [`OrderOptions::max_entries`] in all (spread evenly when there are more); entering at a
//!   point fixes the exit at the same point (the contour is cut all the way round, as a toolpath
//!   cell of Castelino et al. (2003) Fig. 4 fixes its exit). A closed contour keeps its drawn
//!   direction: it leaves where it entered, so the direction never changes travel, and the kerf
//!   side stays as drawn.
//! - **Precedence.** A piece inside a closed contour comes before it (module [`crate::contain`]);
//!   explicit hierarchy pairs are added; operations are done in their listed order (each one a
//!   problem of its own starting where the previous one ended) unless they are mixed.
//! - **Search.** With towpath's solver, groups of more than a few pieces are solved by
//!   [`crate::stroke_search`] (2-opt, Or-opt with reversal and mode choice, segment-swap kicks)
//!   from the greedy-edge tour ([`crate::greedy_match`], no precedence) or a grid nearest-neighbour
//!   tour, whichever is shorter; small ones exactly by `towpath_seq`'s dynamic program.
//!   Either answer passes `towpath_seq::check`.
//! - **Refinement.** After the solve, each closed contour's entry is moved along the contour to
//!   the point that is best between the exit before it and the entry after it, a few passes over
//!   the route; a move is kept only when it shortens the travel.
//! - **Lead-ins** (module [`crate::lead`]) sit at the entry on the scrap side and are part of the
//!   entry state, so the solver prices them.

use std::time::Instant;

use towpath_baselines::{solve_with, BaselineParams, SolverName};
use towpath_seq::{check, End, Metric, Mode, PointCost, Problem, SolveOptions, StateId, Step, TaskId};

use crate::contain::{containers, Shapes};
use crate::error::CutError;
use crate::geom::{dist, seg_flatten, Path, Place, P2};
use crate::greedy_match::{greedy_matching, pen_up};
use crate::lead::{lead_in, LeadIn};
use crate::model::{travel, Drawing, Placement};
use crate::stroke_search::{Budget, StrokeSearch};

/// Where a closed contour may be entered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EntryMode {
    /// Only at its vertices (segment ends).
    Vertex,
    /// Anywhere: vertices and points at a spacing as candidates, then each chosen entry moved
    /// along the contour to its best point.
    Any,
}

/// How to order a drawing.
#[derive(Clone, Debug)]
pub struct OrderOptions {
    /// Open strokes may run backwards.
    pub reverse: bool,
    /// Pieces inside a closed contour come first.
    pub inner_first: bool,
    /// Ignore the operations' order (containment and hierarchy still hold).
    pub mix_operations: bool,
    /// Where closed contours may be entered.
    pub entry: EntryMode,
    /// Spacing of entry candidates along a closed contour (`None`: its length / `max_entries`).
    pub entry_spacing: Option<f64>,
    /// Most entry candidates per closed contour.
    pub max_entries: usize,
    /// A lead-in at each closed contour's entry.
    pub lead_in: Option<LeadIn>,
    /// Where the tool starts (`None`: wherever the first piece begins).
    pub start: Option<P2>,
    /// Flattening and "touching" tolerance, in drawing units.
    pub tolerance: f64,
    /// The solver's budget, seed and threads.
    pub solve: SolveOptions,
    /// Which solver.
    pub solver: SolverName,
    /// The baselines' parameters.
    pub params: BaselineParams,
}

impl Default for OrderOptions {
    fn default() -> Self {
        OrderOptions {
            reverse: true,
            inner_first: true,
            mix_operations: false,
            entry: EntryMode::Any,
            entry_spacing: None,
            max_entries: 12,
            lead_in: None,
            start: Some([0.0, 0.0]),
            tolerance: 1e-3,
            solve: SolveOptions::default(),
            solver: SolverName::Towpath,
            params: BaselineParams::default(),
        }
    }
}

/// What an ordering returns.
#[derive(Clone, Debug)]
pub struct OrderReport {
    /// The pieces in their new order, each as it is done.
    pub placements: Vec<Placement>,
    /// Travel of the input order, each piece as drawn (from the start, if any).
    pub travel_before: f64,
    /// Travel of the new order.
    pub travel_after: f64,
    /// Precedence pairs the order keeps (containment and hierarchy, within the solved groups).
    pub precedence_pairs: usize,
    /// Solver time (all groups).
    pub solve_seconds: f64,
    /// Solver iterations (all groups).
    pub iterations: u64,
    /// Travel right after the solver, before entries were refined.
    pub travel_solved: f64,
    /// A lower bound on the travel of every order that keeps the same rules, when the solver
    /// proved one for every group: asked for with `solve.held_karp_bound`, given when every
    /// group is of open strokes drawn either way (solved through their ends; Held–Karp bound).
    /// `None` otherwise.
    pub travel_lower_bound: Option<f64>,
}

#[derive(Clone, Debug)]
struct Candidate {
    place: Option<Place>,
    reversed: bool,
    entry: P2,
    exit: P2,
}

/// The precedence pairs `(before, after)` the ordering must keep: containment (inner first) and
/// the drawing's hierarchy, and whether operations are ordered.
pub fn precedence_pairs(drawing: &Drawing, shapes: &Shapes, opts: &OrderOptions) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    if opts.inner_first {
        let inside = containers(drawing, shapes, opts.tolerance, !opts.mix_operations);
        for (a, cs) in inside.iter().enumerate() {
            for &c in cs {
                pairs.push((a, c));
            }
        }
    }
    pairs.extend(drawing.hierarchy.iter().copied());
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

fn tangent(path: &Path, at: Place) -> P2 {
    let h = 1e-6;
    let (a, b) = if at.t + h <= 1.0 {
        (path.point(at), path.point(Place { seg: at.seg, t: at.t + h }))
    } else {
        (path.point(Place { seg: at.seg, t: at.t - h }), path.point(at))
    };
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l = dx.hypot(dy);
    if l > 0.0 {
        [dx / l, dy / l]
    } else {
        [1.0, 0.0]
    }
}

/// Entry places of a closed path: vertices, then points at a spacing, at most `max`.
fn entry_places(path: &Path, opts: &OrderOptions) -> Vec<Place> {
    let max = opts.max_entries.max(1);
    let nseg = path.segs.len();
    let vertex_budget = if opts.entry == EntryMode::Any { max.div_ceil(2).max(1) } else { max };
    let mut places: Vec<Place> = if nseg <= vertex_budget {
        (0..nseg).map(|seg| Place { seg, t: 0.0 }).collect()
    } else {
        (0..vertex_budget).map(|k| Place { seg: k * nseg / vertex_budget, t: 0.0 }).collect()
    };
    if opts.entry == EntryMode::Any && places.len() < max {
        let room = max - places.len();
        let len = path.length();
        let spacing = opts.entry_spacing.unwrap_or(len / (room + 1) as f64).max(len / (room + 1) as f64);
        places.extend(path.places_at_spacing(spacing, room));
    }
    places
}

struct Prepared {
    candidates: Vec<Vec<Candidate>>,
    depth: Vec<usize>,
}

fn prepare(drawing: &Drawing, shapes: &Shapes, opts: &OrderOptions) -> Prepared {
    let n = drawing.pieces.len();
    // Depth (number of closed contours around a piece) decides the scrap side of lead-ins.
    let depth: Vec<usize> = if opts.lead_in.is_some() {
        containers(drawing, shapes, opts.tolerance, false).iter().map(|c| c.len()).collect()
    } else {
        vec![0; n]
    };
    let mut candidates = Vec::with_capacity(n);
    for (i, piece) in drawing.pieces.iter().enumerate() {
        let path = &piece.path;
        let mut cands = Vec::new();
        if path.closed && !path.segs.is_empty() && !piece.fixed {
            for place in entry_places(path, opts) {
                let p = path.point(place);
                let entry = match &opts.lead_in {
                    Some(l) => lead_in(path, place, &shapes.points[i], depth[i], l, tangent(path, place)).start,
                    None => p,
                };
                cands.push(Candidate { place: Some(place), reversed: false, entry, exit: p });
            }
        } else {
            cands.push(Candidate { place: None, reversed: false, entry: path.start, exit: path.end() });
            if opts.reverse && piece.reversible && !piece.fixed && path.start != path.end() {
                cands.push(Candidate { place: None, reversed: true, entry: path.end(), exit: path.start });
            }
        }
        candidates.push(cands);
    }
    Prepared { candidates, depth }
}

fn placement(
    drawing: &Drawing,
    shapes: &Shapes,
    prep: &Prepared,
    opts: &OrderOptions,
    piece: usize,
    c: &Candidate,
) -> Placement {
    let src = &drawing.pieces[piece].path;
    let (path, lead) = match c.place {
        Some(place) => {
            let lead = opts
                .lead_in
                .as_ref()
                .map(|l| lead_in(src, place, &shapes.points[piece], prep.depth[piece], l, tangent(src, place)));
            (src.started_at(place), lead)
        }
        None if c.reversed => (src.reversed(), None),
        None => (src.clone(), None),
    };
    Placement { piece, path, reversed: c.reversed, lead_in: lead }
}

/// Orders a drawing.
pub fn order(drawing: &Drawing, opts: &OrderOptions) -> Result<OrderReport, CutError> {
    let n = drawing.pieces.len();
    let shapes = Shapes::new(drawing, opts.tolerance);
    let pairs = precedence_pairs(drawing, &shapes, opts);
    // Operation groups, in order.
    let groups: Vec<Vec<usize>> = if opts.mix_operations || drawing.operations.len() <= 1 {
        vec![(0..n).collect()]
    } else {
        let mut g = vec![Vec::new(); drawing.operations.len().max(1)];
        for (i, p) in drawing.pieces.iter().enumerate() {
            let k = p.operation.min(g.len() - 1);
            g[k].push(i);
        }
        g
    };
    let mut group_of = vec![0usize; n];
    for (k, g) in groups.iter().enumerate() {
        for &i in g {
            group_of[i] = k;
        }
    }
    for &(a, b) in &pairs {
        if a >= n || b >= n {
            return Err(CutError::Hierarchy(format!("piece index {} out of range", a.max(b))));
        }
        if group_of[a] > group_of[b] {
            return Err(CutError::Hierarchy(format!(
                "piece {} must come before piece {}, but its operation {:?} comes after {:?}",
                drawing.pieces[a].id,
                drawing.pieces[b].id,
                drawing.operations[drawing.pieces[a].operation],
                drawing.operations[drawing.pieces[b].operation]
            )));
        }
    }
    let prep = prepare(drawing, &shapes, opts);
    let before = travel(opts.start, &crate::model::as_drawn(drawing));

    let mut placements: Vec<Placement> = Vec::with_capacity(n);
    let mut at = opts.start;
    let mut solve_seconds = 0.0;
    let mut iterations = 0;
    let mut kept_pairs = 0;
    let mut bound = opts.solve.held_karp_bound.then_some(0.0);
    for group in &groups {
        if group.is_empty() {
            continue;
        }
        let mut task_of = vec![u32::MAX; n];
        for (t, &i) in group.iter().enumerate() {
            task_of[i] = t as u32;
        }
        let mut points: Vec<[f64; 3]> = Vec::new();
        let state = |p: P2, points: &mut Vec<[f64; 3]>| {
            points.push([p[0], p[1], 0.0]);
            StateId(points.len() as u32 - 1)
        };
        let start = at.map(|p| state(p, &mut points));
        let mut task_modes = Vec::with_capacity(group.len());
        for &i in group {
            let cands = &prep.candidates[i];
            let mut modes: Vec<Mode> = Vec::with_capacity(cands.len());
            for (k, c) in cands.iter().enumerate() {
                // a mode that is an earlier one run backwards shares its states (the solver then
                // knows the piece is two-way)
                let earlier = cands[..k].iter().position(|o| o.entry == c.exit && o.exit == c.entry);
                modes.push(match earlier {
                    Some(o) => Mode::new(modes[o].exit, modes[o].entry),
                    None => {
                        let e = state(c.entry, &mut points);
                        let x = if c.exit == c.entry { e } else { state(c.exit, &mut points) };
                        Mode::new(e, x)
                    }
                });
            }
            task_modes.push(modes);
        }
        let cost = PointCost::new(points, Metric::Euclidean);
        let mut b = Problem::builder(cost);
        for modes in task_modes {
            b.task(modes);
        }
        for &(x, y) in &pairs {
            if task_of[x] != u32::MAX && task_of[y] != u32::MAX {
                b.precede(TaskId(task_of[x]), TaskId(task_of[y]));
                kept_pairs += 1;
            }
        }
        if let Some(s) = start {
            b.start(s);
        }
        b.end(End::Free);
        let problem = b.build().map_err(|e| CutError::Hierarchy(e.to_string()))?;
        // The input order is not handed to the solver (under a time limit a given start lets
        // the construction stop early); it is kept instead when it is feasible and cheaper.
        let initial: Vec<Step> = (0..group.len() as u32).map(|t| Step { task: TaskId(t), mode: 0 }).collect();
        let initial_cost = check(&problem, &initial).ok();
        let t0 = Instant::now();
        // A nearest-neighbour tour over a grid of entries (precedence kept) is the solver's
        // start: O(n) on spread-out drawings, where the solver's own construction is O(n²).
        let mut group_pairs = Vec::new();
        for &(x, y) in &pairs {
            if task_of[x] != u32::MAX && task_of[y] != u32::MAX {
                group_pairs.push((task_of[x] as usize, task_of[y] as usize));
            }
        }
        let ends: Vec<Vec<(P2, P2)>> =
            group.iter().map(|&i| prep.candidates[i].iter().map(|c| (c.entry, c.exit)).collect()).collect();
        let greedy_steps = greedy(&ends, &group_pairs, at);
        let greedy_ok = check(&problem, &greedy_steps).is_ok();
        // Strokes drawn either way without precedence: towpath's solver on their ends (see
        // `towpath_seq::SolveOptions::two_way_ends`), from the greedy-edge or the
        // nearest-neighbour tour, whichever is shorter.
        let strokes_only = group.iter().all(|&i| {
            matches!(&prep.candidates[i][..], [a, b] if a.entry == b.exit && a.exit == b.entry && a.entry != a.exit)
        });
        let two_way = opts.solve.two_way_ends && group_pairs.is_empty() && strokes_only;
        let (solved, solved_cost) =
            if opts.solver == SolverName::Towpath && greedy_ok && group.len() > opts.solve.exact_up_to && !two_way {
                // towpath's solver on stroke tours: the stroke local search (2-opt, Or-opt and
                // kicks with neighbour lists) from the nearest-neighbour start, anytime.
                let nn: Vec<(usize, u32)> = greedy_steps.iter().map(|s| (s.task.index(), s.mode)).collect();
                // Without precedence, the greedy-edge tour when it is the shorter start.
                let init = match group_pairs.is_empty().then(|| greedy_matching(&ends, at)).flatten() {
                    Some(g) if pen_up(&ends, at, &g) < pen_up(&ends, at, &nn) => g,
                    _ => nn,
                };
                let mut search = StrokeSearch::new(&ends, &group_pairs, at, &init);
                let budget = Budget {
                    deadline: opts.solve.time_limit.map(|d| t0 + d),
                    kicks: opts.solve.iterations,
                    seed: opts.solve.seed,
                };
                let stats = search.optimize(&budget);
                iterations += stats.kicks;
                let steps: Vec<Step> =
                    search.steps().into_iter().map(|(t, m)| Step { task: TaskId(t as u32), mode: m }).collect();
                // The independent checker of towpath-seq vouches for the route and its cost.
                let cost = check(&problem, &steps)
                    .map_err(|e| CutError::Solver(format!("the stroke search gave an invalid route: {e}")))?;
                bound = None;
                (steps, cost)
            } else {
                let mut sopts = opts.solve.clone();
                if greedy_ok {
                    sopts.initial = Some(greedy_steps);
                }
                if two_way {
                    // The greedy-edge tour when it is the shorter start: on 100,000 random
                    // strokes the first descent from the nearest-neighbour tour does not
                    // finish in 5 s, and the greedy one is the better tour to stop in.
                    let nn: Vec<(usize, u32)> =
                        sopts.initial.iter().flatten().map(|s| (s.task.index(), s.mode)).collect();
                    if let Some(g) = greedy_matching(&ends, at) {
                        if nn.is_empty() || pen_up(&ends, at, &g) < pen_up(&ends, at, &nn) {
                            sopts.initial =
                                Some(g.iter().map(|&(t, m)| Step { task: TaskId(t as u32), mode: m }).collect());
                        }
                    }
                    // the starts' time counts against the limit
                    sopts.time_limit = sopts.time_limit.map(|tl| tl.saturating_sub(t0.elapsed()));
                }
                let report = solve_with(opts.solver, &problem, &sopts, &opts.params)
                    .map_err(|e| CutError::Solver(e.to_string()))?;
                iterations += report.iterations;
                // Closed contours' entries move after the solver (`refine`), so a bound on the
                // solver's candidates would not bound the result: strokes only.
                bound = match (bound, report.lower_bound) {
                    (Some(sum), Some(b)) if strokes_only => Some(sum + b),
                    _ => None,
                };
                (report.solution.steps, report.solution.cost)
            };
        solve_seconds += t0.elapsed().as_secs_f64();
        let steps = match initial_cost {
            Some(c) if c < solved_cost => initial,
            _ => solved,
        };
        for s in &steps {
            let i = group[s.task.index()];
            let c = &prep.candidates[i][s.mode as usize];
            placements.push(placement(drawing, &shapes, &prep, opts, i, c));
        }
        at = placements.last().map(|p| p.exit());
    }
    let travel_solved = travel(opts.start, &placements);
    if opts.entry == EntryMode::Any {
        refine(drawing, &shapes, &prep, opts, &mut placements);
    }
    let travel_after = travel(opts.start, &placements);
    Ok(OrderReport {
        placements,
        travel_before: before,
        travel_after,
        precedence_pairs: kept_pairs,
        solve_seconds,
        iterations,
        travel_solved,
        travel_lower_bound: bound,
    })
}

/// Moves each closed contour's entry to the best point between its neighbours.
fn refine(drawing: &Drawing, shapes: &Shapes, prep: &Prepared, opts: &OrderOptions, placements: &mut [Placement]) {
    for _pass in 0..3 {
        let mut improved = false;
        for k in 0..placements.len() {
            let piece = placements[k].piece;
            let src = &drawing.pieces[piece].path;
            if !src.closed || src.segs.is_empty() || drawing.pieces[piece].fixed {
                continue;
            }
            let prev = if k == 0 { opts.start } else { Some(placements[k - 1].exit()) };
            let next = placements.get(k + 1).map(|p| p.entry());
            let price =
                |entry: P2, exit: P2| prev.map_or(0.0, |p| dist(p, entry)) + next.map_or(0.0, |q| dist(exit, q));
            let cur = price(placements[k].entry(), placements[k].exit());
            let eval = |place: Place| -> f64 {
                let p = src.point(place);
                let entry = match &opts.lead_in {
                    Some(l) => {
                        lead_in(src, place, &shapes.points[piece], prep.depth[piece], l, tangent(src, place)).start
                    }
                    None => p,
                };
                price(entry, p)
            };
            // Samples: every segment's start and its flattened interior points.
            let mut best = (f64::INFINITY, Place { seg: 0, t: 0.0 });
            let mut tmp = Vec::new();
            for (i, s) in src.segs.iter().enumerate() {
                tmp.clear();
                seg_flatten(src.seg_start(i), s, opts.tolerance.max(1e-6) * 10.0, &mut tmp);
                let m = tmp.len().clamp(2, 64);
                for j in 0..m {
                    let place = Place { seg: i, t: j as f64 / m as f64 };
                    let v = eval(place);
                    if v < best.0 {
                        best = (v, place);
                    }
                }
            }
            // Golden-section search around the best sample.
            let m = {
                tmp.clear();
                let s = &src.segs[best.1.seg];
                seg_flatten(src.seg_start(best.1.seg), s, opts.tolerance.max(1e-6) * 10.0, &mut tmp);
                tmp.len().clamp(2, 64) as f64
            };
            let seg = best.1.seg;
            let (mut lo, mut hi) = ((best.1.t - 1.0 / m).max(0.0), (best.1.t + 1.0 / m).min(1.0));
            let g = 0.618_033_988_749_894_9;
            for _ in 0..40 {
                let a = hi - g * (hi - lo);
                let b = lo + g * (hi - lo);
                if eval(Place { seg, t: a }) <= eval(Place { seg, t: b }) {
                    hi = b;
                } else {
                    lo = a;
                }
            }
            let t = 0.5 * (lo + hi);
            let v = eval(Place { seg, t });
            if v < best.0 {
                best = (v, Place { seg, t });
            }
            if best.0 < cur - 1e-9 * (1.0 + cur) {
                let c = Candidate { place: Some(best.1), reversed: false, entry: [0.0; 2], exit: [0.0; 2] };
                placements[k] = placement(drawing, shapes, prep, opts, piece, &c);
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
}

/// Chains of open strokes whose ends meet within `tol` (same operation, reversible, not in the
/// explicit hierarchy): each chain is `(piece, reversed)` in drawing order; lone strokes are
/// not listed.
pub fn merge_chains(drawing: &Drawing, tol: f64) -> Vec<Vec<(usize, bool)>> {
    use std::collections::HashMap;
    let n = drawing.pieces.len();
    let mut in_hierarchy = vec![false; n];
    for &(a, b) in &drawing.hierarchy {
        if a < n && b < n {
            in_hierarchy[a] = true;
            in_hierarchy[b] = true;
        }
    }
    let ok: Vec<bool> = (0..n)
        .map(|i| {
            let p = &drawing.pieces[i];
            !p.path.closed && p.reversible && !p.fixed && !in_hierarchy[i] && !p.path.segs.is_empty()
        })
        .collect();
    let cell = tol.max(1e-12);
    let key = |p: P2| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<(usize, bool)>> = HashMap::new();
    for i in (0..n).filter(|&i| ok[i]) {
        let p = &drawing.pieces[i].path;
        grid.entry(key(p.start)).or_default().push((i, false));
        grid.entry(key(p.end())).or_default().push((i, true));
    }
    let mut used = vec![false; n];
    // The unused stroke with an end within `tol` of `at`: (piece, whether it must be reversed).
    let find = |at: P2, op: usize, used: &[bool]| -> Option<(usize, bool)> {
        let (kx, ky) = key(at);
        let mut best: Option<(f64, usize, bool)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &(j, at_end) in grid.get(&(kx + dx, ky + dy)).into_iter().flatten() {
                    if used[j] || drawing.pieces[j].operation != op {
                        continue;
                    }
                    let p = &drawing.pieces[j].path;
                    let d = dist(at, if at_end { p.end() } else { p.start });
                    if d <= tol && best.is_none_or(|b| d < b.0 || (d == b.0 && j < b.1)) {
                        best = Some((d, j, at_end));
                    }
                }
            }
        }
        best.map(|b| (b.1, b.2))
    };
    let mut chains = Vec::new();
    for i in 0..n {
        if !ok[i] || used[i] {
            continue;
        }
        used[i] = true;
        let op = drawing.pieces[i].operation;
        let mut chain = std::collections::VecDeque::from([(i, false)]);
        // forward from the end
        let mut at = drawing.pieces[i].path.end();
        while let Some((j, rev)) = find(at, op, &used) {
            used[j] = true;
            let p = &drawing.pieces[j].path;
            at = if rev { p.start } else { p.end() };
            chain.push_back((j, rev));
        }
        // backward from the start
        let mut at = drawing.pieces[i].path.start;
        while let Some((j, at_end)) = find(at, op, &used) {
            used[j] = true;
            let p = &drawing.pieces[j].path;
            // joined at its end: it runs forwards into `at`; at its start: reversed.
            at = if at_end { p.start } else { p.end() };
            chain.push_front((j, !at_end));
        }
        if chain.len() > 1 {
            chains.push(chain.into_iter().collect());
        }
    }
    chains
}

/// [`order`] with strokes whose ends meet within `tol` joined into one task each (so they are
/// drawn one after the other without lifting); the answer still lists every piece on its own.
pub fn order_merged(drawing: &Drawing, opts: &OrderOptions, tol: f64) -> Result<OrderReport, CutError> {
    let chains = merge_chains(drawing, tol);
    if chains.is_empty() {
        return order(drawing, opts);
    }
    let n = drawing.pieces.len();
    let mut chained = vec![false; n];
    for c in &chains {
        for &(i, _) in c {
            chained[i] = true;
        }
    }
    // The merged drawing: lone pieces, then one open piece per chain.
    let mut merged = Drawing { operations: drawing.operations.clone(), pieces: Vec::new(), hierarchy: Vec::new() };
    let mut origin: Vec<Result<usize, usize>> = Vec::new(); // Ok(piece) or Err(chain)
    let mut new_index = vec![usize::MAX; n];
    for (i, p) in drawing.pieces.iter().enumerate() {
        if !chained[i] {
            new_index[i] = merged.pieces.len();
            merged.pieces.push(p.clone());
            origin.push(Ok(i));
        }
    }
    for (k, c) in chains.iter().enumerate() {
        let mut path: Option<Path> = None;
        for &(i, rev) in c {
            let p = if rev { drawing.pieces[i].path.reversed() } else { drawing.pieces[i].path.clone() };
            match &mut path {
                None => path = Some(p),
                Some(acc) => {
                    if acc.end() != p.start {
                        acc.segs.push(crate::geom::Seg::Line(p.start));
                    }
                    acc.segs.extend(p.segs);
                }
            }
        }
        let first = c[0].0;
        let Some(path) = path else { continue };
        merged.pieces.push(crate::model::Piece {
            id: format!("{}+{}", drawing.pieces[first].id, c.len() - 1),
            operation: drawing.pieces[first].operation,
            path,
            reversible: true,
            fixed: false,
        });
        origin.push(Err(k));
    }
    merged.hierarchy = drawing.hierarchy.iter().map(|&(a, b)| (new_index[a], new_index[b])).collect();
    let mut report = order(&merged, opts)?;
    let mut expanded = Vec::with_capacity(n);
    for pl in &report.placements {
        match origin[pl.piece] {
            Ok(i) => expanded.push(Placement { piece: i, ..pl.clone() }),
            Err(k) => {
                let c = &chains[k];
                let items: Vec<(usize, bool)> =
                    if pl.reversed { c.iter().rev().map(|&(i, r)| (i, !r)).collect() } else { c.clone() };
                for (i, rev) in items {
                    let p = &drawing.pieces[i].path;
                    expanded.push(Placement {
                        piece: i,
                        path: if rev { p.reversed() } else { p.clone() },
                        reversed: rev,
                        lead_in: None,
                    });
                }
            }
        }
    }
    report.placements = expanded;
    report.travel_before = travel(opts.start, &crate::model::as_drawn(drawing));
    report.travel_after = travel(opts.start, &report.placements);
    // the bound was on the merged strokes, whose joins are now drawn: not carried over
    report.travel_lower_bound = None;
    Ok(report)
}

/// A nearest-neighbour route: from `start` (or the first task's entry), always the available
/// task (every predecessor done) with the nearest entry, found in a uniform grid of entries.
/// `ends[t]` lists task t's modes as (entry, exit); `pairs` are (before, after) task pairs.
pub fn greedy(ends: &[Vec<(P2, P2)>], pairs: &[(usize, usize)], start: Option<P2>) -> Vec<Step> {
    let n = ends.len();
    let mut indeg = vec![0usize; n];
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(a, b) in pairs {
        if a < n && b < n {
            indeg[b] += 1;
            succ[a].push(b);
        }
    }
    let all: Vec<P2> = ends.iter().flatten().map(|e| e.0).collect();
    if all.is_empty() {
        return Vec::new();
    }
    let bb = crate::geom::bbox_of(&all);
    let (w, h) = ((bb[2] - bb[0]).max(1e-9), (bb[3] - bb[1]).max(1e-9));
    let cell = ((w * h) / all.len() as f64).sqrt().max(w.max(h) / 4096.0);
    let gx = ((w / cell) as usize + 1).min(4096);
    let gy = ((h / cell) as usize + 1).min(4096);
    let cell_of = |p: P2| -> (usize, usize) {
        let x = (((p[0] - bb[0]) / cell) as isize).clamp(0, gx as isize - 1) as usize;
        let y = (((p[1] - bb[1]) / cell) as isize).clamp(0, gy as isize - 1) as usize;
        (x, y)
    };
    let mut grid: Vec<Vec<(u32, u32)>> = vec![Vec::new(); gx * gy];
    let mut used = vec![false; n];
    let mut available = 0usize;
    let add = |t: usize, grid: &mut Vec<Vec<(u32, u32)>>, available: &mut usize| {
        *available += 1;
        for (m, e) in ends[t].iter().enumerate() {
            let (x, y) = cell_of(e.0);
            grid[y * gx + x].push((t as u32, m as u32));
        }
    };
    for t in 0..n {
        if indeg[t] == 0 {
            add(t, &mut grid, &mut available);
        }
    }
    let mut steps = Vec::with_capacity(n);
    let mut at = start.unwrap_or_else(|| ends.iter().find_map(|e| e.first().map(|x| x.0)).unwrap_or([0.0, 0.0]));
    while available > 0 {
        let (cx, cy) = cell_of(at);
        let mut best: Option<(f64, u32, u32)> = None;
        let mut r = 0usize;
        loop {
            let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(gx - 1));
            let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(gy - 1));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    // Cells inside the ring were searched at a smaller radius.
                    let (dx, dy) =
                        ((x as isize - cx as isize).unsigned_abs(), (y as isize - cy as isize).unsigned_abs());
                    if dx.max(dy) < r {
                        continue;
                    }
                    let bucket = &mut grid[y * gx + x];
                    bucket.retain(|&(t, _)| !used[t as usize]);
                    for &(t, m) in bucket.iter() {
                        let d = dist(at, ends[t as usize][m as usize].0);
                        if best.is_none_or(|b| d < b.0 || (d == b.0 && (t, m) < (b.1, b.2))) {
                            best = Some((d, t, m));
                        }
                    }
                }
            }
            let covered = cx < r && cy < r && cx + r >= gx - 1 && cy + r >= gy - 1;
            if best.is_some_and(|b| b.0 <= r as f64 * cell) || covered {
                break;
            }
            r += 1;
        }
        let Some((_, t, m)) = best else { break };
        let t = t as usize;
        used[t] = true;
        available -= 1;
        steps.push(Step { task: TaskId(t as u32), mode: m });
        at = ends[t][m as usize].1;
        for k in 0..succ[t].len() {
            let s = succ[t][k];
            indeg[s] -= 1;
            if indeg[s] == 0 {
                add(s, &mut grid, &mut available);
            }
        }
    }
    steps
}
