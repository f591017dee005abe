//! Exact mode re-selection for a fixed order: a shortest path through the layered graph whose
//! layers are the tour positions and whose nodes are the modes, O(n·m²) (times the anchor's
//! modes for a cycle).

use super::net::Net;
use super::tour::Tour;
use crate::cost::{Cost, CostModel};

/// Re-selects every node's mode optimally for the current order. Returns true if the cost fell
/// by more than `eps` (the tour is then updated; otherwise it is left as it was).
pub(crate) fn optimize_modes<C: CostModel>(net: &Net<C>, tour: &mut Tour, eps: Cost) -> bool {
    optimize_modes_noting(net, tour, eps, &mut Vec::new())
}

/// [`optimize_modes`], and the nodes whose mode changed are appended to `changed`.
pub(crate) fn optimize_modes_noting<C: CostModel>(
    net: &Net<C>,
    tour: &mut Tour,
    eps: Cost,
    changed: &mut Vec<u32>,
) -> bool {
    let n = tour.len();
    if !net.multi_mode || n < 2 {
        return false;
    }
    let mm = (0..n as u32).map(|v| net.num_modes(v)).max().unwrap_or(1) as usize;
    let a0 = tour.seq[0];
    let mut best_total = Cost::INFINITY;
    let mut best_modes: Vec<u32> = Vec::new();
    let mut f = vec![Cost::INFINITY; n * mm];
    let mut par = vec![0u32; n * mm];
    for m0 in 0..net.num_modes(a0) {
        f.iter_mut().for_each(|x| *x = Cost::INFINITY);
        f[m0 as usize] = net.mode_cost(a0, m0);
        relax_layers(net, &tour.seq, mm, &mut f, &mut par);
        let last = tour.seq[n - 1];
        for ml in 0..net.num_modes(last) {
            let c = f[(n - 1) * mm + ml as usize] + net.arc(last, ml, a0, m0);
            if c < best_total {
                best_total = c;
                best_modes.clear();
                best_modes.resize(n, 0);
                best_modes[n - 1] = ml;
                for i in (1..n).rev() {
                    best_modes[i - 1] = par[i * mm + best_modes[i] as usize];
                }
                best_modes[0] = m0;
            }
        }
    }
    if best_total < tour.cost - eps {
        for (i, &m) in best_modes.iter().enumerate() {
            let v = tour.seq[i];
            if tour.mode[v as usize] != m {
                changed.push(v);
                tour.set_mode(v, m);
            }
        }
        tour.cost = best_total;
        true
    } else {
        false
    }
}

/// The layers after the first of the mode graph along `seq`: given `f`'s first row (the cost of
/// reaching `seq[0]` in each mode), fills row i with the cheapest cost of reaching `seq[i]` in
/// each mode (mode costs included) and `par`'s row i with the mode of `seq[i - 1]` on that
/// path. Rows are `mm` wide.
pub(crate) fn relax_layers<C: CostModel>(net: &Net<C>, seq: &[u32], mm: usize, f: &mut [Cost], par: &mut [u32]) {
    for i in 1..seq.len() {
        let (u, v) = (seq[i - 1], seq[i]);
        for mv in 0..net.num_modes(v) {
            let mut best = (Cost::INFINITY, 0u32);
            for mu in 0..net.num_modes(u) {
                let c = f[(i - 1) * mm + mu as usize] + net.arc(u, mu, v, mv);
                if c < best.0 {
                    best = (c, mu);
                }
            }
            f[i * mm + mv as usize] = best.0 + net.mode_cost(v, mv);
            par[i * mm + mv as usize] = best.1;
        }
    }
}
