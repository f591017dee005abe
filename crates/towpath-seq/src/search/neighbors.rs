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

    /// The same lists with each node's fixed partner (see [`Net::partner`]) first, added where
    /// it was missing: the search must be able to put a fixed edge back that a kick cut.
    pub fn with_partners_first<C: CostModel>(self, net: &Net<C>) -> Self {
        let lists: Vec<Vec<u32>> = (0..net.n_tasks as u32)
            .map(|v| {
                let p = net.partner[v as usize];
                let mut list: Vec<u32> = Vec::with_capacity(self.out(v).len() + 1);
                if p != u32::MAX {
                    list.push(p);
                }
                list.extend(self.out(v).iter().copied().filter(|&u| u != p));
                list
            })
            .collect();
        Neighbors::from_lists(net, lists)
    }

    #[cfg(test)]
    pub fn build<C: CostModel>(net: &Net<C>, k: usize) -> Self {
        Self::build_on(net, k, 1)
    }

    /// [`Neighbors::build`] on up to `threads` threads (the same lists).
    pub fn build_on<C: CostModel>(net: &Net<C>, k: usize, threads: usize) -> Self {
        let n = net.n_tasks;
        let k = k.min(n.saturating_sub(1)).max(1);
        let symmetric = net.p.cost_model().is_symmetric();
        let positions = spatial_points(net);
        let candidates: Vec<Vec<u32>> = match &positions {
            Some((pts, owner)) => kd_candidates(net, pts, owner, k, threads),
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

/// Nearest points looked at per task for its quadrant neighbours (a task at the edge of a
/// cluster looks past the cluster's points for the next one on its empty side).
const QUADRANT_SCAN: usize = 2_000;

/// Candidate lists of each task's `near` nearest tasks and its `per_quadrant` nearest in each
/// of the four quadrants around it, sorted by cost, for plain symmetric one-mode problems whose
/// states lie in one plane (`None` otherwise). On clustered instances the nearest tasks all lie
/// in a task's own cluster, so the arcs between clusters that a good tour needs are in no list;
/// quadrant neighbours keep them (Johnson & McGeoch 2002, LKH's `QUADRANT` candidates).
pub(crate) fn quadrant_lists<C: CostModel>(net: &Net<C>, near: usize, per_quadrant: usize) -> Option<Neighbors> {
    if !net.plain_symmetric || net.multi_mode || net.depot != u32::MAX || net.n_tasks < 8 {
        return None;
    }
    let n = net.n_tasks;
    let cm = net.p.cost_model();
    let point = |t: u32| net.p.modes(TaskId(t)).first().and_then(|m| cm.position(m.entry));
    let z = point(0)?[2];
    let mut pts = Vec::with_capacity(n);
    for t in 0..n as u32 {
        let p = point(t)?;
        if !p.iter().all(|x| x.is_finite()) || p[2] != z {
            return None;
        }
        pts.push([p[0], p[1]]);
    }
    let tree: RTree<GeomWithData<[f64; 2], u32>> =
        RTree::bulk_load(pts.iter().enumerate().map(|(i, &p)| GeomWithData::new(p, i as u32)).collect());
    let mut lists = Vec::with_capacity(n);
    for (v, &p) in pts.iter().enumerate() {
        let mut list: Vec<u32> = Vec::new();
        let mut in_quadrant = [0usize; 4];
        for nn in tree.nearest_neighbor_iter(&p).take(QUADRANT_SCAN) {
            let u = nn.data;
            if u as usize == v {
                continue;
            }
            let q = pts[u as usize];
            let quadrant = usize::from(q[0] >= p[0]) + 2 * usize::from(q[1] >= p[1]);
            if list.len() < near || in_quadrant[quadrant] < per_quadrant {
                list.push(u);
                in_quadrant[quadrant] += 1;
            }
            if list.len() >= near && in_quadrant.iter().all(|&c| c >= per_quadrant) {
                break;
            }
        }
        let mut scored: Vec<(Cost, u32)> = list.iter().map(|&u| (min_arc(net, v as u32, u), u)).collect();
        scored.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        lists.push(scored.into_iter().map(|(_, u)| u).collect());
    }
    Some(Neighbors::from_lists(net, lists))
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

/// With precedence, each task's depth in it (the most tasks on a chain of precedence that ends
/// at it), scaled to a distance: a fourth coordinate for the candidate search. Tasks stacked on
/// one another (the same course in ply after ply of an AFP part) then stand apart by their
/// depth, so that a course's candidates are its neighbours in its own ply and the plies next
/// to it, not its copies above and below, none of which can ever follow it at once (every
/// task tied to it through others must come between). The scale is `DEPTH_SCALE` times the
/// spacing of the points were they spread evenly over their bounding box's plane.
fn precedence_depth<C: CostModel>(net: &Net<C>, pts: &[[f64; 3]]) -> Option<Vec<f64>> {
    if !net.has_prec || pts.is_empty() {
        return None;
    }
    let n = net.n_tasks;
    // Kahn's order over the tasks
    let mut indegree = net.task_indegrees();
    let mut level = vec![0u32; n];
    let mut ready: Vec<u32> = (0..n as u32).filter(|&v| indegree[v as usize] == 0).collect();
    while let Some(v) = ready.pop() {
        for &s in net.successors(v) {
            let s = s as usize;
            if s < n {
                level[s] = level[s].max(level[v as usize] + 1);
                indegree[s] -= 1;
                if indegree[s] == 0 {
                    ready.push(s as u32);
                }
            }
        }
    }
    let (lo, hi) = bounds(pts);
    let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(0.0);
    let spacing = (area / pts.len() as f64).sqrt();
    if !spacing.is_finite() || spacing <= 0.0 {
        return None;
    }
    Some(level.iter().map(|&l| f64::from(l) * DEPTH_SCALE * spacing).collect())
}

/// See [`precedence_depth`]. On a 10,000-course AFP panel of 100 stacked plies (axis cost,
/// 10 s, seed 1) scales 0 (no depth) / 4 / 16 / 64 ended at 2,249,498 / 2,099,952 / 2,151,092 /
/// 2,143,036.
const DEPTH_SCALE: f64 = 4.0;

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

/// For each task, the tasks owning the points nearest to its own (its points that coincide, as
/// a course's start does for both its directions, are asked once), on up to `threads` threads;
/// the lists do not depend on the thread count.
fn kd_candidates<C: CostModel>(
    net: &Net<C>,
    pts: &[[f64; 3]],
    owner: &[u32],
    k: usize,
    threads: usize,
) -> Vec<Vec<u32>> {
    let depth = precedence_depth(net, pts);
    let at = |i: usize| -> [f64; 4] {
        let p = pts[i];
        [p[0], p[1], p[2], depth.as_ref().map_or(0.0, |d| d[owner[i] as usize])]
    };
    let tree: RTree<GeomWithData<[f64; 4], u32>> =
        RTree::bulk_load((0..pts.len()).map(|i| GeomWithData::new(at(i), owner[i])).collect());
    let n = net.n_tasks;
    let mut by_task: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, &t) in owner.iter().enumerate() {
        by_task[t as usize].push(i);
    }
    // points closer than this are one query
    let same = 1e-6 * diagonal(pts);
    let lists_of = |range: std::ops::Range<usize>| -> Vec<Vec<u32>> {
        let mut out = Vec::with_capacity(range.len());
        let mut mark = vec![u32::MAX; n];
        let mut asked: Vec<[f64; 4]> = Vec::new();
        for t in range {
            let idxs = &by_task[t];
            mark[t] = t as u32;
            // Ask for enough points to see about 2k other tasks even when tasks have many states.
            let per_point = (2 * k + 1) * idxs.len().max(1) + 4;
            let mut cands: Vec<u32> = Vec::new();
            asked.clear();
            for &i in idxs {
                let q = at(i);
                if asked.iter().any(|a| (0..4).map(|d| (a[d] - q[d]).powi(2)).sum::<f64>().sqrt() <= same) {
                    continue;
                }
                asked.push(q);
                for nn in tree.nearest_neighbor_iter(&q).take(per_point) {
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
    };
    let threads = threads.clamp(1, n.max(1));
    if threads == 1 {
        return lists_of(0..n);
    }
    let chunk = n.div_ceil(threads);
    std::thread::scope(|scope| {
        let parts: Vec<_> = (0..threads)
            .map(|w| {
                let range = (w * chunk).min(n)..((w + 1) * chunk).min(n);
                let lists_of = &lists_of;
                scope.spawn(move || lists_of(range))
            })
            .collect();
        parts.into_iter().flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
    })
}

/// The points' bounding box: its lowest and highest corner.
fn bounds(pts: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pts {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// The diagonal of the points' bounding box.
fn diagonal(pts: &[[f64; 3]]) -> f64 {
    let (lo, hi) = bounds(pts);
    (0..3).map(|d| (hi[d] - lo[d]).max(0.0).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::*;
    use crate::cost::{Metric, PointCost};
    use crate::model::{Mode, Problem, TaskId};

    fn tour_problem(pts: Vec<[f64; 3]>) -> Problem<PointCost> {
        let n = pts.len();
        let mut b = Problem::builder(PointCost::new(pts, Metric::Euclidean));
        for t in 0..n as u32 {
            b.task(vec![Mode::new(StateId(t), StateId(t))]);
        }
        b.build().expect("valid problem")
    }

    #[test]
    fn quadrant_lists_reach_across_clusters_that_nearest_lists_miss() {
        // Two tight clusters of 60 points, 1,000 apart on the x axis.
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let pts: Vec<[f64; 3]> = (0..120)
            .map(|i| {
                let cx = if i < 60 { 0.0 } else { 1000.0 };
                [cx + rng.gen_range(-10.0..10.0), rng.gen_range(-10.0..10.0), 0.0]
            })
            .collect();
        let p = tour_problem(pts.clone());
        let net = Net::new(&p);
        let other = |v: u32, u: u32| (v < 60) != (u < 60);
        let nearest = Neighbors::build(&net, 10);
        assert!((0..120u32).all(|v| nearest.out(v).iter().all(|&u| !other(v, u))), "nearest lists stay at home");
        let q = quadrant_lists(&net, 6, 1).expect("a planar symmetric tour");
        let across = (0..120u32).filter(|&v| q.out(v).iter().any(|&u| other(v, u))).count();
        // Every point of the left cluster's right edge sees the right cluster (its quadrants to
        // the right hold no point of its own cluster) and vice versa.
        let rightmost = (0..60u32).max_by(|&a, &b| pts[a as usize][0].total_cmp(&pts[b as usize][0])).unwrap();
        assert!(q.out(rightmost).iter().any(|&u| u >= 60), "the rightmost left point sees no right point");
        assert!(across >= 2, "only {across} lists reach across");
        for v in 0..120u32 {
            let list = q.out(v);
            assert!(!list.contains(&v) && list.len() >= 6 && list.len() <= 10);
            let costs: Vec<Cost> = list.iter().map(|&u| min_arc(&net, v, u)).collect();
            assert!(costs.windows(2).all(|w| w[0] <= w[1]), "list of {v} not sorted by cost");
        }
    }

    #[test]
    fn quadrant_lists_need_a_plane() {
        let p = tour_problem((0..20).map(|i| [f64::from(i), 0.0, f64::from(i % 2)]).collect());
        assert!(quadrant_lists(&Net::new(&p), 6, 1).is_none());
    }

    /// Courses stacked in 12 layers (each course over the three nearest of the layer below):
    /// with the precedence's depth as a coordinate, a course's candidates are courses of its
    /// own layer and the layers next to it, away from the layers' edges never its copies four
    /// or more layers away (none of which can follow it at once); without precedence the same
    /// points give all eleven copies.
    /// The lists are the same on one thread and on three.
    #[test]
    fn stacked_courses_find_their_own_layer_not_their_copies() {
        let (layers, per) = (12usize, 60usize);
        let mut pts = Vec::new();
        for l in 0..layers {
            for i in 0..per {
                let (y, z) = (10.0 * i as f64, 1e-4 * l as f64);
                pts.extend([[0.0, y, z], [100.0, y, z], [100.0, y, z + 5.0], [0.0, y, z + 5.0]]);
            }
        }
        pts.push([-50.0, 0.0, 20.0]);
        let build = |with_precedence: bool| {
            let mut b = Problem::builder(PointCost::new(pts.clone(), Metric::Euclidean));
            for t in 0..(layers * per) as u32 {
                let s = |k: u32| StateId(4 * t + k);
                b.task(vec![Mode::new(s(0), s(1)), Mode::new(s(2), s(3))]);
            }
            b.start(StateId((4 * layers * per) as u32));
            if with_precedence {
                for l in 0..layers - 1 {
                    for i in 0..per {
                        for j in i.saturating_sub(1)..(i + 2).min(per) {
                            b.precede(TaskId((l * per + i) as u32), TaskId(((l + 1) * per + j) as u32));
                        }
                    }
                }
            }
            b.build().expect("a valid problem")
        };
        let layer = |t: u32| t as usize / per;
        let p = build(true);
        let net = Net::new(&p);
        let (pts, owner) = spatial_points(&net).expect("positions");
        let depth = precedence_depth(&net, &pts).expect("precedence");
        for t in 0..layers * per {
            assert_eq!(depth[t], depth[per] * layer(t as u32) as f64, "task {t}: depth by layer");
        }
        let lists = kd_candidates(&net, &pts, &owner, 10, 1);
        assert_eq!(lists, kd_candidates(&net, &pts, &owner, 10, 3));
        for (t, list) in lists.iter().enumerate() {
            let (l, i) = (layer(t as u32), t % per);
            // (at the layers' edges the nearest points reach further up and down)
            if (10..per - 10).contains(&i) {
                assert!(list.iter().all(|&u| layer(u).abs_diff(l) <= 3), "task {t}: {list:?}");
            }
            for j in [i.wrapping_sub(1), i + 1] {
                if j < per {
                    assert!(list.contains(&((l * per + j) as u32)), "task {t} misses its neighbour {j} in its layer");
                }
            }
        }
        // the same points without precedence: a course's stacked copies are its candidates
        let q = build(false);
        let net = Net::new(&q);
        let (pts, owner) = spatial_points(&net).expect("positions");
        let t = 5 * per + 30;
        let copies = kd_candidates(&net, &pts, &owner, 10, 1)[t].iter().filter(|&&u| u as usize % per == 30).count();
        assert_eq!(copies, layers - 1);
    }
}
