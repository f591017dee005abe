//! A population of chains at the start of the search on plain tours. Each thread runs several
//! chains in turn, each from a start of its own (see [`Ils::fresh_start`]), and none adopts
//! another's tour; after [`EPOCHS`] epochs every chain's tour is merged into the best by
//! partition crossover and the search goes on with one chain per thread.
//!
//! Why: on clustered points one run of the iterated local search settles in the funnel of its
//! start, where the clusters are entered and left in one way across the whole tour, and its
//! kicks do not leave it (gauss-5000-60 ended anywhere from 1,093,822 to 1,103,349 over 14
//! seeds of one start). Local optima from different starts differ in many independent
//! components, and the merge takes the best of each (Whitley, Hains and Howe 2009 found the
//! same for partition crossover of Lin–Kernighan optima).

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use super::ils::{Budget, Chain, Ils};
use super::local;
use super::net::Net;
use super::tour::Tour;
use crate::cost::{Cost, CostModel};
use crate::SolveOptions;

/// Epochs (of the 20 a search plans) the population runs before it is merged. gauss-5000-60,
/// 10 s, 2 threads, 8 chains per thread, medians of seeds 1-6: 4 epochs 1,094,443, 6
/// 1,093,830, 8 1,093,607.
pub(crate) const EPOCHS: usize = 6;

/// Most chains a thread runs in the population. gauss-5000-60, 10 s, 2 threads, 6 epochs,
/// medians of seeds 1-6: 4 chains 1,095,382, 8 1,093,830, 16 1,094,516 (one chain per thread,
/// no population: 1,099,305).
const MAX_PER_THREAD: usize = 8;

/// Time a chain of the population needs per node of the tour to be worth its start: on
/// gauss-5000-60 a start takes about 40 ms (8 µs a node) and 8 chains per thread of 0.37 s
/// each paid at 10 s, while at 1 s 8 chains of 37 ms each made the tour 1.4 % dearer.
const NODE_SECONDS: f64 = 40e-6;

/// Kicks a chain of the population needs per node of the tour, under a work budget.
const NODE_KICKS: f64 = 0.25;

/// Chains each thread runs in the population phase: one (no population) unless the tours are
/// plain (the local search has 3-opt chains and no fixed edges) and the budget gives each chain
/// [`NODE_SECONDS`] (or [`NODE_KICKS`]) per node.
pub(crate) fn chains_per_thread<C: CostModel>(net: &Net<C>, opts: &SolveOptions, threads: usize) -> usize {
    if !local::plain_tour(net) || net.n < 8 {
        return 1;
    }
    let share = EPOCHS as f64 / super::EPOCHS_PLANNED as f64;
    let k = match (opts.iterations, opts.time_limit) {
        (Some(it), _) => it as f64 * share / threads as f64 / (NODE_KICKS * net.n as f64),
        (None, Some(tl)) => tl.as_secs_f64() * share / (NODE_SECONDS * net.n as f64),
        (None, None) => 1.0,
    };
    (k as usize).clamp(1, MAX_PER_THREAD)
}

/// Runs one thread's chains for an epoch, each for an equal share of the epoch's kicks and
/// time (`slice`), building a chain's own start first where it has none. Returns the kicks.
pub(crate) fn run_thread<C: CostModel>(
    ils: &Ils<'_, '_, C>,
    group: &mut [Chain],
    budget: Budget,
    slice: Option<Duration>,
    cancel: Option<&AtomicBool>,
) -> u64 {
    let k = group.len().max(1) as u32;
    let begun = Instant::now();
    let mut kicks = 0;
    for (i, chain) in group.iter_mut().enumerate() {
        if chain.fresh {
            chain.fresh = false;
            let start = ils.fresh_start(&mut chain.rng, budget.hard);
            chain.adopt(&start);
        }
        let mut share = budget;
        share.kicks = (budget.kicks / k as u64).max(1);
        if let Some(s) = slice.filter(|_| k > 1) {
            let end = begun + s * (i as u32 + 1) / k;
            share.deadline = Some(budget.deadline.map_or(end, |d| d.min(end)));
        }
        kicks += ils.run(chain, share, cancel);
    }
    kicks
}

/// The population's end: the best chain's tour is merged with every other chain's (twice
/// over, the cheapest first), each merge polished by the local search and kept when cheaper;
/// the result becomes `best` and every chain's tour. `chains` is cut to `threads`.
pub(crate) fn merge_all<C: CostModel>(
    net: &Net<C>,
    ils: &Ils<'_, '_, C>,
    best: &mut Tour,
    chains: &mut Vec<Chain>,
    threads: usize,
    search_end: Option<Instant>,
    eps: Cost,
) {
    chains.sort_by(|a, b| a.best.cost.total_cmp(&b.best.cost));
    super::take_cheapest(best, chains, eps);
    for _round in 0..2 {
        super::merge_into_best(net, ils, best, chains, search_end, eps);
    }
    chains.truncate(threads);
    for (t, c) in chains.iter_mut().enumerate() {
        c.restless = t % 2 == 1;
        c.stagnation = 0;
        c.adopt(best);
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::search::neighbors::Neighbors;
    use crate::search::testing::points_problem;
    use crate::solution::check;

    /// `clusters` Gaussian-like groups of `per` points (uniform in ±20) at random centres of a
    /// 2,000 square.
    fn clustered(seed: u64, clusters: usize, per: usize) -> Vec<[f64; 3]> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut pts = Vec::new();
        for _ in 0..clusters {
            let (cx, cy) = (rng.gen_range(0.0..2000.0), rng.gen_range(0.0..2000.0));
            for _ in 0..per {
                pts.push([cx + rng.gen_range(-20.0..20.0), cy + rng.gen_range(-20.0..20.0), 0.0]);
            }
        }
        pts
    }

    /// Every node once, `pos` the inverse of `seq`, and the cost what the arcs say.
    fn assert_valid(net: &Net<crate::cost::PointCost>, t: &Tour) {
        let mut seen = t.seq.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..net.n as u32).collect::<Vec<_>>());
        for (i, &v) in t.seq.iter().enumerate() {
            assert_eq!(t.pos[v as usize] as usize, i);
        }
        assert!(
            (t.cost - t.full_cost(net)).abs() <= 1e-9 * t.cost.abs().max(1.0),
            "{} vs {}",
            t.cost,
            t.full_cost(net)
        );
    }

    /// A fresh start visits every node once, is brought to a local optimum (a further descent,
    /// from every node at once, finds less than 0.5 %: the don't-look bits of the first leave a
    /// few moves behind) and depends on the random state: chains start in different places.
    #[test]
    fn fresh_starts_are_distinct_local_optima() {
        let p = points_problem(clustered(5, 12, 25));
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 10);
        let ils = Ils::new(&net, &nb, 1e-9);
        let mut tours = Vec::new();
        for seed in 0..4 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let t = ils.fresh_start(&mut rng, None);
            assert_valid(&net, &t);
            let mut again = t.clone();
            ils.descend(&mut again, None);
            assert!(again.cost >= 0.995 * t.cost, "{} after {}", again.cost, t.cost);
            tours.push(t.seq);
        }
        tours.sort();
        tours.dedup();
        assert!(tours.len() >= 3, "only {} distinct starts of 4", tours.len());
    }

    /// The merge of the population is never dearer than its best chain, is a valid tour, and
    /// leaves one chain per thread on it (every second one restless).
    #[test]
    fn merge_keeps_the_best_and_leaves_a_chain_per_thread() {
        let p = points_problem(clustered(7, 15, 20));
        let net = Net::new(&p);
        let nb = Neighbors::build(&net, 10);
        let ils = Ils::new(&net, &nb, 1e-9);
        let mut chains: Vec<Chain> = (0..6)
            .map(|s| {
                let mut c = Chain::new(&ils.fresh_start(&mut Pcg64Mcg::seed_from_u64(s), None), s);
                let budget = Budget { kicks: 200, deadline: None, hard: None, temperature: 0.0, slack: 0.0 };
                ils.run(&mut c, budget, None);
                c
            })
            .collect();
        let lowest = chains.iter().map(|c| c.best.cost).fold(Cost::INFINITY, Cost::min);
        let mut best = chains[3].best.clone();
        merge_all(&net, &ils, &mut best, &mut chains, 2, None, 1e-9);
        assert_valid(&net, &best);
        assert!(best.cost <= lowest + 1e-6, "{} against {lowest}", best.cost);
        assert_eq!(chains.len(), 2);
        for (t, c) in chains.iter().enumerate() {
            assert_eq!(c.cur.seq, best.seq);
            assert_eq!(c.best.seq, best.seq);
            assert_eq!(c.restless, t == 1);
        }
    }

    /// A population only where each chain gets its time or kicks per node, and only on plain
    /// tours.
    #[test]
    fn population_size_follows_the_budget() {
        let p = points_problem(clustered(3, 40, 50));
        let net = Net::new(&p);
        let n = net.n as f64;
        let timed = |secs: f64| SolveOptions { time_limit: Some(Duration::from_secs_f64(secs)), ..Default::default() };
        // 10 s at 2,000 nodes: the most; 2 s: 7; 0.5 s: none
        assert_eq!(chains_per_thread(&net, &timed(10.0), 2), MAX_PER_THREAD);
        let per = |secs: f64| (secs * 0.3 / (NODE_SECONDS * n)) as usize;
        assert_eq!(chains_per_thread(&net, &timed(2.0), 2), per(2.0));
        assert!(per(2.0) > 1 && per(2.0) < MAX_PER_THREAD);
        assert_eq!(chains_per_thread(&net, &timed(0.5), 2), 1);
        // a work budget decides alone: 4 chains per thread need 4 · 0.25 · n kicks per thread
        // in the population's 6 epochs of 20
        let worked = |it: u64| SolveOptions { iterations: Some(it), ..Default::default() };
        let four = (4.0 * NODE_KICKS * n * 2.0 / 0.3).ceil() as u64;
        assert_eq!(chains_per_thread(&net, &worked(four), 2), 4);
        assert_eq!(chains_per_thread(&net, &worked(1000), 2), 1);
        // not on tours with fixed edges
        let mut fixed = Net::new(&p);
        fixed.partner = (0..net.n as u32).map(|v| v ^ 1).collect();
        assert_eq!(chains_per_thread(&fixed, &timed(10.0), 2), 1);
    }

    /// With a population (under a work budget that allows one), a solve is still deterministic
    /// and its route is what the checker says.
    #[test]
    fn solves_with_a_population_are_deterministic() {
        let p = points_problem(clustered(11, 10, 30));
        let opts =
            SolveOptions { time_limit: None, iterations: Some(2_000), threads: 2, seed: 4, ..Default::default() };
        assert!(chains_per_thread(&Net::new(&p), &opts, 2) > 1);
        let a = crate::solve(&p, &opts).expect("solves");
        let b = crate::solve(&p, &opts).expect("solves");
        assert_eq!(a.solution.steps, b.solution.steps);
        let cost = check(&p, &a.solution.steps).expect("feasible");
        assert!((cost - a.solution.cost).abs() < 1e-6 * cost);
    }
}
