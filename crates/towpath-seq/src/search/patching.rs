//! Assignment and patching: a start for asymmetric one-mode problems (ATSP, SOP).
//!
//! On random asymmetric costs the cheapest assignment (every node one successor, every node
//! one predecessor: a set of cycles) is nearly a tour: on SOPLIB's sparse files its cost equals
//! the best known tour's, and the few cycles it leaves are joined by *patching*, each time at
//! the pair of arcs, one in each of two cycles, whose exchange costs least (Karp 1979; Glover,
//! Gutin, Yeo & Zverovich 2001 compare such constructions). Local search from there does far
//! better on such costs than from nearest neighbour, whose greedy arcs lead it into long
//! detours at the end (Johnson, Gutin, McGeoch et al. 2002 on random ATSP matrices).
//!
//! The tour is then made to keep the precedence: tasks are taken in the patched tour's order,
//! each as soon as its predecessors are done (a stable topological order).

use std::time::Instant;

use super::construct::{follow_order, Seq};
use super::net::Net;
use crate::cost::{Cost, CostModel};

/// Largest tour (nodes) the construction runs on: the assignment takes O(n³).
pub(crate) const PATCHING_UP_TO: usize = 600;

/// The patched assignment tour, made to keep precedence; `None` when the problem is not of the
/// kind (see [`arc_matrix`]) or the deadline passes.
#[cfg(test)]
pub(crate) fn assignment_patching<C: CostModel>(net: &Net<C>, deadline: Option<Instant>) -> Option<Seq> {
    let c = arc_matrix(net, deadline)?;
    let mut succ = Assignment::solve(&c, net.n).columns();
    patch(&c, net.n, &mut succ);
    tour_of(net, &succ)
}

/// The arc costs between the nodes of an asymmetric one-mode problem, row-major, for the
/// assignment; `None` when the problem is not of the kind (more than one mode on a task,
/// consecutive groups, symmetric costs, too large or too small) or the deadline passes. An arc
/// into a node's own predecessor can be in no route and costs [`Net::forbidden`] (the closing
/// arc into the node at position 0 is the wrap of the cyclic tour, always allowed).
pub(crate) fn arc_matrix<C: CostModel>(net: &Net<C>, deadline: Option<Instant>) -> Option<Vec<Cost>> {
    let n = net.n;
    if !(4..=PATCHING_UP_TO).contains(&n) || net.multi_mode || net.has_groups || net.plain_symmetric {
        return None;
    }
    let mut c = vec![net.forbidden; n * n];
    for a in 0..n as u32 {
        if deadline.is_some_and(|d| Instant::now() >= d) {
            return None;
        }
        for b in 0..n as u32 {
            if a != b && (b == net.anchor || !net.direct_predecessors(a).contains(&b)) {
                c[a as usize * n + b as usize] = net.arc(a, 0, b, 0).min(net.forbidden);
            }
        }
    }
    Some(c)
}

/// The route that follows the single cycle `succ` from the anchor, made to keep precedence (a
/// stable topological order).
pub(crate) fn tour_of<C: CostModel>(net: &Net<C>, succ: &[usize]) -> Option<Seq> {
    let n = net.n;
    let mut pos = vec![0u32; n];
    let mut v = net.anchor as usize;
    for i in 0..n {
        pos[v] = i as u32;
        v = succ[v];
    }
    follow_order(net, &pos)
}

/// An optimal assignment of `n` rows to `n` columns of a cost matrix (row-major) with its dual
/// potentials: shortest augmenting paths (Kuhn–Munkres in the form of Jonker & Volgenant 1987),
/// O(n³) from scratch, O(n²) to reassign one row after its arc got dearer.
#[derive(Clone)]
pub(crate) struct Assignment {
    /// Row and column potentials, 1-based; `c(i, j) - u[i] - v[j] >= 0`, zero on assigned arcs.
    u: Vec<Cost>,
    v: Vec<Cost>,
    /// The row (1-based) assigned to each column (1-based), 0 when free; index 0 is the virtual
    /// column an augmentation starts from.
    row_of: Vec<usize>,
}

impl Assignment {
    /// The cheapest assignment for the cost matrix `c`.
    pub fn solve(c: &[Cost], n: usize) -> Self {
        let mut a = Assignment { u: vec![0.0; n + 1], v: vec![0.0; n + 1], row_of: vec![0; n + 1] };
        for i in 1..=n {
            a.augment(c, n, i);
        }
        a
    }

    /// Re-solves after the arc `row → col` of the assignment was made dearer in `c` (and any
    /// other costs raised): the row is freed and assigned again along one shortest augmenting
    /// path. The potentials stay feasible because no cost went down.
    pub fn reassign(&mut self, c: &[Cost], n: usize, row: usize, col: usize) {
        debug_assert_eq!(self.row_of[col + 1], row + 1);
        self.row_of[col + 1] = 0;
        self.augment(c, n, row + 1);
    }

    /// The column of each row (0-based).
    pub fn columns(&self) -> Vec<usize> {
        let n = self.row_of.len() - 1;
        let mut col_of = vec![0usize; n];
        for j in 1..=n {
            col_of[self.row_of[j] - 1] = j - 1;
        }
        col_of
    }

    /// The assignment's cost under `c`.
    pub fn cost(&self, c: &[Cost]) -> Cost {
        let n = self.row_of.len() - 1;
        (1..=n).map(|j| c[(self.row_of[j] - 1) * n + j - 1]).sum()
    }

    /// Assigns the free row `i` (1-based) along a shortest augmenting path to a free column.
    fn augment(&mut self, c: &[Cost], n: usize, i: usize) {
        let Assignment { u, v, row_of } = self;
        let mut way = vec![0usize; n + 1];
        let mut minv = vec![Cost::INFINITY; n + 1];
        let mut used = vec![false; n + 1];
        row_of[0] = i;
        let mut j0 = 0usize;
        loop {
            used[j0] = true;
            let i0 = row_of[j0];
            let mut delta = Cost::INFINITY;
            let mut j1 = 0usize;
            let row = &c[(i0 - 1) * n..i0 * n];
            for j in 1..=n {
                if !used[j] {
                    let cur = row[j - 1] - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=n {
                if used[j] {
                    u[row_of[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if row_of[j0] == 0 {
                break;
            }
        }
        // Flip the augmenting path.
        loop {
            let j1 = way[j0];
            row_of[j0] = row_of[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
}

/// Joins the cycles of the successor function `succ` into one: each time, over every pair of
/// arcs `a → a'` and `b → b'` in different cycles, the exchange for `a → b'` and `b → a'` that
/// costs least.
pub(crate) fn patch(c: &[Cost], n: usize, succ: &mut [usize]) {
    let mut cycle = vec![0usize; n];
    loop {
        let cycles = cycles_of(succ);
        if cycles.len() <= 1 {
            return;
        }
        for (id, nodes) in cycles.iter().enumerate() {
            for &x in nodes {
                cycle[x] = id;
            }
        }
        let mut best = (Cost::INFINITY, 0, 0);
        for a in 0..n {
            let a2 = succ[a];
            let base = c[a * n + a2];
            for b in 0..n {
                if cycle[b] == cycle[a] {
                    continue;
                }
                let b2 = succ[b];
                let d = c[a * n + b2] + c[b * n + a2] - base - c[b * n + b2];
                if d < best.0 {
                    best = (d, a, b);
                }
            }
        }
        let (_, a, b) = best;
        let (a2, b2) = (succ[a], succ[b]);
        succ[a] = b2;
        succ[b] = a2;
    }
}

/// The cycles of a successor function, each as its nodes in order.
pub(crate) fn cycles_of(succ: &[usize]) -> Vec<Vec<usize>> {
    let mut seen = vec![false; succ.len()];
    let mut out = Vec::new();
    for s in 0..succ.len() {
        if !seen[s] {
            let mut cycle = Vec::new();
            let mut x = s;
            while !seen[x] {
                seen[x] = true;
                cycle.push(x);
                x = succ[x];
            }
            out.push(cycle);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;

    /// Every permutation's cost, the cheapest.
    fn brute_force(c: &[Cost], n: usize) -> Cost {
        fn go(c: &[Cost], n: usize, row: usize, used: &mut Vec<bool>) -> Cost {
            if row == n {
                return 0.0;
            }
            let mut best = Cost::INFINITY;
            for j in 0..n {
                if !used[j] {
                    used[j] = true;
                    best = best.min(c[row * n + j] + go(c, n, row + 1, used));
                    used[j] = false;
                }
            }
            best
        }
        go(c, n, 0, &mut vec![false; n])
    }

    #[test]
    fn the_assignment_is_the_cheapest_permutation() {
        for seed in 0..40u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = 1 + (seed % 7) as usize;
            let c: Vec<Cost> = (0..n * n).map(|_| f64::from(rng.gen_range(0..50u32))).collect();
            let col = Assignment::solve(&c, n).columns();
            let mut seen = col.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "seed {seed}: not a permutation");
            let cost: Cost = (0..n).map(|r| c[r * n + col[r]]).sum();
            assert_eq!(cost, brute_force(&c, n), "seed {seed}");
        }
    }

    #[test]
    fn reassigning_a_dearer_row_matches_a_fresh_solve() {
        for seed in 0..40u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = 2 + (seed % 7) as usize;
            let mut c: Vec<Cost> = (0..n * n).map(|_| f64::from(rng.gen_range(0..60u32))).collect();
            let mut a = Assignment::solve(&c, n);
            // Make assigned arcs dearer one after another (and an unassigned one), reassigning.
            for _ in 0..n.min(4) {
                let cols = a.columns();
                let row = rng.gen_range(0..n);
                let col = cols[row];
                c[row * n + col] += f64::from(rng.gen_range(1..80u32));
                let (i, j) = (rng.gen_range(0..n), rng.gen_range(0..n));
                if cols[i] != j {
                    c[i * n + j] += 5.0;
                }
                a.reassign(&c, n, row, col);
                assert_eq!(a.cost(&c), Assignment::solve(&c, n).cost(&c), "seed {seed}");
                assert_eq!(a.cost(&c), brute_force(&c, n), "seed {seed}");
            }
        }
    }

    #[test]
    fn the_patched_start_is_a_route_the_checker_accepts() {
        use crate::search::tour::Tour;
        use crate::solution::check;
        for seed in 0..30u64 {
            // Random costs, a few precedence pairs along a hidden order, the first task pinned
            // and, every other seed, the last one on an open route.
            let p = super::super::ap_branch::tests::problem(seed, 8 + (seed % 25) as usize, 100, true);
            let net = Net::new(&p);
            let (seq, mode) = assignment_patching(&net, None).expect("an asymmetric one-mode problem");
            let tour = Tour::new(&net, seq, mode);
            let steps = super::super::steps_from_tour(&net, &tour);
            let cost = check(&p, &steps).expect("the patched start keeps precedence and pins");
            assert!((cost - tour.cost).abs() < 1e-6, "seed {seed}: {cost} vs {}", tour.cost);
        }
    }

    #[test]
    fn patching_leaves_one_cycle_through_every_node() {
        for seed in 0..20u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            let n = 5 + (seed % 30) as usize;
            let mut c: Vec<Cost> = (0..n * n).map(|_| f64::from(rng.gen_range(0..100u32))).collect();
            for i in 0..n {
                c[i * n + i] = 1e12;
            }
            let mut succ = Assignment::solve(&c, n).columns();
            let before: Cost = (0..n).map(|r| c[r * n + succ[r]]).sum();
            patch(&c, n, &mut succ);
            let mut x = 0;
            for step in 1..=n {
                x = succ[x];
                assert_eq!(x == 0, step == n, "seed {seed}: a cycle of {step} nodes");
            }
            let after: Cost = (0..n).map(|r| c[r * n + succ[r]]).sum();
            assert!(after >= before, "seed {seed}: patching went below the assignment bound");
        }
    }
}
