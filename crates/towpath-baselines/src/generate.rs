//! Instances built in code for tests and benchmarks of the GTSP solvers, shaped like the public
//! benchmark sets (which are read from files by the formats crate, not here):
//!
//! - [`random_gtsp`]: a GTSP-LIB-like instance: points uniform in a 1000 × 1000 square with
//!   TSPLIB `EUC_2D` distances, clustered as Fischetti, Salazar-González & Toth did for GTSP-LIB
//!   (⌈n/5⌉ centres chosen farthest-first from the two mutually farthest points, every point in
//!   its nearest centre's cluster), a closed tour visiting one point per cluster;
//! - with `precedence`, a PCGTSP-like variant (as Salman et al. derived from SOP instances):
//!   the tour starts at a one-point depot cluster and random precedence rules order the
//!   clusters.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use towpath_seq::{Metric, Mode, ModelError, PointCost, Problem, StateId, TaskId};

/// A GTSP (or, with `precedence`, PCGTSP) instance with `nodes` points (see the module docs).
/// Clusters are tasks, their points the modes (`Mode::point`). Without precedence the route is
/// a cycle; with it, task 0 is a depot cluster of one point pinned first, and each other cluster
/// has up to two random predecessors among the clusters before it in a random order.
pub fn random_gtsp(nodes: usize, seed: u64, precedence: bool) -> Result<Problem<PointCost>, ModelError> {
    let n = nodes.max(2);
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x6_75E9);
    let pts: Vec<[f64; 3]> =
        (0..n).map(|_| [rng.gen_range(0.0..1000.0f64).round(), rng.gen_range(0.0..1000.0f64).round(), 0.0]).collect();
    let d = |a: usize, b: usize| ((pts[a][0] - pts[b][0]).powi(2) + (pts[a][1] - pts[b][1]).powi(2)).sqrt();
    // Farthest-first centres, seeded with the diameter pair (lowest index on ties).
    let m = n.div_ceil(5).max(2);
    let (mut a0, mut b0, mut best) = (0, 1, -1.0);
    for a in 0..n {
        for b in a + 1..n {
            if d(a, b) > best {
                (a0, b0, best) = (a, b, d(a, b));
            }
        }
    }
    let mut centres = vec![a0, b0];
    let mut near: Vec<f64> = (0..n).map(|v| d(v, a0).min(d(v, b0))).collect();
    while centres.len() < m {
        let c = (0..n).fold(0, |c, v| if near[v] > near[c] { v } else { c });
        centres.push(c);
        for v in 0..n {
            near[v] = near[v].min(d(v, c));
        }
    }
    let mut clusters: Vec<Vec<u32>> = vec![Vec::new(); m];
    for v in 0..n {
        let k = (0..m).fold(0, |k, j| if d(v, centres[j]) < d(v, centres[k]) { j } else { k });
        clusters[k].push(v as u32);
    }
    let mut b = Problem::builder(PointCost::new(pts, Metric::EuclideanNint));
    if precedence {
        // the depot: the first centre alone
        let depot = centres[0] as u32;
        for c in clusters.iter_mut() {
            c.retain(|&v| v != depot);
        }
        clusters.retain(|c| !c.is_empty());
        let t0 = b.task(vec![Mode::point(StateId(depot))]);
        b.first(t0);
    }
    let offset = u32::from(precedence);
    for c in &clusters {
        b.task(c.iter().map(|&v| Mode::point(StateId(v))).collect());
    }
    if precedence {
        let k = clusters.len();
        let mut order: Vec<u32> = (0..k as u32).collect();
        for i in (1..k).rev() {
            order.swap(i, rng.gen_range(0..=i));
        }
        for i in 1..k {
            for _ in 0..2 {
                if rng.gen_bool(0.5) {
                    let j = rng.gen_range(0..i);
                    b.precede(TaskId(order[j] + offset), TaskId(order[i] + offset));
                }
            }
        }
    }
    b.build()
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_seq::CostModel;

    #[test]
    fn clusters_partition_the_points() {
        for precedence in [false, true] {
            let p = random_gtsp(60, 3, precedence).unwrap();
            let mut seen = vec![0; 60];
            for t in p.tasks() {
                for m in p.modes(t) {
                    seen[m.entry.index()] += 1;
                }
            }
            assert!(seen.iter().all(|&s| s == 1));
            assert_eq!(p.cost_model().num_states(), 60);
            assert!(p.is_cyclic());
            if precedence {
                // the depot, alone, plus the 12 clusters (one of them may have been the depot's)
                assert!((12..=13).contains(&p.num_tasks()));
                assert_eq!(p.first_task(), Some(TaskId(0)));
                assert_eq!(p.modes(TaskId(0)).len(), 1);
                assert!(p.precedence().num_edges() > 0);
            } else {
                assert_eq!(p.num_tasks(), 12);
                assert_eq!(p.first_task(), None);
            }
        }
    }
}
