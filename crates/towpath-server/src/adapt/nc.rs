//! AFP programs: demo parts and their cells, parsing, the drawable geometry of a program,
//! optimization with progress and cancel (`towpath_nc::optimize`, the same run as `towpath
//! optimize`), motion-safety checks against a cell, and reports. Every call into `towpath-nc` is
//! here.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use towpath_machine::{CostKind, Machine};
use towpath_nc::{
    parse, AfpOptions, NcError, OptimizeOptions, PrecedenceRule, Program, Region, Report, Safety, SafetyOptions,
    SafetyReport, SolverName, Stage, Width,
};

use crate::error::ApiError;
use crate::geometry::Blob;

pub use towpath_nc::Dialect;

/// Tow width of the demo parts and the panel, mm.
pub const DEMO_TOW_WIDTH: f64 = towpath_nc::demo::TOW_WIDTH;

/// A built-in demo part.
pub struct DemoPart {
    /// File-friendly name.
    pub name: String,
    /// What it is.
    pub description: String,
    /// Its machine.
    pub machine: Machine,
    /// Program text (reference dialect).
    pub program: String,
    /// The meshes of its cell (mold tool, stringers, fixtures) as (file name, STL bytes); the
    /// names are those `towpath demo` writes (`part.obstacle.stl`).
    pub cell: Vec<(String, Vec<u8>)>,
}

/// The built-in demo parts (Doherty et al. (2022)'s test parts, and the parts in a cell).
pub fn demo_parts() -> Vec<DemoPart> {
    towpath_nc::demo::demo_parts()
        .into_iter()
        .map(|p| {
            let cell = p
                .obstacles
                .iter()
                .map(|o| {
                    let soup = towpath_geom::Soup::from_triangles(
                        o.triangles.iter().map(|t| t.map(towpath_geom::DVec3::from_array)),
                    );
                    let mut stl = Vec::new();
                    // Writing into memory cannot fail.
                    let _ = towpath_geom::io::write_stl(&mut stl, &soup);
                    (format!("{}.{}.stl", p.name, o.name), stl)
                })
                .collect();
            DemoPart { name: p.name, description: p.description, machine: p.machine, program: p.program, cell }
        })
        .collect()
}

/// The motion-safety set-up of a machine in the cell made of `meshes` (name, file bytes: STL,
/// OBJ or PLY), keeping `clearance` mm (default [`towpath_nc::DEFAULT_CLEARANCE`]).
pub fn cell(
    machine: &Machine,
    dialect: &Dialect,
    meshes: &[(String, Arc<Vec<u8>>)],
    clearance: Option<f64>,
) -> Result<Safety, ApiError> {
    let mut soups = Vec::with_capacity(meshes.len());
    for (name, bytes) in meshes {
        soups.push((name.clone(), super::read_soup(name, bytes)?));
    }
    let opts = SafetyOptions { clearance: clearance.unwrap_or(towpath_nc::DEFAULT_CLEARANCE), ..Default::default() };
    Safety::from_meshes(machine, dialect, &soups, opts).map_err(|e| ApiError::bad(format!("molds: {e}")))
}

/// Most issues of each kind a safety report lists in a response (the counts are always whole).
pub const MAX_LISTED_ISSUES: usize = 2000;

/// A safety report as the front end reads it: counts, the least clearance and the issues
/// (each list cut at [`MAX_LISTED_ISSUES`]).
pub fn safety_json(r: &SafetyReport) -> Value {
    let cut = |v: &[towpath_nc::MoveIssue]| v.iter().take(MAX_LISTED_ISSUES).cloned().collect::<Vec<_>>();
    json!({
        "safe": r.is_safe(),
        "summary": r.summary(),
        "clearance": r.clearance,
        "moves_checked": r.moves_checked,
        "min_clearance": r.min_clearance.map(|(d, line)| json!({"mm": d, "line": line})),
        "collision_count": r.collisions.len(),
        "near_miss_count": r.near_misses.len(),
        "limit_violation_count": r.limit_violations.len(),
        "collisions": cut(&r.collisions),
        "near_misses": cut(&r.near_misses),
        "limit_violations": r.limit_violations.iter().take(MAX_LISTED_ISSUES).collect::<Vec<_>>(),
    })
}

/// Checks a program's motion against a cell and the machine's travel limits (the checks of
/// `towpath verify --mold`). The cell must lie under the laid path, as `towpath` requires.
pub fn check_safety(
    file: &str,
    text: &str,
    machine: &Machine,
    dialect: &Dialect,
    safety: &Safety,
) -> Result<SafetyReport, ApiError> {
    let program = parse(text, machine, dialect).map_err(|e| program_error(file, e))?;
    towpath_nc::check_cell_under_path(&program, machine, safety, towpath_nc::MOLD_GAP)
        .map_err(|e| ApiError::bad(format!("molds: {e}")))?;
    Ok(towpath_nc::check_program(&program, safety))
}

/// The large stacked panel (`plies` × about `courses` courses) on the gantry machine.
pub fn panel(plies: usize, courses: usize) -> (String, Machine) {
    (towpath_nc::demo::stacked_panel(plies, courses), towpath_nc::demo::gantry())
}

/// Maps a library error about a program to an API error naming the file and line.
pub fn program_error(file: &str, e: NcError) -> ApiError {
    match e {
        NcError::Line { line, message } => ApiError::in_file(file, Some(line), message),
        NcError::SelfCheck(m) => ApiError::Internal(format!("{file}: the optimized program did not verify: {m}")),
        other => ApiError::in_file(file, None, other.to_string()),
    }
}

/// A parsed program and what the server shows of it.
pub struct Parsed {
    program: Program,
}

/// Facts of a ply for the program view's list.
#[derive(Clone, Debug, Serialize)]
pub struct PlyInfo {
    /// Marker label.
    pub label: String,
    /// Short name (its number, else its label).
    pub name: String,
    /// Marker line, 1-based.
    pub line: Option<usize>,
    /// Course indices (program order).
    pub courses: Vec<usize>,
    /// Laid length of its courses, mm (tool point, part frame).
    pub length: f64,
}

/// Facts of a course for hover and lists.
#[derive(Clone, Debug, Serialize)]
pub struct CourseInfo {
    /// Ply index.
    pub ply: usize,
    /// Course number from its marker.
    pub number: Option<i64>,
    /// Position in the program, from 1.
    pub position: usize,
    /// First and last line of its span, 1-based.
    pub lines: [usize; 2],
    /// Line of its roller contact, 1-based.
    pub contact_line: usize,
    /// Laid length, mm.
    pub length: f64,
    /// For an optimized program: the original course it is (index) and whether reversed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub original: Option<usize>,
    /// Laid in reverse of the original.
    pub reversed: bool,
}

/// Summary of a program.
#[derive(Clone, Debug, Serialize)]
pub struct ProgramInfo {
    /// Lines.
    pub lines: usize,
    /// Moves.
    pub segments: usize,
    /// Plies.
    pub plies: Vec<PlyInfo>,
    /// Courses.
    pub courses: Vec<CourseInfo>,
}

/// Segment kinds in the geometry: laid, approach/retract, off-part feed, rapid.
pub const KIND_LAYUP: u8 = 0;
/// Approach or retract.
pub const KIND_APPROACH: u8 = 1;
/// Off-part feed move (transit, header, footer).
pub const KIND_TRANSIT: u8 = 2;
/// Rapid off-part move.
pub const KIND_RAPID: u8 = 3;

/// Parses a program; errors name the file and line.
pub fn parse_program(file: &str, text: &str, machine: &Machine, dialect: &Dialect) -> Result<Parsed, ApiError> {
    parse(text, machine, dialect).map(|program| Parsed { program }).map_err(|e| program_error(file, e))
}

/// Course count of a program as the dialect's contact code counts it (cheap, for time limits).
pub fn default_time_limit(courses: usize) -> f64 {
    towpath_nc::auto_time_limit(courses).as_secs_f64()
}

fn part_points(p: &Program, machine: &Machine) -> Vec<[f64; 3]> {
    if let Some(pts) = p.part_points(machine) {
        return pts;
    }
    // No kinematics: the axes labelled X, Y and Z, where there are such.
    let idx: Vec<Option<usize>> = ["X", "Y", "Z"].iter().map(|l| machine.axis_index(l)).collect();
    let n = p.points.len() / p.dim.max(1);
    (0..n as u32)
        .map(|i| {
            let v = p.point(i);
            [0, 1, 2].map(|k| idx[k].and_then(|a| v.get(a).copied()).unwrap_or(0.0))
        })
        .collect()
}

impl Parsed {
    /// Number of courses.
    pub fn courses(&self) -> usize {
        self.program.courses.len()
    }

    /// The program's summary and its drawable geometry; `order` maps an optimized program's
    /// courses to the original's (course, reversed).
    pub fn geometry(&self, machine: &Machine, order: Option<&[(usize, bool)]>) -> (ProgramInfo, Blob) {
        let p = &self.program;
        let pts = part_points(p, machine);
        let regions = p.regions();
        let n = p.segments.len();
        let (mut from, mut to, mut course, mut line) =
            (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        let (mut kind, mut feed) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut lengths = vec![0.0f64; p.courses.len()];
        let dist = |a: u32, b: u32| -> f64 {
            match (pts.get(a as usize), pts.get(b as usize)) {
                (Some(a), Some(b)) => ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt(),
                _ => 0.0,
            }
        };
        for s in &p.segments {
            let region = regions.get(s.line as usize).copied().unwrap_or(Region::Footer);
            let (c, k) = match region {
                Region::OnPart(c) if s.on_part => (c as i32, KIND_LAYUP),
                Region::OnPart(c) | Region::Approach(c) | Region::Retract(c) => (c as i32, KIND_APPROACH),
                Region::Middle(c) => (c as i32, if s.rapid { KIND_RAPID } else { KIND_TRANSIT }),
                Region::Header | Region::Footer => (-1, if s.rapid { KIND_RAPID } else { KIND_TRANSIT }),
            };
            if k == KIND_LAYUP {
                if let Some(l) = lengths.get_mut(c as usize) {
                    *l += dist(s.from, s.to);
                }
            }
            from.push(s.from);
            to.push(s.to);
            course.push(c);
            line.push(s.line);
            kind.push(k);
            feed.push(if s.rapid || !s.feed.is_finite() { -1.0f32 } else { s.feed as f32 });
        }
        let courses: Vec<CourseInfo> = p
            .courses
            .iter()
            .enumerate()
            .map(|(i, c)| CourseInfo {
                ply: c.ply,
                number: c.number,
                position: i + 1,
                lines: [c.span.start + 1, c.span.end.max(c.span.start + 1)],
                contact_line: c.on_part.start + 1,
                length: lengths[i],
                original: order.and_then(|o| o.get(i)).map(|o| o.0),
                reversed: order.and_then(|o| o.get(i)).is_some_and(|o| o.1),
            })
            .collect();
        let plies = p
            .plies
            .iter()
            .map(|ply| PlyInfo {
                label: ply.label.clone(),
                name: towpath_nc::ply_name(ply),
                line: ply.line.map(|l| l + 1),
                courses: ply.courses.clone(),
                length: ply.courses.iter().map(|&c| lengths.get(c).copied().unwrap_or(0.0)).sum(),
            })
            .collect();
        let info = ProgramInfo { lines: p.lines.len(), segments: n, plies, courses };
        let mut blob = Blob::new();
        let flat: Vec<f32> = pts.iter().flat_map(|q| q.map(|v| v as f32)).collect();
        blob.f32("points", &flat);
        blob.u32("seg_from", &from);
        blob.u32("seg_to", &to);
        blob.i32("seg_course", &course);
        blob.u32("seg_line", &line);
        blob.f32("seg_feed", &feed);
        blob.u8("seg_kind", &kind);
        (info, blob)
    }
}

/// What the solve panel asks for.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct OptimizeRequest {
    /// Cost model: `auto` (cycle time when every axis of the machine has a velocity, else the
    /// weighted axis distance, as `towpath optimize` chooses), `axis`, `time` or `tool`.
    pub cost: String,
    /// Allow reversed courses.
    pub bidirectional: bool,
    /// `courses`, `sets` or `plies`.
    pub precedence: String,
    /// Keep each ply's course order.
    pub keep_ply_order: bool,
    /// Tow width, mm (course width = tow width × tows on).
    pub tow_width: Option<f64>,
    /// Fixed course width, mm.
    pub course_width: Option<f64>,
    /// `towpath` or one of the papers' solvers.
    pub solver: String,
    /// Solver time limit, s (default: the CLI's automatic limit).
    pub time_limit: Option<f64>,
    /// Work budget (deterministic with no time limit).
    pub iterations: Option<u64>,
    /// Seed.
    pub seed: u64,
    /// Solver threads (default 1, so that queued jobs share the machine fairly).
    pub threads: Option<usize>,
    /// Meshes of the cell (names of built-in or uploaded meshes): with them, transits are
    /// planned around the cell and every move is checked, as `towpath optimize --mold`.
    pub molds: Vec<String>,
    /// Clearance kept from the cell, mm (default 5; needs `molds`).
    pub clearance: Option<f64>,
}

impl Default for OptimizeRequest {
    fn default() -> Self {
        OptimizeRequest {
            cost: "auto".into(),
            bidirectional: false,
            precedence: "courses".into(),
            keep_ply_order: false,
            tow_width: None,
            course_width: None,
            solver: "towpath".into(),
            time_limit: None,
            iterations: None,
            seed: 1,
            threads: None,
            molds: Vec::new(),
            clearance: None,
        }
    }
}

struct Checked {
    afp: AfpOptions,
    solver: SolverName,
}

impl OptimizeRequest {
    fn check(&self) -> Result<Checked, ApiError> {
        // `auto` is resolved against the machine in `optimize`; the time cost stands in until then.
        let cost: CostKind = match self.cost.as_str() {
            "auto" => CostKind::Time,
            c => c.parse().map_err(|e: String| ApiError::bad(format!("cost: {e}")))?,
        };
        let precedence: PrecedenceRule =
            self.precedence.parse().map_err(|e: String| ApiError::bad(format!("precedence: {e}")))?;
        let solver: SolverName = self.solver.parse().map_err(|e| ApiError::bad(format!("solver: {e}")))?;
        let positive = |name: &str, w: f64| {
            if w.is_finite() && w > 0.0 {
                Ok(w)
            } else {
                Err(ApiError::bad(format!("{name} {w}: a width must be a number > 0")))
            }
        };
        let width = match (self.tow_width, self.course_width) {
            (Some(_), Some(_)) => return Err(ApiError::bad("give a tow width or a course width, not both")),
            (Some(w), None) => Some(Width::Tow(positive("tow_width", w)?)),
            (None, Some(w)) => Some(Width::Course(positive("course_width", w)?)),
            (None, None) => None,
        };
        if let Some(t) = self.time_limit {
            if !(t.is_finite() && t > 0.0) {
                return Err(ApiError::bad(format!("time_limit {t}: give a number of seconds > 0")));
            }
        }
        if self.threads == Some(0) {
            return Err(ApiError::bad("threads: at least 1"));
        }
        if let Some(c) = self.clearance {
            if self.molds.is_empty() {
                return Err(ApiError::bad("clearance: give the molds of the cell to keep it from"));
            }
            if !(c.is_finite() && c > 0.0 && c <= 1e4) {
                return Err(ApiError::bad(format!("clearance {c}: a distance in mm > 0 and at most 10000")));
            }
        }
        Ok(Checked {
            afp: AfpOptions {
                cost,
                bidirectional: self.bidirectional,
                precedence,
                keep_ply_order: self.keep_ply_order,
                width,
            },
            solver,
        })
    }

    /// Validates the request without running it.
    pub fn validate(&self) -> Result<(), ApiError> {
        self.check().map(|_| ())
    }
}

/// Progress of an optimization, as the job sees it.
#[derive(Clone, Debug, Default)]
pub struct SolveProgress {
    /// Solver cost of the original order.
    pub initial_cost: Option<f64>,
    /// Best solver cost so far.
    pub best_cost: Option<f64>,
    /// Kicks done.
    pub iterations: u64,
    /// Fraction of the budget.
    pub fraction: f64,
}

/// Hooks the job gives the optimization.
pub struct Hooks {
    /// Set to stop.
    pub cancel: Arc<AtomicBool>,
    /// Called with the phase name when it changes.
    pub phase: Arc<dyn Fn(&str) + Send + Sync>,
    /// Called as the solver progresses.
    pub progress: Arc<dyn Fn(&SolveProgress) + Send + Sync>,
}

/// Off-part and total motion before and after under one cost model.
#[derive(Clone, Debug, Serialize)]
pub struct Saving {
    /// `axis`, `time` or `tool`.
    pub cost: String,
    /// Unit.
    pub unit: String,
    /// Off-part before.
    pub off_before: f64,
    /// Off-part after.
    pub off_after: f64,
    /// Off-part saved, %.
    pub off_saved_percent: f64,
    /// Total before.
    pub total_before: f64,
    /// Total after.
    pub total_after: f64,
    /// Total saved, %.
    pub total_saved_percent: f64,
}

/// Saving per ply.
#[derive(Clone, Debug, Serialize)]
pub struct PlySaving {
    /// Ply label.
    pub ply: String,
    /// Courses.
    pub courses: usize,
    /// Off-part before, under the optimized cost.
    pub before: f64,
    /// After.
    pub after: f64,
    /// Saved, %.
    pub saved_percent: f64,
}

/// The outcome of an optimization.
pub struct OptimizeOutcome {
    /// The cost model optimized (`auto` resolved against the machine): `axis`, `time` or `tool`.
    pub cost: String,
    /// The optimized program.
    pub text: String,
    /// New order: (original course, reversed).
    pub order: Vec<(usize, bool)>,
    /// Report as JSON.
    pub report_json: String,
    /// Report as a page.
    pub report_html: String,
    /// Savings per cost model.
    pub savings: Vec<Saving>,
    /// Savings per ply under the optimized cost.
    pub per_ply: Vec<PlySaving>,
    /// The verifier accepted the output.
    pub verified: bool,
    /// The verifier's verdict in words.
    pub verdict: String,
    /// Nothing cheaper was found: the input is returned.
    pub fell_back: bool,
    /// Solver cost before and after.
    pub solver_cost: (f64, f64),
    /// Courses laid reversed.
    pub reversed: usize,
    /// The motion safety of the input and of the output, when the request gave a cell.
    pub safety: Option<towpath_nc::SafetyPair>,
}

/// Why an optimization stopped without a result.
pub enum Stopped {
    /// Cancelled by the user.
    Cancelled,
    /// Refused or failed.
    Failed(ApiError),
}

impl From<ApiError> for Stopped {
    fn from(e: ApiError) -> Self {
        Stopped::Failed(e)
    }
}

/// Optimizes a program with `towpath_nc::optimize` (the run `towpath optimize` makes: the
/// output never costs more than the input and never takes longer, and with a cell every transit
/// is planned around it and the output is refused unless it is safe).
pub fn optimize(
    file: &str,
    text: &str,
    machine: &Machine,
    dialect: &Dialect,
    req: &OptimizeRequest,
    safety: Option<Safety>,
    hooks: &Hooks,
) -> Result<OptimizeOutcome, Stopped> {
    let mut checked = req.check()?;
    if req.cost == "auto" {
        checked.afp.cost = towpath_nc::default_cost(machine);
    }
    let time_limit = match (req.time_limit, req.iterations) {
        (Some(t), _) => Some(Duration::from_secs_f64(t)),
        (None, Some(_)) => None,
        // As `towpath optimize`: the course count by the dialect's contact code.
        (None, None) => Some(towpath_nc::auto_time_limit(if dialect.contact_on.is_empty() {
            1000
        } else {
            text.lines().filter(|l| l.contains(dialect.contact_on.as_str())).count().max(1)
        })),
    };
    // The input's route cost arrives with the solving stage; progress reports it beside the best.
    let initial: Arc<Mutex<Option<f64>>> = Arc::new(Mutex::new(None));
    let stage: towpath_nc::StageFn = {
        let (initial, progress, phase) = (initial.clone(), hooks.progress.clone(), hooks.phase.clone());
        Arc::new(move |s: Stage| {
            phase(s.label());
            if let Stage::Solving { initial_cost } = s {
                *initial.lock().unwrap_or_else(|e| e.into_inner()) = initial_cost;
                progress(&SolveProgress { initial_cost, best_cost: initial_cost, iterations: 0, fraction: 0.0 });
            }
        })
    };
    let progress: towpath_seq::ProgressFn = {
        let (initial, cb) = (initial.clone(), hooks.progress.clone());
        Arc::new(move |p: &towpath_seq::Progress| {
            cb(&SolveProgress {
                initial_cost: *initial.lock().unwrap_or_else(|e| e.into_inner()),
                best_cost: Some(p.best_cost),
                iterations: p.iterations,
                fraction: p.fraction,
            })
        })
    };
    let opts = OptimizeOptions {
        afp: checked.afp.clone(),
        time_limit,
        iterations: req.iterations,
        seed: req.seed,
        threads: req.threads.unwrap_or(1),
        progress: Some(progress),
        solver: checked.solver,
        baselines: towpath_nc::BaselineParams::default(),
        safety,
        cancel: Some(hooks.cancel.clone()),
        stage: Some(stage),
    };
    let o = towpath_nc::optimize(text, machine, dialect, &opts).map_err(|e| match e {
        NcError::Cancelled => Stopped::Cancelled,
        e => Stopped::Failed(program_error(file, e)),
    })?;
    if hooks.cancel.load(Ordering::Relaxed) {
        return Err(Stopped::Cancelled);
    }
    (hooks.progress)(&SolveProgress {
        initial_cost: *initial.lock().unwrap_or_else(|e| e.into_inner()),
        best_cost: Some(o.solver.cost),
        iterations: o.solver.iterations,
        fraction: 1.0,
    });
    let report = Report::new(file, machine, &o, &checked.afp);
    let report_json = serde_json::to_string_pretty(&report).map_err(|e| ApiError::Internal(e.to_string()))?;
    let report_html = report.to_html(&o, &o.output, machine);
    let savings = report
        .totals
        .iter()
        .map(|t| Saving {
            cost: t.kind.name().into(),
            unit: t.unit.into(),
            off_before: t.off_before,
            off_after: t.off_after,
            off_saved_percent: t.off_saved_percent,
            total_before: t.total_before,
            total_after: t.total_after,
            total_saved_percent: t.total_saved_percent,
        })
        .collect();
    let per_ply = report
        .per_ply
        .iter()
        .map(|g| {
            let c = g.off_part.iter().find(|c| c.kind == checked.afp.cost).or(g.off_part.first());
            PlySaving {
                ply: g.label.clone(),
                courses: g.courses,
                before: c.map_or(0.0, |c| c.before),
                after: c.map_or(0.0, |c| c.after),
                saved_percent: c.map_or(0.0, |c| c.saved_percent),
            }
        })
        .collect();
    let verdict = format!(
        "verified: {} courses, the same on-part motion{}, precedence kept",
        o.verification.courses,
        if o.verification.reversed > 0 {
            format!(" ({} laid in reverse, checked point by point)", o.verification.reversed)
        } else {
            String::new()
        }
    );
    Ok(OptimizeOutcome {
        cost: checked.afp.cost.name().to_string(),
        order: o.order.iter().map(|p| (p.course, p.reversed)).collect(),
        reversed: o.verification.reversed,
        text: o.text,
        report_json,
        report_html,
        savings,
        per_ply,
        verified: report.verified,
        verdict,
        fell_back: o.fell_back,
        solver_cost: (o.solver.initial_cost, o.solver.cost),
        safety: o.safety,
    })
}

/// Verifies an optimized program against its original (the same check as `towpath verify`,
/// with the dialect's width and course-level precedence); the verdict in words.
pub fn verify(original: &str, optimized: &str, machine: &Machine, dialect: &Dialect) -> Result<String, ApiError> {
    let opts = towpath_nc::VerifyOptions::default();
    towpath_nc::verify(original, optimized, machine, dialect, &opts)
        .map(|v| format!("verified: {} courses", v.courses))
        .map_err(|e| ApiError::bad(e.to_string()))
}
