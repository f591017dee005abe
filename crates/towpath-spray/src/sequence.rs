//! One robot path: every pass is a task with two directions (Tewolde & Sheng 2008 §III-C, the
//! open rural postman problem with each pass as a required edge and direct moves between their
//! ends), sequenced as an open path from an optional home position by towpath's solver or the
//! paper's own GA and ant colony (`towpath-baselines`).
//!
//! **Pricing.** A transit's cost is the length of the move as it will be written ([`Transit`]):
//! straight when clear, longer when lifted. Checking clearance for every pair of pass ends would
//! cost too much, so transits are priced lazily: the cost model answers the straight-line
//! distance (a lower bound) unless the pair's lifted length is known; after each solve the
//! route's transits are computed, any lifted one is added to the known lengths, and the solver
//! runs again from the route found, until the route's every transit is priced as written (at
//! most [`MAX_ROUNDS`] rounds). The answer's cost is then exactly the written path length.
//!
//! Mode costs are the passes' spray lengths, so a route's cost is its full path length as the
//! paper's tour length (TL) is; travel is the cost minus the spray length.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::time::Duration;

use glam::DVec3;
use rayon::prelude::*;
use towpath_baselines::{solve_with, BaselineParams, SolverName};
use towpath_seq::{solve_reversible, CostModel, End, Mode, Problem, SolveOptions, StateId, Step};

use crate::error::SprayError;
use crate::passes::Pass;
use crate::transit::{Clearance, Transit};

/// Most solve rounds of the lazy pricing.
pub const MAX_ROUNDS: usize = 6;
/// Default work budget per pass (improvement kicks of towpath's solver).
pub const KICKS_PER_PASS: u64 = 15;
/// Smallest default work budget.
pub const MIN_KICKS: u64 = 100;
/// The solver stops when this many twentieths of its budget in a row found nothing better
/// (and never before as many kicks again as the best route took to find).
pub const STALL_EPOCHS: u32 = 3;
/// Up to this many pairs of pass ends on different patches, every such transit is priced as
/// written before the first solve (in parallel), so the solver sees the lifts from the start.
pub const EAGER_PAIRS: usize = 20_000;

/// How to sequence.
#[derive(Debug, Clone)]
pub struct SeqOptions {
    /// The solver.
    pub solver: SolverName,
    /// Parameters of the papers' solvers.
    pub params: BaselineParams,
    /// Time limit of the first round (later rounds get a quarter).
    pub time_limit: Option<Duration>,
    /// Work budget per round (the solver's improvement kicks); `None`: [`KICKS_PER_PASS`] per
    /// pass, at least [`MIN_KICKS`]. The answer depends only on the input, the seed and the
    /// thread count when the time limit does not end the search first.
    pub iterations: Option<u64>,
    /// Random seed.
    pub seed: u64,
    /// Solver threads.
    pub threads: usize,
}

impl Default for SeqOptions {
    fn default() -> Self {
        SeqOptions {
            solver: SolverName::Towpath,
            params: BaselineParams::default(),
            time_limit: Some(Duration::from_secs(1)),
            iterations: None,
            seed: 1,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

#[derive(Default)]
struct PairHasher(u64);
impl Hasher for PairHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (x ^ (x >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    }
}
type Known = HashMap<u64, f64, BuildHasherDefault<PairHasher>>;

fn key(a: u32, b: u32) -> u64 {
    let (x, y) = if a < b { (a, b) } else { (b, a) };
    ((x as u64) << 32) | y as u64
}

/// Transit lengths between pass ends: known lifted lengths, else the straight distance.
#[derive(Clone)]
pub struct TransitCost {
    positions: Vec<DVec3>,
    known: Known,
}

impl CostModel for TransitCost {
    fn num_states(&self) -> usize {
        self.positions.len()
    }
    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> f64 {
        if !self.known.is_empty() {
            if let Some(&c) = self.known.get(&key(from.0, to.0)) {
                return c;
            }
        }
        self.positions[from.index()].distance(self.positions[to.index()])
    }
    fn is_symmetric(&self) -> bool {
        true
    }
    fn position(&self, s: StateId) -> Option<[f64; 3]> {
        self.positions.get(s.index()).map(|p| p.to_array())
    }
}

/// A sequenced path: the order, the transits, what it cost.
#[derive(Debug, Clone)]
pub struct Sequenced {
    /// Passes in order with their direction (mode 0 as planned, 1 reversed).
    pub steps: Vec<Step>,
    /// The transit before each step (from home, or from the previous pass); `None` before the
    /// first pass when there is no home.
    pub transits: Vec<Option<Transit>>,
    /// Total travel (mm).
    pub travel: f64,
    /// Solve rounds of the lazy pricing.
    pub rounds: usize,
    /// Solver wall time summed over rounds (s).
    pub solver_seconds: f64,
    /// Transits that had to lift.
    pub lifted: usize,
    /// Transits whose every move could not be checked clear.
    pub unchecked: usize,
}

/// States: pass p starts at 2p and ends at 2p+1; home (if any) is 2n.
fn state_pose(passes: &[Pass], s: u32) -> (DVec3, DVec3) {
    let p = &passes[(s / 2) as usize];
    let i = if s % 2 == 0 { 0 } else { p.positions.len() - 1 };
    (p.positions[i], -p.axes[i])
}

/// Orders and orients the passes (see the module docs).
pub fn sequence(
    passes: &[Pass],
    home: Option<DVec3>,
    clearance: &Clearance,
    opts: &SeqOptions,
) -> Result<Sequenced, SprayError> {
    let n = passes.len();
    if n == 0 {
        return Ok(Sequenced {
            steps: Vec::new(),
            transits: Vec::new(),
            travel: 0.0,
            rounds: 0,
            solver_seconds: 0.0,
            lifted: 0,
            unchecked: 0,
        });
    }
    let mut positions: Vec<DVec3> = (0..2 * n as u32).map(|s| state_pose(passes, s).0).collect();
    let home_state = home.map(|h| {
        positions.push(h);
        (2 * n) as u32
    });
    // Normal at a state (pointing away from the part); home: towards the first pass.
    let normal_of = |s: u32| -> DVec3 {
        if Some(s) == home_state {
            DVec3::ZERO
        } else {
            state_pose(passes, s).1
        }
    };
    let spray_len: f64 = passes.iter().map(|p| p.length).sum();
    let mut known = Known::default();
    let mut transit_cache: HashMap<(u32, u32), Transit> = HashMap::new();
    // Small plans: price every transit between ends on different patches now (within a patch
    // the moves are short and almost always straight; the lazy rounds catch the rest).
    let ends = 2 * n as u32;
    let cross = |a: u32, b: u32| passes[(a / 2) as usize].patch != passes[(b / 2) as usize].patch;
    let count: usize = {
        let mut per_patch: HashMap<u32, usize> = HashMap::new();
        for p in passes {
            *per_patch.entry(p.patch).or_insert(0) += 2;
        }
        let same: usize = per_patch.values().map(|c| c * c).sum();
        ((2 * n) * (2 * n) - same) / 2
    };
    if count <= EAGER_PAIRS {
        let pairs: Vec<(u32, u32)> =
            (0..ends).flat_map(|a| (a + 1..ends).filter(move |&b| cross(a, b)).map(move |b| (a, b))).collect();
        let priced: Vec<((u32, u32), Transit)> = pairs
            .par_iter()
            .map(|&(a, b)| {
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                ((a, b), clearance.transit(pa, normal_of(a), pb, normal_of(b)))
            })
            .collect();
        for ((a, b), t) in priced {
            let straight = positions[a as usize].distance(positions[b as usize]);
            if t.length > straight * (1.0 + 1e-12) + 1e-9 {
                known.insert(key(a, b), t.length);
            }
        }
    }
    let mut initial: Option<Vec<Step>> = None;
    let mut best: Option<(f64, Vec<Step>)> = None;
    let mut rounds = 0;
    let mut solver_seconds = 0.0;
    let steps = loop {
        rounds += 1;
        let cost = TransitCost { positions: positions.clone(), known: known.clone() };
        let mut b = Problem::builder(cost);
        for p in 0..n as u32 {
            let (s, e) = (StateId(2 * p), StateId(2 * p + 1));
            let len = passes[p as usize].length;
            b.task(vec![Mode { entry: s, exit: e, cost: len }, Mode { entry: e, exit: s, cost: len }]);
        }
        if let Some(h) = home_state {
            b.start(StateId(h));
        }
        b.end(End::Free);
        let problem = b.build().map_err(|e| SprayError::Sequencing(e.to_string()))?;
        let so = SolveOptions {
            time_limit: opts.time_limit.map(|t| if rounds == 1 { t } else { t / 4 }),
            iterations: Some(opts.iterations.unwrap_or((n as u64 * KICKS_PER_PASS).max(MIN_KICKS))),
            seed: opts.seed,
            threads: opts.threads.max(1),
            initial: initial.clone(),
            stall_epochs: Some(STALL_EPOCHS),
            ..SolveOptions::default()
        };
        let report = match opts.solver {
            SolverName::Towpath => solve_reversible(&problem, &so).map_err(|e| e.to_string()),
            s => solve_with(s, &problem, &so, &opts.params).map_err(|e| e.to_string()),
        }
        .map_err(SprayError::Sequencing)?;
        solver_seconds += report.elapsed.as_secs_f64();
        let steps = report.solution.steps;
        // Price the route's transits as written.
        let pairs = route_pairs(&steps, home_state);
        let todo: Vec<(u32, u32)> =
            pairs.iter().flatten().copied().filter(|pr| !transit_cache.contains_key(pr)).collect();
        let computed: Vec<((u32, u32), Transit)> = todo
            .par_iter()
            .map(|&(a, bb)| {
                let (pa, pb) = (positions[a as usize], positions[bb as usize]);
                let (na, nb) = (normal_of(a), normal_of(bb));
                let na = if na == DVec3::ZERO { (pa - pb).try_normalize().unwrap_or(DVec3::Z) } else { na };
                ((a, bb), clearance.transit(pa, na, pb, nb))
            })
            .collect();
        let mut added = false;
        for (pr, t) in computed {
            let straight = positions[pr.0 as usize].distance(positions[pr.1 as usize]);
            if t.length > straight * (1.0 + 1e-12) + 1e-9 && !known.contains_key(&key(pr.0, pr.1)) {
                known.insert(key(pr.0, pr.1), t.length);
                added = true;
            }
            transit_cache.insert(pr, t);
        }
        // The route's length as written (every transit of it is now priced).
        let written: f64 = pairs.iter().flatten().map(|pr| transit_cache.get(pr).map_or(0.0, |t| t.length)).sum();
        if best.as_ref().is_none_or(|(c, _)| written < *c) {
            best = Some((written, steps.clone()));
        }
        if !added || rounds >= MAX_ROUNDS {
            // The last round may have found lifts it could not yet price: keep the route that is
            // shortest as written.
            break best.map_or(steps, |(_, s)| s);
        }
        initial = Some(steps);
    };
    let pairs = route_pairs(&steps, home_state);
    let mut transits = Vec::with_capacity(steps.len());
    let (mut travel, mut lifted, mut unchecked) = (0.0, 0, 0);
    for pr in pairs {
        let t = pr.map(|pr| {
            transit_cache.get(&pr).cloned().unwrap_or_else(|| {
                let (pa, pb) = (positions[pr.0 as usize], positions[pr.1 as usize]);
                clearance.transit(pa, normal_of(pr.0), pb, normal_of(pr.1))
            })
        });
        if let Some(t) = &t {
            travel += t.length;
            lifted += usize::from(!t.via.is_empty());
            unchecked += usize::from(!t.clear);
        }
        transits.push(t);
    }
    debug_assert!(spray_len >= 0.0);
    Ok(Sequenced { steps, transits, travel, rounds, solver_seconds, lifted, unchecked })
}

/// The (from-state, to-state) pair of the transit before each step.
fn route_pairs(steps: &[Step], home: Option<u32>) -> Vec<Option<(u32, u32)>> {
    let mut out = Vec::with_capacity(steps.len());
    let mut cur = home;
    for s in steps {
        let t = s.task.0;
        let (entry, exit) = if s.mode == 0 { (2 * t, 2 * t + 1) } else { (2 * t + 1, 2 * t) };
        out.push(cur.map(|c| (c, entry)));
        cur = Some(exit);
    }
    out
}
