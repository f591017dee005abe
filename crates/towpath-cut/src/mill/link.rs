//! Linking the cells of each tool (Castelino et al. 2003 §4.2): a generalized TSP with
//! precedence. Each cell is a task; its modes are entry candidates on its outermost loop
//! (vertices and points at a spacing), each fixing the exit; a tool starts at the origin and
//! returns there. Precedence: every cell of a parent feature before every cell of its child
//! features (the nearest ancestor this tool machines), and within a feature the cell that split
//! before the cells it split into (outside-in) or after them (inside-out). Solved by towpath's
//! solver or, for comparison, the paper's own transformation (`--solver castelino`).

use std::time::Instant;

use towpath_baselines::{solve_with, BaselineParams, SolverName};
use towpath_seq::{check, End, Metric, Mode, PointCost, Problem, SolveOptions, StateId, Step, TaskId};

use crate::error::CutError;
use crate::geom::{dist, Place, P2};
use crate::mill::cells::{cell_path, cells_for_tool, Cell, CellPath};
use crate::mill::part::Part;

/// How to plan.
#[derive(Clone, Debug)]
pub struct MillOptions {
    /// Entry candidate spacing along a cell's outermost loop (`None`: only vertices, plus
    /// points to reach `max_entries`).
    pub entry_spacing: Option<f64>,
    /// Most entry candidates per cell.
    pub max_entries: usize,
    /// Machine each cell from the inside out (default outside-in).
    pub inside_out: bool,
    /// Only these tool numbers (empty: all).
    pub tools: Vec<u32>,
    /// Solver budget, seed, threads.
    pub solve: SolveOptions,
    /// Which solver.
    pub solver: SolverName,
    /// Baselines' parameters.
    pub params: BaselineParams,
}

impl Default for MillOptions {
    fn default() -> Self {
        MillOptions {
            entry_spacing: None,
            max_entries: 16,
            inside_out: false,
            tools: Vec::new(),
            solve: SolveOptions::default(),
            solver: SolverName::Towpath,
            params: BaselineParams::default(),
        }
    }
}

/// The linked toolpath of one tool.
#[derive(Clone, Debug)]
pub struct ToolPlan {
    /// Index into the part's tools.
    pub tool: usize,
    /// The tool's cells.
    pub cells: Vec<Cell>,
    /// Cells in machining order, each machined from its chosen entry.
    pub order: Vec<(usize, CellPath)>,
    /// The baseline order (cells in feature order, each from its first vertex).
    pub baseline: Vec<(usize, CellPath)>,
    /// Precedence pairs between cells.
    pub precedence: Vec<(usize, usize)>,
    /// Rapid length in X/Y of the baseline, origin to origin.
    pub rapid_before: f64,
    /// Rapid length in X/Y of the plan.
    pub rapid_after: f64,
    /// Solver time.
    pub solve_seconds: f64,
}

/// A whole part's plan.
#[derive(Clone, Debug)]
pub struct Plan {
    /// One per tool used.
    pub tools: Vec<ToolPlan>,
}

fn entry_places(cell: &Cell, opts: &MillOptions) -> Vec<Place> {
    let Some(first) = cell.levels.first() else { return Vec::new() };
    let outer = &first.outer;
    let max = opts.max_entries.max(1);
    let n = outer.segs.len();
    let mut places: Vec<Place> = if n <= max {
        (0..n).map(|seg| Place { seg, t: 0.0 }).collect()
    } else {
        (0..max).map(|k| Place { seg: k * n / max, t: 0.0 }).collect()
    };
    if places.len() < max {
        let room = max - places.len();
        let len = outer.length();
        let spacing = opts.entry_spacing.unwrap_or(len / (room + 1) as f64).max(len / (room + 1) as f64);
        places.extend(outer.places_at_spacing(spacing, room));
    }
    places
}

/// Rapid X/Y length of machining cell paths in order from `origin` back to it.
pub fn rapid_length(origin: P2, order: &[(usize, CellPath)]) -> f64 {
    let mut at = origin;
    let mut total = 0.0;
    for (_, p) in order {
        total += dist(at, p.entry());
        at = p.exit();
    }
    total + dist(at, origin)
}

/// The precedence pairs between a tool's cells.
pub fn cell_precedence(part: &Part, cells: &[Cell], inside_out: bool) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for (i, c) in cells.iter().enumerate() {
        if let Some(p) = c.parent {
            pairs.push(if inside_out { (i, p) } else { (p, i) });
        }
    }
    // Feature hierarchy: the nearest ancestor with cells for this tool.
    let has = |f: usize| cells.iter().any(|c| c.feature == f);
    for (i, c) in cells.iter().enumerate() {
        let mut anc = part.features[c.feature].parent;
        while let Some(a) = anc {
            if has(a) {
                for (j, d) in cells.iter().enumerate() {
                    if d.feature == a {
                        pairs.push((j, i));
                    }
                }
                break;
            }
            anc = part.features[a].parent;
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Plans every tool of a part.
pub fn plan(part: &Part, opts: &MillOptions) -> Result<Plan, CutError> {
    let mut tools = Vec::new();
    for (ti, tool) in part.tools.iter().enumerate() {
        if !opts.tools.is_empty() && !opts.tools.contains(&tool.number) {
            continue;
        }
        let cells = cells_for_tool(part, ti);
        let precedence = cell_precedence(part, &cells, opts.inside_out);
        // Modes: each candidate's cell path, priced by its entry and exit.
        let mut points: Vec<[f64; 3]> = vec![[part.origin[0], part.origin[1], 0.0]];
        let mut paths: Vec<Vec<CellPath>> = Vec::with_capacity(cells.len());
        let mut b_modes = Vec::with_capacity(cells.len());
        for cell in &cells {
            let mut modes = Vec::new();
            let mut cps = Vec::new();
            for place in entry_places(cell, opts) {
                let cp = cell_path(cell, place, opts.inside_out);
                let (e, x) = (cp.entry(), cp.exit());
                points.push([e[0], e[1], 0.0]);
                let es = StateId(points.len() as u32 - 1);
                points.push([x[0], x[1], 0.0]);
                let xs = StateId(points.len() as u32 - 1);
                modes.push(Mode::new(es, xs));
                cps.push(cp);
            }
            b_modes.push(modes);
            paths.push(cps);
        }
        let mut baseline_steps: Vec<Step> = Vec::new();
        let mut tp = ToolPlan {
            tool: ti,
            cells: cells.clone(),
            order: Vec::new(),
            baseline: Vec::new(),
            precedence: precedence.clone(),
            rapid_before: 0.0,
            rapid_after: 0.0,
            solve_seconds: 0.0,
        };
        if cells.is_empty() {
            tools.push(tp);
            continue;
        }
        let mut b = Problem::builder(PointCost::new(points, Metric::Euclidean));
        for m in b_modes {
            b.task(m);
        }
        for &(x, y) in &precedence {
            b.precede(TaskId(x as u32), TaskId(y as u32));
        }
        b.start(StateId(0));
        b.end(End::Closed);
        let problem = b.build().map_err(|e| CutError::Hierarchy(e.to_string()))?;
        // Baseline: cells in feature order (a topological order, stable), first vertex.
        let topo = problem.precedence().topological().to_vec();
        let mut done = vec![false; cells.len()];
        let preds: Vec<Vec<usize>> = (0..cells.len())
            .map(|t| problem.precedence().predecessors(TaskId(t as u32)).iter().map(|x| x.index()).collect())
            .collect();
        while baseline_steps.len() < cells.len() {
            let next = (0..cells.len()).find(|&t| !done[t] && preds[t].iter().all(|&p| done[p]));
            let t = next.unwrap_or_else(|| topo[baseline_steps.len()].index());
            done[t] = true;
            baseline_steps.push(Step { task: TaskId(t as u32), mode: 0 });
        }
        check(&problem, &baseline_steps).map_err(|e| CutError::Hierarchy(e.to_string()))?;
        let mut sopts = opts.solve.clone();
        sopts.initial = Some(baseline_steps.clone());
        let t0 = Instant::now();
        let report =
            solve_with(opts.solver, &problem, &sopts, &opts.params).map_err(|e| CutError::Solver(e.to_string()))?;
        tp.solve_seconds = t0.elapsed().as_secs_f64();
        tp.baseline =
            baseline_steps.iter().map(|s| (s.task.index(), paths[s.task.index()][s.mode as usize].clone())).collect();
        tp.order = report
            .solution
            .steps
            .iter()
            .map(|s| (s.task.index(), paths[s.task.index()][s.mode as usize].clone()))
            .collect();
        tp.rapid_before = rapid_length(part.origin, &tp.baseline);
        tp.rapid_after = rapid_length(part.origin, &tp.order);
        tools.push(tp);
    }
    Ok(Plan { tools })
}

/// Checks a plan independently of the solver: every cell of every planned tool once, the
/// precedence pairs (recomputed from the part) kept. Returns the problems found.
pub fn check_plan(part: &Part, plan: &Plan, inside_out: bool) -> Vec<String> {
    let mut problems = Vec::new();
    for tp in &plan.tools {
        let number = part.tools[tp.tool].number;
        let mut pos = vec![usize::MAX; tp.cells.len()];
        for (k, (c, _)) in tp.order.iter().enumerate() {
            match pos.get_mut(*c) {
                Some(p) if *p == usize::MAX => *p = k,
                _ => problems.push(format!("T{number}: cell {c} done twice or unknown")),
            }
        }
        for (c, p) in pos.iter().enumerate() {
            if *p == usize::MAX {
                problems.push(format!("T{number}: cell {} not machined", tp.cells[c].id));
            }
        }
        for (a, b) in cell_precedence(part, &tp.cells, inside_out) {
            if pos[a] != usize::MAX && pos[b] != usize::MAX && pos[a] > pos[b] {
                problems.push(format!("T{number}: cell {} must come before {}", tp.cells[a].id, tp.cells[b].id));
            }
        }
    }
    problems
}
