//! Pricing transits for the sequencer: a [`CostModel`] whose arcs cost what the planned transit
//! (the one the writer will write) costs under the machine's cost model.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use towpath_machine::MachineCost;
use towpath_seq::{Cost, CostModel, StateId};

use crate::plan::Planner;

/// Number of independently locked parts of the cache.
const SHARDS: usize = 64;

/// A [`CostModel`] over the states of a [`MachineCost`] that prices each arc as the transit
/// [`Planner::plan`] writes for it: straight where that is clear, else up, across and down,
/// each move priced by [`MachineCost::direct`]. An arc with no safe transit costs infinity
/// (forbidden).
///
/// Arcs are planned once and cached (the solver asks for the same arc many times). The cache is
/// shared between threads (sharded locks); a plan depends only on its two states, so the costs
/// are the same whatever the order of the calls, and symmetric.
#[derive(Debug)]
pub struct TransitCost {
    planner: Arc<Planner>,
    base: MachineCost,
    cache: Vec<Mutex<HashMap<(u32, u32), Cost>>>,
}

impl TransitCost {
    /// Prices the states of `base` (its machine, cost kind and states; a clearance set on it is
    /// ignored: the planner decides how transits lift) with `planner`.
    pub fn new(planner: Arc<Planner>, base: MachineCost) -> TransitCost {
        TransitCost { planner, base, cache: (0..SHARDS).map(|_| Mutex::new(HashMap::new())).collect() }
    }

    /// The planner.
    pub fn planner(&self) -> &Planner {
        &self.planner
    }

    /// The underlying machine cost and its states.
    pub fn base(&self) -> &MachineCost {
        &self.base
    }

    /// How many arcs have been planned so far.
    pub fn planned(&self) -> usize {
        self.cache.iter().map(|m| m.lock().map_or(0, |m| m.len())).sum()
    }
}

impl CostModel for TransitCost {
    fn num_states(&self) -> usize {
        self.base.num_states()
    }

    fn cost(&self, from: StateId, to: StateId) -> Cost {
        if from == to {
            return 0.0;
        }
        let key = if from.0 < to.0 { (from.0, to.0) } else { (to.0, from.0) };
        let shard = &self.cache[(key.0 as usize).wrapping_mul(31).wrapping_add(key.1 as usize) % SHARDS];
        if let Some(&c) = shard.lock().ok().and_then(|m| m.get(&key).copied()).as_ref() {
            return c;
        }
        let states = self.base.states();
        let c = self
            .planner
            .price(&self.base, states.get(StateId(key.0)), states.get(StateId(key.1)))
            .unwrap_or(f64::INFINITY);
        if let Ok(mut m) = shard.lock() {
            m.insert(key, c);
        }
        c
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        self.base.position(state)
    }
}
