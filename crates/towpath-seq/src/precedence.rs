//! The precedence DAG over tasks, stored as compressed adjacency lists in both directions.

use crate::model::TaskId;

/// A precedence relation: `before → after` edges over tasks, known to be acyclic.
#[derive(Clone, Debug, Default)]
pub struct Precedence {
    succ_offsets: Vec<u32>,
    succ: Vec<TaskId>,
    pred_offsets: Vec<u32>,
    pred: Vec<TaskId>,
    topo: Vec<TaskId>,
}

impl Precedence {
    /// Builds the relation over `n` tasks from `(before, after)` index pairs (duplicates are
    /// merged). Returns the tasks of one cycle, in order, if the edges are not acyclic. Indices
    /// must be `< n`.
    pub fn new(n: usize, edges: &[(u32, u32)]) -> Result<Self, Vec<u32>> {
        let mut e: Vec<(u32, u32)> = edges.to_vec();
        e.sort_unstable();
        e.dedup();
        let (succ_offsets, succ) = csr(n, e.iter().copied());
        let (pred_offsets, pred) = csr(n, e.iter().map(|&(a, b)| (b, a)));
        let mut p = Precedence { succ_offsets, succ, pred_offsets, pred, topo: Vec::new() };
        p.topo = p.topological_order()?;
        Ok(p)
    }

    /// Number of distinct edges.
    pub fn num_edges(&self) -> usize {
        self.succ.len()
    }

    /// Tasks that must come directly after `t` (its out-edges).
    #[inline]
    pub fn successors(&self, t: TaskId) -> &[TaskId] {
        let i = t.index();
        &self.succ[self.succ_offsets[i] as usize..self.succ_offsets[i + 1] as usize]
    }

    /// Tasks that must come before `t` (its in-edges).
    #[inline]
    pub fn predecessors(&self, t: TaskId) -> &[TaskId] {
        let i = t.index();
        &self.pred[self.pred_offsets[i] as usize..self.pred_offsets[i + 1] as usize]
    }

    /// A topological order of all tasks (ties broken by lowest index).
    pub fn topological(&self) -> &[TaskId] {
        &self.topo
    }

    fn topological_order(&self) -> Result<Vec<TaskId>, Vec<u32>> {
        let n = self.succ_offsets.len() - 1;
        let mut indeg: Vec<u32> = (0..n).map(|i| self.predecessors(TaskId(i as u32)).len() as u32).collect();
        let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<u32>> =
            (0..n as u32).filter(|&i| indeg[i as usize] == 0).map(std::cmp::Reverse).collect();
        let mut order = Vec::with_capacity(n);
        while let Some(std::cmp::Reverse(t)) = heap.pop() {
            order.push(TaskId(t));
            for &s in self.successors(TaskId(t)) {
                indeg[s.index()] -= 1;
                if indeg[s.index()] == 0 {
                    heap.push(std::cmp::Reverse(s.0));
                }
            }
        }
        if order.len() == n {
            return Ok(order);
        }
        // Find a cycle among the remaining tasks: walk predecessors that are still blocked.
        let start = (0..n).find(|&i| indeg[i] > 0).unwrap_or(0);
        let mut seen = vec![usize::MAX; n];
        let mut path = Vec::new();
        let mut cur = start;
        loop {
            if seen[cur] != usize::MAX {
                let mut cycle: Vec<u32> = path[seen[cur]..].to_vec();
                cycle.reverse();
                return Err(cycle);
            }
            seen[cur] = path.len();
            path.push(cur as u32);
            cur =
                self.predecessors(TaskId(cur as u32)).iter().map(|p| p.index()).find(|&p| indeg[p] > 0).unwrap_or(cur);
        }
    }
}

fn csr(n: usize, edges: impl Iterator<Item = (u32, u32)> + Clone) -> (Vec<u32>, Vec<TaskId>) {
    let mut offsets = vec![0u32; n + 1];
    for (a, _) in edges.clone() {
        offsets[a as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut out = vec![TaskId(0); offsets[n] as usize];
    for (a, b) in edges {
        out[fill[a as usize] as usize] = TaskId(b);
        fill[a as usize] += 1;
    }
    for i in 0..n {
        out[offsets[i] as usize..offsets[i + 1] as usize].sort_unstable();
    }
    (offsets, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycle_is_reported_in_order() {
        let err = Precedence::new(4, &[(0, 1), (1, 2), (2, 3), (3, 1)]).unwrap_err();
        assert_eq!(err.len(), 3);
        // every consecutive pair of the witness is an edge
        let edges = [(0, 1), (1, 2), (2, 3), (3, 1)];
        for k in 0..err.len() {
            let (a, b) = (err[k], err[(k + 1) % err.len()]);
            assert!(edges.contains(&(a, b)), "{a}->{b} not an edge in {err:?}");
        }
    }

    #[test]
    fn self_loop_is_a_cycle() {
        assert_eq!(Precedence::new(2, &[(1, 1)]).unwrap_err(), vec![1]);
    }

    #[test]
    fn topological_respects_edges() {
        let p = Precedence::new(5, &[(4, 0), (3, 4), (2, 1)]).unwrap();
        let pos: Vec<usize> = {
            let mut pos = vec![0; 5];
            for (i, t) in p.topological().iter().enumerate() {
                pos[t.index()] = i;
            }
            pos
        };
        assert!(pos[4] < pos[0] && pos[3] < pos[4] && pos[2] < pos[1]);
    }
}
