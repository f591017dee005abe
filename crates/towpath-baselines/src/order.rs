//! Building a route one task at a time while keeping it feasible: precedence, consecutive groups
//! and pinned first/last tasks. The constructive solvers (the GA's decoder, the ants) ask which
//! tasks may come next and take one.
//!
//! The seed papers' GA and ACO have no precedence (seed 004's open rural postman problem has
//! none); on problems that do, these solvers only ever choose among the tasks this builder
//! allows, so their routes stay feasible.

use towpath_seq::{CostModel, Problem, TaskId};

/// Feasibility bookkeeping for a route under construction.
#[derive(Clone, Debug)]
pub(crate) struct OrderBuilder<'p, C> {
    p: &'p Problem<C>,
    /// Predecessors not yet done, per task.
    indeg: Vec<u32>,
    /// Predecessors outside the group not yet done, per group.
    group_ext: Vec<u32>,
    /// Members not yet done, per group.
    group_left: Vec<u32>,
    /// The group being worked through, if any.
    open_group: Option<usize>,
    done: Vec<bool>,
    count: usize,
    /// True when the problem has no precedence, groups or pins: every undone task is allowed.
    free: bool,
}

impl<'p, C: CostModel> OrderBuilder<'p, C> {
    pub fn new(p: &'p Problem<C>) -> Self {
        let n = p.num_tasks();
        let prec = p.precedence();
        let indeg: Vec<u32> = p.tasks().map(|t| prec.predecessors(t).len() as u32).collect();
        let mut group_ext = vec![0u32; p.groups().len()];
        for t in p.tasks() {
            if let Some(g) = p.group_of(t) {
                group_ext[g] += prec.predecessors(t).iter().filter(|&&q| p.group_of(q) != Some(g)).count() as u32;
            }
        }
        let free =
            prec.num_edges() == 0 && p.groups().is_empty() && p.first_task().is_none() && p.last_task().is_none();
        OrderBuilder {
            p,
            indeg,
            group_ext,
            group_left: p.groups().iter().map(|g| g.len() as u32).collect(),
            open_group: None,
            done: vec![false; n],
            count: 0,
            free,
        }
    }

    /// True when the problem imposes nothing on the order.
    pub fn is_free(&self) -> bool {
        self.free
    }

    /// Tasks taken so far.
    pub fn len(&self) -> usize {
        self.count
    }

    /// May task `t` come next?
    pub fn allowed(&self, t: u32) -> bool {
        let i = t as usize;
        if self.done[i] {
            return false;
        }
        if self.free {
            return true;
        }
        if self.indeg[i] != 0 {
            return false;
        }
        let n = self.done.len();
        if let Some(f) = self.p.first_task() {
            if !self.done[f.index()] && f.0 != t {
                return false;
            }
        }
        if let Some(l) = self.p.last_task() {
            if l.0 == t && self.count + 1 < n {
                return false;
            }
        }
        let g = self.p.group_of(TaskId(t));
        match self.open_group {
            Some(og) => g == Some(og),
            None => g.is_none_or(|g| self.group_ext[g] == 0),
        }
    }

    /// Marks `t` done (it must be allowed).
    pub fn take(&mut self, t: u32) {
        let p = self.p;
        let i = t as usize;
        self.done[i] = true;
        self.count += 1;
        if self.free {
            return;
        }
        let g = p.group_of(TaskId(t));
        for &s in p.precedence().successors(TaskId(t)) {
            self.indeg[s.index()] -= 1;
            if let Some(gs) = p.group_of(s) {
                if g != Some(gs) {
                    self.group_ext[gs] -= 1;
                }
            }
        }
        if let Some(g) = g {
            self.group_left[g] -= 1;
            self.open_group = if self.group_left[g] > 0 { Some(g) } else { None };
        }
    }
}
