//! The ant colony algorithm of seed 004 §V (Tewolde & Sheng 2008), an ant system after Dorigo,
//! Maniezzo & Colorni [21].
//!
//! - **Graph** (§V-A): the complete graph on the end points of the required edges, weighted by
//!   shortest-path distances. In towpath's model these are the *states* the tasks' modes enter
//!   and leave; the trail `TV` lives on pairs of states.
//! - **Ants**: "a number of ants are created ... starting from each vertex of the required
//!   edges". An ant placed at an end point of a required edge begins by traversing it (the
//!   task done in the mode that enters there). ACO1 deploys one ant per required edge, ACO2 two,
//!   one at each end (Table I). The paper does not say at which end ACO1's ant starts; we draw
//!   it at random each cycle, so that every end point can begin a route (a fixed end would make
//!   routes that begin at the other end unreachable).
//! - **Moves** (eq. 3): from its current vertex `x` an ant may go to any end point `y` of a
//!   required edge not yet visited (then traverses that edge); it picks `y` with probability
//!   `TV_xy^α · η_xy^β / Σ_w TV_xw^α · η_xw^β`, visibility `η_xy = 1 / d_xy` (shortest
//!   distance). When some legal `y` is at distance 0 its visibility is infinite: the limit of
//!   eq. 3 then chooses among the zero-distance moves only, in proportion to their trails.
//! - **Trail update** (eqs. 1–2), after every cycle: `ΔTV_xy = Σ_i Q / TL[i]` over the ants
//!   `i` whose route uses the connection `x → y`, then `TV_xy ← ρ · TV_xy + ΔTV_xy`. The
//!   paper's graph is undirected, so on a symmetric cost model a deposit on `x → y` also goes to
//!   `y → x`; on an asymmetric one trails are directed. Connections only: the traversal of a
//!   required edge itself is forced, so a trail on it would never be read.
//! - **Settings** (§VI-B): α = 1, β = 5, ρ = 0.5, Q = 100, ten cycles (Table I, II).
//! - **Initial trail**: the paper does not give it. We use `Q / L_greedy`, the deposit one ant
//!   would make on the route that always takes the most visible move, so initial and deposited
//!   trails are on one scale whatever the unit of length.
//!
//! With a fixed start state, every route begins there and the ant's starting edge is its first
//! task. On problems with precedence, consecutive groups or pins (the paper has none) an ant
//! only considers the tasks that may come next; an ant whose starting task may not come first
//! starts from the start state (or, without one, at a random allowed task) instead.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_seq::{Clock, CostModel, Problem, SolveOptions, SolveReport, StateId, Step, TaskId};

use crate::common::finish;
use crate::order::OrderBuilder;
use crate::BaselineError;

/// Largest number of distinct states the ant system keeps trails for (two dense
/// states × states matrices).
pub const ACO_MAX_STATES: usize = 2048;

/// Most ants per required edge (the paper has one or two).
pub const ACO_MAX_ANTS_PER_TASK: usize = 64;

/// Most moves one ant may weigh on its walk (tasks × (tasks + modes)): every walk is done in
/// full, the first one even after the time limit.
pub const ACO_MAX_WALK: u64 = 100_000_000;

/// Parameters of the ant system (seed 004 §V, §VI-B).
#[derive(Clone, Debug, PartialEq)]
pub struct AcoParams {
    /// α: weight of the trail (paper: 1).
    pub alpha: f64,
    /// β: weight of the visibility (paper: 5).
    pub beta: f64,
    /// ρ: trail persistence per cycle (paper: 0.5).
    pub rho: f64,
    /// Q: deposit constant (paper: 100).
    pub q: f64,
    /// Cycles (paper: 10 for Tables I–II; 100 in its first runs).
    pub cycles: usize,
    /// Ants per required edge: 1 (ACO1) or 2 (ACO2).
    pub ants_per_task: usize,
    /// Initial trail; `None` for `Q / L_greedy` (see the module docs).
    pub initial_trail: Option<f64>,
}

impl Default for AcoParams {
    /// The paper's settings with one ant per required edge (ACO1).
    fn default() -> Self {
        AcoParams { alpha: 1.0, beta: 5.0, rho: 0.5, q: 100.0, cycles: 10, ants_per_task: 1, initial_trail: None }
    }
}

impl AcoParams {
    /// ACO1 of Table I: one ant per required edge.
    pub fn aco1() -> Self {
        AcoParams::default()
    }

    /// ACO2 of Table I: two ants per required edge, one at each end.
    pub fn aco2() -> Self {
        AcoParams { ants_per_task: 2, ..AcoParams::default() }
    }

    fn validate(&self) -> Result<(), BaselineError> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(ok(self.alpha) && ok(self.beta) && ok(self.q) && ok(self.rho) && self.rho <= 1.0) {
            return Err(BaselineError::BadParams(format!(
                "ACO needs α, β, Q ≥ 0 and 0 ≤ ρ ≤ 1 (got α {}, β {}, Q {}, ρ {})",
                self.alpha, self.beta, self.q, self.rho
            )));
        }
        if self.ants_per_task == 0 {
            return Err(BaselineError::BadParams("ACO needs at least one ant per required edge".into()));
        }
        if self.ants_per_task > ACO_MAX_ANTS_PER_TASK {
            return Err(BaselineError::TooMuch {
                param: "aco.ants_per_task",
                message: format!(
                    "{} ants per required edge asked for; the ant system deploys at most {ACO_MAX_ANTS_PER_TASK}",
                    self.ants_per_task
                ),
            });
        }
        if let Some(t) = self.initial_trail {
            if !(t.is_finite() && t > 0.0) {
                return Err(BaselineError::BadParams(format!("ACO initial trail must be > 0, not {t}")));
            }
        }
        Ok(())
    }
}

/// Applies eqs. 1–2 to a dense `s × s` trail matrix: every route deposits `Q / TL` on each
/// connection it uses (and on the reverse pair if `undirected`), then
/// `TV ← ρ · TV + ΔTV`. `routes` holds each ant's connections (as compact state pairs) and
/// tour length.
pub fn update_trails(tv: &mut [f64], s: usize, routes: &[(Vec<(u32, u32)>, f64)], rho: f64, q: f64, undirected: bool) {
    let mut delta = vec![0.0; tv.len()];
    for (conns, tl) in routes {
        if !(tl.is_finite() && *tl > 0.0) {
            continue;
        }
        let d = q / tl;
        for &(x, y) in conns {
            delta[x as usize * s + y as usize] += d;
            if undirected && x != y {
                delta[y as usize * s + x as usize] += d;
            }
        }
    }
    for (t, d) in tv.iter_mut().zip(delta) {
        *t = rho * *t + d;
    }
}

/// Compact numbering of the states the problem uses.
struct States {
    index: std::collections::HashMap<u32, u32>,
    list: Vec<StateId>,
}

impl States {
    fn new<C: CostModel>(p: &Problem<C>) -> Self {
        let mut s = States { index: Default::default(), list: Vec::new() };
        if let Some(st) = p.start() {
            s.add(st);
        }
        for t in p.tasks() {
            for m in p.modes(t) {
                s.add(m.entry);
                s.add(m.exit);
            }
        }
        s
    }
    fn add(&mut self, st: StateId) {
        let n = self.list.len() as u32;
        if let std::collections::hash_map::Entry::Vacant(v) = self.index.entry(st.0) {
            v.insert(n);
            self.list.push(st);
        }
    }
    fn of(&self, st: StateId) -> u32 {
        self.index.get(&st.0).copied().unwrap_or(0)
    }
}

struct Colony<'p, C> {
    p: &'p Problem<C>,
    s: usize,
    /// Compact entry/exit state of each (task, mode), indexed by `mode_base[task] + mode`.
    entry: Vec<u32>,
    exit: Vec<u32>,
    mode_base: Vec<usize>,
    /// `η^β` between compact states (infinite for distance 0, 0 for forbidden).
    vis: Vec<f64>,
    start: Option<u32>,
    alpha: f64,
    undirected: bool,
}

impl<C: CostModel> Colony<'_, C> {
    /// One ant's route from `start` (a task and mode to begin with, if it may come first).
    /// Returns the steps, the connections used, and the route cost.
    fn walk(
        &self,
        tv: &[f64],
        start: Option<(u32, u32)>,
        rng: &mut Pcg64Mcg,
        greedy: bool,
    ) -> (Vec<Step>, Vec<(u32, u32)>) {
        let p = self.p;
        let n = p.num_tasks();
        let mut b = OrderBuilder::new(p);
        let mut steps = Vec::with_capacity(n);
        let mut conns = Vec::with_capacity(n);
        let mut cur: Option<u32> = self.start;
        if let Some((t, m)) = start.filter(|&(t, _)| b.allowed(t)) {
            let k = self.mode_base[t as usize] + m as usize;
            if let Some(c) = cur {
                conns.push((c, self.entry[k]));
            }
            b.take(t);
            steps.push(Step { task: TaskId(t), mode: m });
            cur = Some(self.exit[k]);
        }
        let mut cand: Vec<(u32, u32, f64)> = Vec::new();
        while steps.len() < n {
            cand.clear();
            let mut zero = false;
            for t in 0..n as u32 {
                if !b.allowed(t) {
                    continue;
                }
                for m in 0..p.modes(TaskId(t)).len() as u32 {
                    let k = self.mode_base[t as usize] + m as usize;
                    let w = match cur {
                        None => 1.0,
                        Some(x) => {
                            let y = self.entry[k] as usize;
                            let v = self.vis[x as usize * self.s + y];
                            let trail = tv[x as usize * self.s + y];
                            let trail = if self.alpha == 1.0 { trail } else { trail.powf(self.alpha) };
                            if v.is_infinite() {
                                if !zero {
                                    zero = true;
                                    cand.clear();
                                }
                                trail
                            } else if zero {
                                continue;
                            } else {
                                trail * v
                            }
                        }
                    };
                    cand.push((t, m, w));
                }
            }
            let Some(&(t0, m0, _)) = cand.first() else {
                break; // nothing may come next: the constraints cannot be met
            };
            let (t, m) = if greedy {
                let (t, m, _) =
                    cand.iter().fold((t0, m0, f64::NEG_INFINITY), |a, &(t, m, w)| if w > a.2 { (t, m, w) } else { a });
                (t, m)
            } else {
                let total: f64 = cand.iter().map(|c| c.2).sum();
                if total > 0.0 && total.is_finite() {
                    let mut r = rng.gen::<f64>() * total;
                    let mut pick = (cand[cand.len() - 1].0, cand[cand.len() - 1].1);
                    for &(t, m, w) in &cand {
                        if r < w {
                            pick = (t, m);
                            break;
                        }
                        r -= w;
                    }
                    pick
                } else {
                    let (t, m, _) = cand[rng.gen_range(0..cand.len())];
                    (t, m)
                }
            };
            let k = self.mode_base[t as usize] + m as usize;
            if let Some(c) = cur {
                conns.push((c, self.entry[k]));
            }
            b.take(t);
            steps.push(Step { task: TaskId(t), mode: m });
            cur = Some(self.exit[k]);
        }
        (steps, conns)
    }
}

/// Runs the ant system. Deterministic for a given `opts.seed` unless the time limit or cancel
/// flag stops it early.
pub fn solve_aco<C: CostModel>(
    p: &Problem<C>,
    params: &AcoParams,
    opts: &SolveOptions,
) -> Result<SolveReport, BaselineError> {
    params.validate()?;
    let clock = Clock::for_options(opts);
    let n = p.num_tasks();
    let states = States::new(p);
    let s = states.list.len();
    if s > ACO_MAX_STATES {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Aco1,
            what: format!("{s} distinct states; the ant system keeps dense trails for at most {ACO_MAX_STATES}"),
        });
    }
    let modes: usize = p.tasks().map(|t| p.modes(t).len()).sum();
    let walk = n as u64 * (n + modes) as u64;
    if walk > ACO_MAX_WALK {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Aco1,
            what: format!(
                "{n} tasks with {modes} modes: one ant weighs {walk} moves on its walk, the ant system at most \
                 {ACO_MAX_WALK}"
            ),
        });
    }
    let cm = p.cost_model();
    let mut vis = vec![0.0; s * s];
    for i in 0..s {
        for j in 0..s {
            let d = cm.cost(states.list[i], states.list[j]);
            vis[i * s + j] = if d.is_nan() || d.is_infinite() {
                0.0
            } else if d <= 0.0 {
                f64::INFINITY
            } else {
                (1.0 / d).powf(params.beta)
            };
        }
    }
    let mut entry = Vec::new();
    let mut exit = Vec::new();
    let mut mode_base = Vec::with_capacity(n);
    for t in p.tasks() {
        mode_base.push(entry.len());
        for m in p.modes(t) {
            entry.push(states.of(m.entry));
            exit.push(states.of(m.exit));
        }
    }
    let colony = Colony {
        p,
        s,
        entry,
        exit,
        mode_base,
        vis,
        start: p.start().map(|st| states.of(st)),
        alpha: params.alpha,
        undirected: cm.is_symmetric(),
    };
    let mut rng = Pcg64Mcg::seed_from_u64(opts.seed ^ 0xAC0_5EED_0004);
    let route_cost = |steps: &[Step]| {
        if steps.len() == n {
            let c = p.route_cost(steps);
            if c.is_nan() {
                f64::INFINITY
            } else {
                c
            }
        } else {
            f64::INFINITY
        }
    };
    // Initial trail: Q over the greedy route's length (uniform trails, most visible move).
    let ones = vec![1.0; s * s];
    let (greedy, _) = colony.walk(&ones, None, &mut rng, true);
    let greedy_cost = route_cost(&greedy);
    let tv0 = params.initial_trail.unwrap_or(if greedy_cost.is_finite() && greedy_cost > 0.0 {
        params.q.max(f64::MIN_POSITIVE) / greedy_cost
    } else {
        1.0
    });
    let mut tv = vec![tv0; s * s];
    // Ants: `ants_per_task` per task. With at least as many ants as the task has modes, ant j
    // starts in mode j mod k (ACO2: one at each end); with fewer, each cycle draws distinct
    // starting modes at random (ACO1: one end, either one).
    let mut ants: Vec<(u32, u32)> = Vec::with_capacity(n * params.ants_per_task);
    let place_ants = |ants: &mut Vec<(u32, u32)>, rng: &mut Pcg64Mcg| {
        ants.clear();
        for t in p.tasks() {
            let k = p.modes(t).len() as u32;
            let a = params.ants_per_task as u32;
            if a >= k {
                ants.extend((0..a).map(|j| (t.0, j % k)));
            } else {
                let mut modes: Vec<u32> = (0..k).collect();
                for j in 0..a as usize {
                    let pick = rng.gen_range(j..k as usize);
                    modes.swap(j, pick);
                    ants.push((t.0, modes[j]));
                }
            }
        }
    };
    let mut best: (Vec<Step>, f64) = (greedy, greedy_cost);
    let mut first_cost = f64::INFINITY;
    let mut cycles = 0u64;
    let mut routes: Vec<(Vec<(u32, u32)>, f64)> = Vec::with_capacity(ants.len());
    for _ in 0..params.cycles {
        if clock.expired() {
            break;
        }
        cycles += 1;
        routes.clear();
        place_ants(&mut ants, &mut rng);
        let mut cycle_best = f64::INFINITY;
        for &(t, m) in &ants {
            if clock.expired() {
                break;
            }
            let (steps, conns) = colony.walk(&tv, Some((t, m)), &mut rng, false);
            let tl = route_cost(&steps);
            cycle_best = cycle_best.min(tl);
            if tl < best.1 {
                best = (steps, tl);
            }
            routes.push((conns, tl));
        }
        if cycles == 1 {
            first_cost = cycle_best;
        }
        update_trails(&mut tv, s, &routes, params.rho, params.q, colony.undirected);
    }
    if cycles == 0 {
        first_cost = best.1;
    }
    finish(p, best.0, opts, &clock, first_cost, cycles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trail_update_follows_eqs_1_and_2() {
        // three states; two ants: 0→1→2 (TL 4) and 0→2 (TL 10)
        let mut tv = vec![2.0; 9];
        let routes = vec![(vec![(0, 1), (1, 2)], 4.0), (vec![(0, 2)], 10.0)];
        update_trails(&mut tv, 3, &routes, 0.5, 100.0, false);
        let expect = |x: usize, y: usize| {
            let mut d = 0.0;
            if (x, y) == (0, 1) || (x, y) == (1, 2) {
                d += 100.0 / 4.0;
            }
            if (x, y) == (0, 2) {
                d += 100.0 / 10.0;
            }
            0.5 * 2.0 + d
        };
        for x in 0..3 {
            for y in 0..3 {
                assert_eq!(tv[x * 3 + y], expect(x, y), "({x},{y})");
            }
        }
        // undirected: the reverse pairs receive the same deposit
        let mut tv = vec![0.0; 9];
        update_trails(&mut tv, 3, &routes, 0.5, 100.0, true);
        assert_eq!(tv[3], 25.0);
        assert_eq!(tv[1], 25.0);
        assert_eq!(tv[6], 10.0);
        // an edge used by no ant only evaporates
        let mut tv = vec![8.0; 9];
        update_trails(&mut tv, 3, &[], 0.5, 100.0, true);
        assert!(tv.iter().all(|&t| t == 4.0));
    }
}
