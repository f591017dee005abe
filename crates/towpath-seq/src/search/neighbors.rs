//! Candidate neighbour lists: for each task, the few tasks it is cheapest to go to (out) and to
//! come from (in). Built from an R-tree when the cost model has positions, else by scanning.

use rstar::primitives::GeomWithData;
use rstar::RTree;

use super::net::Net;
use crate::cost::{Cost, CostModel, StateId};
use crate::model::TaskId;

pub(crate) struct Neighbors {
    k: usize,
    out: Vec<u32>,
    out_len: Vec<u8>,
    inn: Vec<u32>,
    inn_len: Vec<u8>,
    /// The cheapest transition over all mode pairs, per entry of `out` / `inn` (a lower bound
    /// of the arc whatever the modes; lists are sorted by it).
    out_lb: Vec<Cost>,
    inn_lb: Vec<Cost>,
    symmetric: bool,
}

impl Neighbors {
    /// Tasks cheapest to go to from `v` (best first). Empty for the depot.
    #[inline]
    pub fn out(&self, v: u32) -> &[u32] {
        match self.out_len.get(v as usize) {
            Some(&l) => {
                let a = v as usize * self.k;
                &self.out[a..a + l as usize]
            }
            None => &[],
        }
    }

    /// Lower bounds (cheapest over mode pairs) of the arcs to [`Neighbors::out`]'s tasks.
    #[inline]
    pub fn out_lb(&self, v: u32) -> &[Cost] {
        let l = self.out(v).len();
        let a = v as usize * self.k;
        &self.out_lb[a..a + l]
    }

    /// Lower bounds (cheapest over mode pairs) of the arcs from [`Neighbors::inn`]'s tasks.
    #[inline]
    pub fn inn_lb(&self, v: u32) -> &[Cost] {
        if self.symmetric {
            return self.out_lb(v);
        }
        let l = self.inn(v).len();
        let a = v as usize * self.k;
        &self.inn_lb[a..a + l]
    }

    /// Tasks cheapest to come from into `v` (best first).
    #[inline]
    pub fn inn(&self, v: u32) -> &[u32] {
        if self.symmetric {
            return self.out(v);
        }
        match self.inn_len.get(v as usize) {
            Some(&l) => {
                let a = v as usize * self.k;
                &self.inn[a..a + l as usize]
            }
            None => &[],
        }
    }

    /// Lists given per task (each sorted by cost, as the searches expect), on a symmetric cost
    /// model.
    pub fn from_lists<C: CostModel>(net: &Net<C>, lists: Vec<Vec<u32>>) -> Self {
        let n = net.n_tasks;
        debug_assert_eq!(lists.len(), n);
        let k = lists.iter().map(Vec::len).max().unwrap_or(0).max(1);
        let mut out = vec![u32::MAX; n * k];
        let mut out_lb = vec![Cost::INFINITY; n * k];
        for (v, list) in lists.iter().enumerate() {
            for (i, &u) in list.iter().enumerate() {
                out[v * k + i] = u;
                out_lb[v * k + i] = min_arc(net, v as u32, u);
            }
        }
        let out_len = lists.iter().map(|l| l.len() as u8).collect();
        Neighbors { k, out, out_len, inn: Vec::new(), inn_len: Vec::new(), out_lb, inn_lb: Vec::new(), symmetric: true }
    }

    pub fn build<C: CostModel>(net: &Net<C>, k: usize) -> Self {
        let n = net.n_tasks;
        let k = k.min(n.saturating_sub(1)).max(1);
        let symmetric = net.p.cost_model().is_symmetric();
        let positions = spatial_points(net);
        let candidates: Vec<Vec<u32>> = match &positions {
            Some((pts, owner)) => kd_candidates(net, pts, owner, k),
            None => Vec::new(),
        };
        let mut out = vec![u32::MAX; n * k];
        let mut inn = if symmetric { Vec::new() } else { vec![u32::MAX; n * k] };
        let mut out_lb = vec![Cost::INFINITY; n * k];
        let mut inn_lb = if symmetric { Vec::new() } else { vec![Cost::INFINITY; n * k] };
        let mut scored: Vec<(Cost, u32)> = Vec::with_capacity(n);
        for v in 0..n as u32 {
            // out
            scored.clear();
            let pool: Box<dyn Iterator<Item = u32>> = if positions.is_some() {
                Box::new(candidates[v as usize].iter().copied())
            } else {
                Box::new(0..n as u32)
            };
            let pool: Vec<u32> = pool.filter(|&u| u != v).collect();
            for &u in &pool {
                scored.push((min_arc(net, v, u), u));
            }
            let r = v as usize * k..(v as usize + 1) * k;
            fill(&mut out[r.clone()], &mut out_lb[r], &mut scored);
            if !symmetric {
                scored.clear();
                for &u in &pool {
                    scored.push((min_arc(net, u, v), u));
                }
                let r = v as usize * k..(v as usize + 1) * k;
                fill(&mut inn[r.clone()], &mut inn_lb[r], &mut scored);
            }
        }
        let out_len = (0..n).map(|v| count(&out[v * k..(v + 1) * k])).collect();
        let inn_len = if symmetric { Vec::new() } else { (0..n).map(|v| count(&inn[v * k..(v + 1) * k])).collect() };
        Neighbors { k, out, out_len, inn, inn_len, out_lb, inn_lb, symmetric }
    }
}

fn count(s: &[u32]) -> u8 {
    s.iter().position(|&x| x == u32::MAX).unwrap_or(s.len()) as u8
}

fn fill(dst: &mut [u32], lb: &mut [Cost], scored: &mut [(Cost, u32)]) {
    let k = dst.len().min(scored.len());
    if k == 0 {
        return;
    }
    if scored.len() > k {
        scored.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }
    let best = &mut scored[..k];
    best.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for ((d, l), s) in dst.iter_mut().zip(lb.iter_mut()).zip(best.iter()) {
        *d = s.1;
        *l = s.0;
    }
}

/// Cheapest transition from any mode of `a` to any mode of `b`.
fn min_arc<C: CostModel>(net: &Net<C>, a: u32, b: u32) -> Cost {
    let mut best = Cost::INFINITY;
    for ma in 0..net.num_modes(a) {
        for mb in 0..net.num_modes(b) {
            let c = net.arc(a, ma, b, mb);
            if c < best {
                best = c;
            }
        }
    }
    best
}

/// Points of every mode's entry and exit state, with the task that owns each, if the cost model
/// has positions for all of them.
fn spatial_points<C: CostModel>(net: &Net<C>) -> Option<(Vec<[f64; 3]>, Vec<u32>)> {
    let n = net.n_tasks;
    // A k-d tree pays off only on larger instances.
    if n < 600 {
        return None;
    }
    let cm = net.p.cost_model();
    let mut pts = Vec::new();
    let mut owner = Vec::new();
    let mut seen: Vec<StateId> = Vec::new();
    for t in 0..n as u32 {
        seen.clear();
        for m in net.p.modes(TaskId(t)) {
            for s in [m.entry, m.exit] {
                if seen.contains(&s) {
                    continue;
                }
                seen.push(s);
                let p = cm.position(s)?;
                if !p.iter().all(|x| x.is_finite()) {
                    return None;
                }
                pts.push(p);
                owner.push(t);
            }
        }
    }
    Some((pts, owner))
}

fn kd_candidates<C: CostModel>(net: &Net<C>, pts: &[[f64; 3]], owner: &[u32], k: usize) -> Vec<Vec<u32>> {
    let tree: RTree<GeomWithData<[f64; 3], u32>> =
        RTree::bulk_load(pts.iter().zip(owner).map(|(p, &t)| GeomWithData::new(*p, t)).collect());
    let n = net.n_tasks;
    let mut by_task: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, &t) in owner.iter().enumerate() {
        by_task[t as usize].push(i);
    }
    let mut out = Vec::with_capacity(n);
    let mut mark = vec![u32::MAX; n];
    for (t, idxs) in by_task.iter().enumerate() {
        mark[t] = t as u32;
        // Ask for enough points to see about 2k other tasks even when tasks have many states.
        let per_point = (2 * k + 1) * idxs.len().max(1) + 4;
        let mut cands: Vec<u32> = Vec::new();
        for &i in idxs {
            for nn in tree.nearest_neighbor_iter(&pts[i]).take(per_point) {
                let u = nn.data;
                if mark[u as usize] != t as u32 {
                    mark[u as usize] = t as u32;
                    cands.push(u);
                }
            }
        }
        out.push(cands);
    }
    out
}
