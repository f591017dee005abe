//! The genetic algorithm of seed 004 §IV (Tewolde & Sheng 2008), as the paper describes it.
//!
//! - **Chromosome** (§IV-1): `P_i`, the order in which the required edges (tasks) are done, and
//!   `Ps_i`, a direction bit per position (1 = the edge's initially assigned direction, here
//!   mode 0; 0 = reversed, mode 1). The paper prints the two side by side (`P_i = 3 1 2 5 4 6`,
//!   `Ps_i = 0 0 1 0 1 0`); we read `Ps_i[k]` as the direction of the edge at position `k` of
//!   `P_i`. On tasks with more than two modes the "bit" is a mode index (taken modulo the
//!   task's number of modes) and flipping it means moving to the next mode.
//! - **Initial population**: random orders and random directions ("we assign the visiting
//!   directions ... arbitrarily").
//! - **Selection for crossover** (§IV-2): "five pairs of random samples of the whole
//!   population", keeping "the best pair ... based on their fitness"; we keep the pair with the
//!   smallest summed tour length.
//! - **Crossover** (§IV-2, Fig. 8): order crossover (OX) of Gen & Cheng [18] on `P_i`: a random
//!   block is copied from one parent in place, the other positions are filled left to right
//!   with the other parent's remaining tasks in its order; the ordinary crossover on `Ps_i`
//!   keeps the same block from one parent and takes the other positions from the other. Each
//!   crossover makes two children (parents' roles swapped). The crossover rate sets the number
//!   of children per generation: `x_rate · P_size` (§IV-4, `P_total = P_size + x_rate·P_size`).
//! - **Mutation** (§IV-3): reciprocal exchange on `P_i` (swap the tasks at two random
//!   positions), and on `Ps_i` swap two random bits and flip a third. Mutation changes an
//!   individual in place ("it does not generate a new offspring"); it is applied
//!   `m_rate · P_size` times per generation, each time to a randomly picked individual of the
//!   generation (parents and children).
//! - **Survival** (§IV-4): the best `P_size` of the `P_total` individuals go on.
//! - **Fitness**: the route's length (the problem's route cost).
//!
//! Settings (§VI-A): population 100, crossover rate 0.2, mutation rate 0.05 ("good
//! performance"); the GA column of Table I used 1000 generations and population 200
//! ([`GaParams::table_i`]). The best route seen in any generation is returned.
//!
//! **Behaviour.** With survival of the best and a handful of mutations per generation the
//! population soon fills with copies of one route: on a 10-edge instance of seed 004's shape
//! the best route of generation 100 is still the best at generation 50 000. The paper's note
//! that the GA "converges at the best solution with fewer than 100 generations" fits this; on
//! our generated instances its gap to the ant system grows faster with size than in Table I
//! (see `BENCHMARKS.md`). [`GaParams::bits_by_edge`] reads the direction bits per edge instead,
//! the other reading the text allows; it does slightly better on larger instances and is not
//! the default.
//!
//! On problems with precedence, consecutive groups or pinned tasks (the paper has none) the
//! order is decoded as a priority list: the next task is always the earliest one in `P_i` that
//! may come next.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_seq::{Clock, CostModel, Problem, SolveOptions, SolveReport, Step, TaskId};

use crate::common::finish;
use crate::order::OrderBuilder;
use crate::BaselineError;

/// Parameters of the GA (seed 004 §IV, §VI-A).
#[derive(Clone, Debug, PartialEq)]
pub struct GaParams {
    /// `P_size`: individuals kept each generation (paper: 100).
    pub population: usize,
    /// Generations to run (paper: 100 suffices for "reasonable sizes"; Table I used 1000).
    pub generations: usize,
    /// `x_rate`: children per generation as a fraction of `P_size` (paper: 0.2).
    pub crossover_rate: f64,
    /// `m_rate`: mutations per generation as a fraction of `P_size` (paper: 0.05).
    pub mutation_rate: f64,
    /// Random pairs sampled to pick parents (paper: 5).
    pub parent_pairs: usize,
    /// Read `Ps_i[k]` as the direction of required edge `k` rather than of the edge at position
    /// `k` of `P_i` (the paper's text allows both; default `false`, see the module docs).
    pub bits_by_edge: bool,
}

impl Default for GaParams {
    /// The settings of §VI-A: population 100, 100 generations, x = 0.2, m = 0.05.
    fn default() -> Self {
        GaParams {
            population: 100,
            generations: 100,
            crossover_rate: 0.2,
            mutation_rate: 0.05,
            parent_pairs: 5,
            bits_by_edge: false,
        }
    }
}

impl GaParams {
    /// The settings behind Table I's GA column: 1000 generations, population 200, x = 0.2,
    /// m = 0.05.
    pub fn table_i() -> Self {
        GaParams { population: 200, generations: 1000, ..GaParams::default() }
    }

    /// Checks the parameters, and the memory a population of individuals of `n` tasks takes.
    fn validate(&self, n: usize) -> Result<(), BaselineError> {
        if self.population < 2 {
            return Err(BaselineError::BadParams("GA population must be at least 2".into()));
        }
        for (name, v) in [("crossover rate", self.crossover_rate), ("mutation rate", self.mutation_rate)] {
            if !(v.is_finite() && (0.0..=GA_MAX_RATE).contains(&v)) {
                return Err(BaselineError::BadParams(format!(
                    "GA {name} must be a number from 0 to {GA_MAX_RATE} (a fraction of P_size per generation), not {v}"
                )));
            }
        }
        if self.parent_pairs == 0 {
            return Err(BaselineError::BadParams("GA needs at least one parent pair to sample".into()));
        }
        // P_total = P_size + x_rate · P_size individuals, each an order and its genes.
        let individual = INDIVIDUAL_BYTES + 8.0 * n as f64;
        let total = self.population as f64 * (1.0 + self.crossover_rate);
        let bytes = total * individual;
        if bytes > GA_MAX_BYTES as f64 {
            let most = (GA_MAX_BYTES as f64 / individual / (1.0 + self.crossover_rate)).floor().max(2.0);
            return Err(BaselineError::TooMuch {
                param: "ga.population",
                message: format!(
                    "a GA population of {} on {n} tasks keeps {total:.3e} individuals of {individual} bytes ({}); \
                     at most {} of memory, a population of up to {most:.0} here",
                    self.population,
                    human_bytes(bytes),
                    human_bytes(GA_MAX_BYTES as f64)
                ),
            });
        }
        Ok(())
    }
}

/// Most memory the GA's population may take.
pub const GA_MAX_BYTES: u64 = 1 << 30;

/// Largest crossover or mutation rate (children or mutations per generation, as a fraction of
/// `P_size`).
pub const GA_MAX_RATE: f64 = 100.0;

/// Most steps the first two chromosomes' decoding may take.
const GA_MAX_DECODE: u64 = 1_000_000_000;

/// Memory of an individual besides its `8 n` bytes of order and genes.
const INDIVIDUAL_BYTES: f64 = 64.0;

/// A byte count for messages: `2.1 TB`, `512 MB`.
pub(crate) fn human_bytes(b: f64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{v:.0} {}", units[k])
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// One individual: the order `P_i`, the per-position mode genes `Ps_i`, and its tour length.
#[derive(Clone, Debug)]
struct Individual {
    order: Vec<u32>,
    genes: Vec<u32>,
    cost: f64,
}

/// Order crossover (Gen & Cheng): the child keeps `keep[lo..hi]` in place; the other positions
/// are filled from left to right with the tasks of `other` not in that block, in `other`'s order.
pub fn order_crossover(keep: &[u32], other: &[u32], lo: usize, hi: usize) -> Vec<u32> {
    let n = keep.len();
    let mut in_block = vec![false; n];
    for &t in &keep[lo..hi] {
        in_block[t as usize] = true;
    }
    let mut rest = other.iter().copied().filter(|&t| !in_block[t as usize]);
    (0..n).map(|k| if (lo..hi).contains(&k) { keep[k] } else { rest.next().unwrap_or(u32::MAX) }).collect()
}

/// The ordinary crossover on the direction bits: `keep[lo..hi]` in place, the rest from `other`.
pub fn bit_crossover(keep: &[u32], other: &[u32], lo: usize, hi: usize) -> Vec<u32> {
    (0..keep.len()).map(|k| if (lo..hi).contains(&k) { keep[k] } else { other[k] }).collect()
}

/// The two mutations of §IV-3 on one individual: reciprocal exchange of two positions of the
/// order; on the genes, a swap of two positions and a flip of a third (`flip` maps a gene to its
/// flipped value).
fn mutate(ind: &mut Individual, rng: &mut Pcg64Mcg, flip: impl Fn(u32) -> u32) {
    let n = ind.order.len();
    if n >= 2 {
        let (i, j) = two_distinct(rng, n);
        ind.order.swap(i, j);
        let (i, j) = two_distinct(rng, n);
        ind.genes.swap(i, j);
    }
    if n >= 1 {
        let k = rng.gen_range(0..n);
        ind.genes[k] = flip(ind.genes[k]);
    }
}

fn two_distinct(rng: &mut Pcg64Mcg, n: usize) -> (usize, usize) {
    let i = rng.gen_range(0..n);
    let mut j = rng.gen_range(0..n - 1);
    if j >= i {
        j += 1;
    }
    (i, j)
}

/// Turns a chromosome into a feasible route (see the module docs for problems with precedence).
fn decode<C: CostModel>(p: &Problem<C>, order: &[u32], genes: &[u32], by_edge: bool, out: &mut Vec<Step>) {
    out.clear();
    let mode_of = |t: u32, g: u32| g % p.modes(TaskId(t)).len() as u32;
    let gene = |k: usize| if by_edge { genes[order[k] as usize] } else { genes[k] };
    let mut b = OrderBuilder::new(p);
    if b.is_free() {
        out.extend(order.iter().enumerate().map(|(k, &t)| Step { task: TaskId(t), mode: mode_of(t, gene(k)) }));
        return;
    }
    let n = order.len();
    let mut used = vec![false; n];
    while b.len() < n {
        let Some(k) = (0..n).find(|&k| !used[k] && b.allowed(order[k])) else {
            return; // no task may come next: the problem's constraints cannot be met
        };
        used[k] = true;
        b.take(order[k]);
        out.push(Step { task: TaskId(order[k]), mode: mode_of(order[k], gene(k)) });
    }
}

/// Runs the GA. Deterministic for a given `opts.seed` unless the time limit or cancel flag
/// stops it early.
pub fn solve_ga<C: CostModel>(
    p: &Problem<C>,
    params: &GaParams,
    opts: &SolveOptions,
) -> Result<SolveReport, BaselineError> {
    let n = p.num_tasks();
    params.validate(n)?;
    // Decoding a chromosome under precedence, groups or pins scans the order for each step;
    // the first two individuals are made whatever the time limit.
    if !OrderBuilder::new(p).is_free() && 2 * (n as u64).pow(2) > GA_MAX_DECODE {
        return Err(BaselineError::TooLarge {
            solver: crate::SolverName::Ga,
            what: format!(
                "{n} tasks under precedence, groups or pins: decoding a chromosome weighs n² = {} steps, the GA \
                 at most {}",
                (n as u64).pow(2),
                GA_MAX_DECODE / 2
            ),
        });
    }
    let clock = Clock::for_options(opts);
    let max_modes = p.max_modes().max(1) as u32;
    let flip = |g: u32| (g + 1) % max_modes;
    let mut rng = Pcg64Mcg::seed_from_u64(opts.seed ^ 0x6A_5EED_0004);
    let mut steps = Vec::with_capacity(n);
    let eval = |order: &[u32], genes: &[u32], steps: &mut Vec<Step>| {
        decode(p, order, genes, params.bits_by_edge, steps);
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
    let total = params.population + (params.crossover_rate * params.population as f64).round() as usize;
    let mut pop: Vec<Individual> = Vec::with_capacity(total);
    for _ in 0..params.population {
        // The time limit may cut the first population short (never below two individuals).
        if pop.len() >= 2 && clock.expired() {
            break;
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            order.swap(i, rng.gen_range(0..=i));
        }
        let genes: Vec<u32> = (0..n).map(|_| rng.gen_range(0..max_modes)).collect();
        let cost = eval(&order, &genes, &mut steps);
        pop.push(Individual { order, genes, cost });
    }
    let psize = pop.len();
    let by_cost = |a: &Individual, b: &Individual| a.cost.total_cmp(&b.cost);
    pop.sort_by(by_cost);
    let mut best = pop[0].clone();
    let first_cost = best.cost;
    let children = (params.crossover_rate * psize as f64).round() as usize;
    let mutations = (params.mutation_rate * psize as f64).round() as usize;
    let mut generations = 0u64;
    for _ in 0..params.generations {
        if clock.expired() {
            break;
        }
        generations += 1;
        let mut made = 0;
        while made < children && n > 0 && !clock.expired() {
            // parents: the best of `parent_pairs` random pairs
            let mut pair = two_distinct(&mut rng, psize);
            let mut pair_cost = pop[pair.0].cost + pop[pair.1].cost;
            for _ in 1..params.parent_pairs {
                let (i, j) = two_distinct(&mut rng, psize);
                let c = pop[i].cost + pop[j].cost;
                if c < pair_cost {
                    pair_cost = c;
                    pair = (i, j);
                }
            }
            let (a, b) = (&pop[pair.0], &pop[pair.1]);
            let mut lo = rng.gen_range(0..n);
            let mut hi = rng.gen_range(0..n);
            if lo > hi {
                std::mem::swap(&mut lo, &mut hi);
            }
            let hi = hi + 1;
            let kids = [
                (order_crossover(&a.order, &b.order, lo, hi), bit_crossover(&a.genes, &b.genes, lo, hi)),
                (order_crossover(&b.order, &a.order, lo, hi), bit_crossover(&b.genes, &a.genes, lo, hi)),
            ];
            for (order, genes) in kids {
                if made < children {
                    let cost = eval(&order, &genes, &mut steps);
                    pop.push(Individual { order, genes, cost });
                    made += 1;
                }
            }
        }
        for _ in 0..mutations {
            if clock.expired() {
                break;
            }
            let k = rng.gen_range(0..pop.len());
            mutate(&mut pop[k], &mut rng, flip);
            let ind = &pop[k];
            let cost = eval(&ind.order, &ind.genes, &mut steps);
            pop[k].cost = cost;
        }
        pop.sort_by(by_cost);
        pop.truncate(psize);
        if pop[0].cost < best.cost {
            best = pop[0].clone();
        }
    }
    decode(p, &best.order, &best.genes, params.bits_by_edge, &mut steps);
    finish(p, steps, opts, &clock, first_cost, generations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::{prop_assert_eq, proptest};

    proptest! {
        /// OX keeps a permutation and the block of the first parent in place.
        #[test]
        fn ox_keeps_a_permutation(n in 1usize..40, seed in 0u64..1000, a in 0usize..40, b in 0usize..40) {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let mut p1: Vec<u32> = (0..n as u32).collect();
            let mut p2 = p1.clone();
            for i in (1..n).rev() {
                p1.swap(i, rng.gen_range(0..=i));
                p2.swap(i, rng.gen_range(0..=i));
            }
            let (lo, hi) = ((a % n).min(b % n), (a % n).max(b % n) + 1);
            let c = order_crossover(&p1, &p2, lo, hi);
            let mut sorted = c.clone();
            sorted.sort();
            prop_assert_eq!(sorted, (0..n as u32).collect::<Vec<_>>());
            prop_assert_eq!(&c[lo..hi], &p1[lo..hi]);
            // outside the block, the order is the second parent's
            let outside: Vec<u32> = c.iter().enumerate().filter(|(k, _)| !(lo..hi).contains(k)).map(|(_, &t)| t).collect();
            let expect: Vec<u32> = p2.iter().copied().filter(|t| !p1[lo..hi].contains(t)).collect();
            prop_assert_eq!(outside, expect);
        }
    }

    #[test]
    fn ox_worked_example() {
        // Gen & Cheng's illustration: block 3..7 of the first parent kept
        let p1 = [0, 1, 2, 3, 4, 5, 6, 7, 8];
        let p2 = [4, 3, 1, 8, 7, 2, 0, 6, 5];
        assert_eq!(order_crossover(&p1, &p2, 3, 7), vec![1, 8, 7, 3, 4, 5, 6, 2, 0]);
        assert_eq!(bit_crossover(&[1, 1, 1, 1], &[0, 0, 0, 0], 1, 3), vec![0, 1, 1, 0]);
    }

    #[test]
    fn mutation_swaps_and_flips() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        for _ in 0..100 {
            let mut ind = Individual { order: (0..6).collect(), genes: vec![0, 0, 0, 1, 1, 1], cost: 0.0 };
            mutate(&mut ind, &mut rng, |g| 1 - g);
            // the order is a permutation differing from the identity in exactly two places
            let moved = ind.order.iter().enumerate().filter(|&(k, &t)| k as u32 != t).count();
            assert_eq!(moved, 2);
            // a swap keeps the number of ones, the flip changes it by one
            let ones = ind.genes.iter().filter(|&&g| g == 1).count();
            assert!(ones == 2 || ones == 4, "{:?}", ind.genes);
        }
    }
}
