//! Cost models over machine states (axis vectors), for the sequencing engine.

use std::str::FromStr;

use serde::{Deserialize, Serialize};
use towpath_seq::{Cost, CostModel, StateId};

use crate::config::Machine;
use crate::kinematics::Kinematics;

/// How a move is priced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CostKind {
    /// Seed 000's weighted axis distance Σ C(a)·|Δa| (mm and degrees, weighted).
    Axis,
    /// Move time in seconds, all axes together, trapezoidal profile per axis.
    Time,
    /// Straight-line distance of the tool point in the part frame, mm.
    Tool,
}

impl CostKind {
    /// All kinds, in report order.
    pub const ALL: [CostKind; 3] = [CostKind::Axis, CostKind::Time, CostKind::Tool];

    /// The kind's name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CostKind::Axis => "axis",
            CostKind::Time => "time",
            CostKind::Tool => "tool",
        }
    }

    /// The unit of the cost.
    pub fn unit(self) -> &'static str {
        match self {
            CostKind::Axis => "weighted mm+deg",
            CostKind::Time => "s",
            CostKind::Tool => "mm",
        }
    }
}

impl FromStr for CostKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "axis" => Ok(CostKind::Axis),
            "time" => Ok(CostKind::Time),
            "tool" => Ok(CostKind::Tool),
            _ => Err(format!("unknown cost model {s:?}: expected axis, time or tool")),
        }
    }
}

impl std::fmt::Display for CostKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a cost model cannot be built for a machine.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CostError {
    /// The time cost needs a velocity limit on every axis.
    #[error("the time cost needs max_velocity on every axis; missing on {0}")]
    MissingVelocity(String),
    /// The tool cost needs kinematics.
    #[error("the tool cost needs the tool point: give the machine a DH chain or X/Y/Z linear axes")]
    NoKinematics,
    /// A state has the wrong number of values.
    #[error("a state has {got} values but the machine has {expected} axes")]
    WrongDimension {
        /// Values given.
        got: usize,
        /// Axes of the machine.
        expected: usize,
    },
    /// A state value is not finite.
    #[error("state value {0} is not finite")]
    NotFinite(f64),
    /// The clearance axis or value cannot be used.
    #[error("clearance: {0}")]
    Clearance(String),
}

/// A table of machine states (axis vectors of one length), addressed by [`StateId`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StateTable {
    dim: usize,
    values: Vec<f64>,
}

impl StateTable {
    /// An empty table for states of `dim` values.
    pub fn new(dim: usize) -> Self {
        StateTable { dim, values: Vec::new() }
    }

    /// Adds a state and returns its id.
    pub fn push(&mut self, state: &[f64]) -> Result<StateId, CostError> {
        if state.len() != self.dim {
            return Err(CostError::WrongDimension { got: state.len(), expected: self.dim });
        }
        if let Some(v) = state.iter().find(|v| !v.is_finite()) {
            return Err(CostError::NotFinite(*v));
        }
        self.values.extend_from_slice(state);
        Ok(StateId((self.len() - 1) as u32))
    }

    /// The values of a state.
    #[inline]
    pub fn get(&self, s: StateId) -> &[f64] {
        let a = s.index() * self.dim;
        &self.values[a..a + self.dim]
    }

    /// Number of states.
    pub fn len(&self) -> usize {
        self.values.len().checked_div(self.dim).unwrap_or(0)
    }

    /// True if the table holds no states.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Values per state.
    pub fn dim(&self) -> usize {
        self.dim
    }
}

/// A machine motion cost over a table of states: implements [`CostModel`].
///
/// Transitions take continuous and mandrel axes the short way round. The model is symmetric.
/// When the machine has kinematics, states have positions (the part-frame tool point) so the
/// solver can build neighbour lists from a k-d tree.
#[derive(Clone, Debug)]
pub struct MachineCost {
    machine: Machine,
    kind: CostKind,
    kin: Option<Kinematics>,
    states: StateTable,
    points: Vec<[f64; 3]>,
    /// Transits go by way of this value of this (linear) axis; see [`MachineCost::with_clearance`].
    clearance: Option<(usize, f64)>,
}

impl MachineCost {
    /// Builds the model; refuses a time cost without velocity limits and a tool cost without
    /// kinematics.
    pub fn new(machine: Machine, kind: CostKind, states: StateTable) -> Result<Self, CostError> {
        if states.dim() != machine.dim() && !states.is_empty() {
            return Err(CostError::WrongDimension { got: states.dim(), expected: machine.dim() });
        }
        let kin = machine.kinematics();
        match kind {
            CostKind::Time => {
                let missing = machine.axes_without_velocity();
                if !missing.is_empty() {
                    return Err(CostError::MissingVelocity(missing.join(", ")));
                }
            }
            CostKind::Tool if kin.is_none() => return Err(CostError::NoKinematics),
            _ => {}
        }
        let points = match &kin {
            Some(k) => (0..states.len()).map(|i| k.part_point(states.get(StateId(i as u32)))).collect(),
            None => Vec::new(),
        };
        Ok(MachineCost { machine, kind, kin, states, points, clearance: None })
    }

    /// Transitions by way of a clearance value of linear axis `axis`: a transition that moves
    /// any other axis goes to `value` on that axis first, then moves the other axes, then goes
    /// to its target's value (three moves, each priced as a direct move); one that moves only
    /// that axis stays a direct move. The model stays symmetric and obeys the triangle
    /// inequality.
    pub fn with_clearance(mut self, axis: usize, value: f64) -> Result<Self, CostError> {
        match self.machine.axes.get(axis) {
            None => return Err(CostError::Clearance(format!("the machine has no axis {axis}"))),
            Some(a) if a.kind != crate::AxisKind::Linear => {
                return Err(CostError::Clearance(format!("axis {} is not a linear axis", a.label)))
            }
            Some(_) if !value.is_finite() => return Err(CostError::Clearance(format!("{value} is not finite"))),
            Some(_) => {}
        }
        self.clearance = Some((axis, value));
        Ok(self)
    }

    /// The clearance axis and value, if transitions go by way of one.
    pub fn clearance(&self) -> Option<(usize, f64)> {
        self.clearance
    }

    /// The machine.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The cost kind.
    pub fn kind(&self) -> CostKind {
        self.kind
    }

    /// The states.
    pub fn states(&self) -> &StateTable {
        &self.states
    }

    /// The cost of a move from `from` to `to` whose per-axis travel is `deltas` (which may differ
    /// from `to − from` for axes that wrap), at the axes' limits (a rapid move).
    pub fn segment(&self, from: &[f64], to: &[f64], deltas: &[f64]) -> Cost {
        match self.kind {
            CostKind::Axis => self.machine.weighted_distance(deltas),
            CostKind::Time => self.machine.move_time(deltas),
            CostKind::Tool => match &self.kin {
                Some(k) => dist(k.part_point(from), k.part_point(to)),
                None => 0.0,
            },
        }
    }

    /// Like [`MachineCost::segment`] for a feed move at `feed` (mm/s, or deg/s for angular
    /// axes alone; see [`Machine::feed_move_time`]): the time cost respects the feed, the
    /// distance costs do not depend on it. `None` prices a rapid move.
    pub fn segment_at(&self, from: &[f64], to: &[f64], deltas: &[f64], feed: Option<f64>) -> Cost {
        match (self.kind, feed) {
            (CostKind::Time, Some(f)) => self.machine.feed_move_time(deltas, f),
            _ => self.segment(from, to, deltas),
        }
    }

    /// The cost of a transition between two states: the shortest direct move (wrapping axes the
    /// short way), or with a clearance ([`MachineCost::with_clearance`]) the three moves by way
    /// of it when an axis other than the clearance axis moves.
    pub fn between(&self, from: &[f64], to: &[f64]) -> Cost {
        if let Some((z, h)) = self.clearance {
            let others_move =
                (0..from.len()).any(|i| i != z && self.machine.short_delta(i, from[i], to[i]).abs() > 1e-9);
            if others_move {
                let (mut up, mut over) = (from.to_vec(), to.to_vec());
                up[z] = h;
                over[z] = h;
                return self.direct(from, &up) + self.direct(&up, &over) + self.direct(&over, to);
            }
        }
        self.direct(from, to)
    }

    /// The cost of the shortest direct move between two states (wrapping axes the short way).
    pub fn direct(&self, from: &[f64], to: &[f64]) -> Cost {
        match self.kind {
            CostKind::Tool => self.segment(from, to, &[]),
            _ => {
                let mut deltas = [0.0f64; 16];
                if from.len() <= deltas.len() {
                    for i in 0..from.len() {
                        deltas[i] = self.machine.short_delta(i, from[i], to[i]);
                    }
                    self.segment(from, to, &deltas[..from.len()])
                } else {
                    let d: Vec<f64> = (0..from.len()).map(|i| self.machine.short_delta(i, from[i], to[i])).collect();
                    self.segment(from, to, &d)
                }
            }
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

impl CostModel for MachineCost {
    fn num_states(&self) -> usize {
        self.states.len()
    }

    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        if self.kind == CostKind::Tool && self.clearance.is_none() {
            return dist(self.points[from.index()], self.points[to.index()]);
        }
        self.between(self.states.get(from), self.states.get(to))
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        // Positions only guide the solver's neighbour lists. They are nudged by less than a
        // micrometre, differently per state, because the k-d tree behind those lists (kiddo 4.2
        // `ImmutableKdTree`) panics when a coordinate is the same for every point, as the tool
        // height of every transit state often is.
        self.points.get(state.index()).map(|p| {
            let h = (state.0 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let nudge = |k: u32| ((h >> (k * 16)) & 0xFFFF) as f64 * 1e-11;
            [p[0] + nudge(0), p[1] + nudge(1), p[2] + nudge(2)]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Axis, AxisKind};
    use proptest::prelude::*;

    fn machine() -> Machine {
        let mut x = Axis::new("X", AxisKind::Linear);
        x.max_velocity = Some(500.0);
        x.max_acceleration = Some(1000.0);
        let mut y = Axis::new("Y", AxisKind::Linear);
        y.max_velocity = Some(500.0);
        y.weight = 0.5;
        let mut a = Axis::new("A", AxisKind::Mandrel);
        a.max_velocity = Some(90.0);
        a.weight = 2.0;
        Machine::new("m", vec![x, y, a]).unwrap()
    }

    #[test]
    fn axis_cost_is_weighted_and_wraps_the_mandrel() {
        let mut t = StateTable::new(3);
        let s0 = t.push(&[0.0, 0.0, 350.0]).unwrap();
        let s1 = t.push(&[10.0, 20.0, 10.0]).unwrap();
        let c = MachineCost::new(machine(), CostKind::Axis, t).unwrap();
        // 10 + 0.5*20 + 2*20 (short way, not 340).
        assert_eq!(c.cost(s0, s1), 60.0);
        assert_eq!(c.cost(s1, s0), 60.0);
    }

    #[test]
    fn refusals() {
        let mut m = machine();
        m.axes[1].max_velocity = None;
        let e = MachineCost::new(m, CostKind::Time, StateTable::new(3)).unwrap_err();
        assert_eq!(e.to_string(), "the time cost needs max_velocity on every axis; missing on Y");
        let r = Machine::new("r", vec![Axis::new("A", AxisKind::Rotary)]).unwrap();
        assert_eq!(MachineCost::new(r, CostKind::Tool, StateTable::new(1)).unwrap_err(), CostError::NoKinematics);
        let mut t = StateTable::new(2);
        assert!(t.push(&[1.0]).is_err());
        assert!(t.push(&[1.0, f64::NAN]).is_err());
    }

    /// With a clearance on Y (at 150), a transition that moves X or the mandrel goes up, across
    /// and down; one that moves Y alone stays direct.
    #[test]
    fn clearance_transits_go_up_across_and_down() {
        let mut t = StateTable::new(3);
        let s0 = t.push(&[0.0, 100.0, 0.0]).unwrap();
        let s1 = t.push(&[40.0, 120.0, 0.0]).unwrap();
        let s2 = t.push(&[0.0, 20.0, 0.0]).unwrap();
        let c = MachineCost::new(machine(), CostKind::Axis, t.clone()).unwrap().with_clearance(1, 150.0).unwrap();
        // Up 50 (weight 0.5), across 40, down 30 (weight 0.5).
        assert_eq!(c.cost(s0, s1), 25.0 + 40.0 + 15.0);
        assert_eq!(c.cost(s1, s0), 80.0);
        assert_eq!(c.cost(s0, s2), 0.5 * 80.0);
        let tool = MachineCost::new(machine(), CostKind::Tool, t).unwrap().with_clearance(1, 150.0).unwrap();
        assert!((tool.cost(s0, s1) - 120.0).abs() < 1e-9);
        let e = MachineCost::new(machine(), CostKind::Axis, StateTable::new(3)).unwrap().with_clearance(2, 1.0);
        assert_eq!(e.unwrap_err().to_string(), "clearance: axis A is not a linear axis");
    }

    #[test]
    fn tool_cost_in_the_part_frame() {
        let mut t = StateTable::new(3);
        // Same machine point, mandrel turned by 180°: the tool crosses the part's diameter.
        let s0 = t.push(&[0.0, 100.0, 0.0]).unwrap();
        let s1 = t.push(&[0.0, 100.0, 180.0]).unwrap();
        let c = MachineCost::new(machine(), CostKind::Tool, t).unwrap();
        assert!((c.cost(s0, s1) - 200.0).abs() < 1e-9);
        assert!(c.position(s0).is_some());
    }

    proptest! {
        #[test]
        fn costs_are_symmetric_and_obey_the_triangle_inequality(
            a in proptest::array::uniform3(-1000.0f64..1000.0),
            b in proptest::array::uniform3(-1000.0f64..1000.0),
            c in proptest::array::uniform3(-1000.0f64..1000.0),
        ) {
            let mut t = StateTable::new(3);
            let (sa, sb, sc) = (t.push(&a).unwrap(), t.push(&b).unwrap(), t.push(&c).unwrap());
            for (kind, clearance) in CostKind::ALL.into_iter().flat_map(|k| [(k, None), (k, Some(150.0))]) {
                let mut m = MachineCost::new(machine(), kind, t.clone()).unwrap();
                if let Some(h) = clearance {
                    m = m.with_clearance(1, h).unwrap();
                }
                let ab = m.cost(sa, sb);
                prop_assert!((ab - m.cost(sb, sa)).abs() <= 1e-9 * (1.0 + ab));
                // Direct moves are never dearer than going through a third state: the
                // rewriter relies on this when it replaces a transit by one move.
                prop_assert!(ab <= m.cost(sa, sc) + m.cost(sc, sb) + 1e-9 * (1.0 + ab), "{kind} {clearance:?}");
                prop_assert!(m.cost(sa, sa).abs() < 1e-12);
            }
        }
    }
}
