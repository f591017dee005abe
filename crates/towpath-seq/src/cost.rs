//! Transition cost models.
//!
//! A cost model prices the move from one *state* (a machine configuration, a point) to another.
//! Tasks refer to states through their modes' entry and exit states; the solvers only ever ask a
//! [`CostModel`] for `cost(from, to)`, so a model may hold a dense matrix, compute distances on
//! demand from coordinates (so 100,000-task instances never need an n² matrix), or run a machine
//! motion model supplied by another crate.

use std::sync::Arc;

/// The cost of a transition. Integer-valued models (TSPLIB) are represented exactly.
pub type Cost = f64;

/// Identifies one state of a [`CostModel`]: an index in `0..model.num_states()`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StateId(pub u32);

impl StateId {
    /// The state's index as a `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Prices transitions between states.
///
/// Implementations must be deterministic and cheap to call; solvers call `cost` in their inner
/// loops. Costs may be asymmetric. A cost that is not finite marks a forbidden transition.
pub trait CostModel: Send + Sync {
    /// How many states the model knows; valid [`StateId`]s are `0..num_states()`.
    fn num_states(&self) -> usize;

    /// The cost of moving from `from` to `to`.
    fn cost(&self, from: StateId, to: StateId) -> Cost;

    /// True when `cost(a, b) == cost(b, a)` for every pair. Solvers use reversal moves only then.
    fn is_symmetric(&self) -> bool {
        false
    }

    /// A point in R³ for the state, if the model has one. Used only to build spatial neighbour
    /// lists (a spatial tree) instead of scanning all pairs; the cost itself always comes from
    /// [`CostModel::cost`].
    fn position(&self, _state: StateId) -> Option<[f64; 3]> {
        None
    }
}

impl<C: CostModel + ?Sized> CostModel for &C {
    fn num_states(&self) -> usize {
        (**self).num_states()
    }
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        (**self).cost(from, to)
    }
    fn is_symmetric(&self) -> bool {
        (**self).is_symmetric()
    }
    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        (**self).position(state)
    }
}

impl<C: CostModel + ?Sized> CostModel for Box<C> {
    fn num_states(&self) -> usize {
        (**self).num_states()
    }
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        (**self).cost(from, to)
    }
    fn is_symmetric(&self) -> bool {
        (**self).is_symmetric()
    }
    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        (**self).position(state)
    }
}

impl<C: CostModel + ?Sized> CostModel for Arc<C> {
    fn num_states(&self) -> usize {
        (**self).num_states()
    }
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        (**self).cost(from, to)
    }
    fn is_symmetric(&self) -> bool {
        (**self).is_symmetric()
    }
    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        (**self).position(state)
    }
}

/// A dense, row-major cost matrix; asymmetric costs allowed.
#[derive(Clone, Debug)]
pub struct MatrixCost {
    n: usize,
    data: Vec<Cost>,
    symmetric: bool,
}

impl MatrixCost {
    /// Builds a matrix from `n * n` row-major entries (`data[i * n + j]` is the cost i → j).
    /// Returns `None` if the length is not `n * n`.
    pub fn new(n: usize, data: Vec<Cost>) -> Option<Self> {
        if n.checked_mul(n)? != data.len() {
            return None;
        }
        let symmetric = (0..n).all(|i| (0..i).all(|j| data[i * n + j] == data[j * n + i]));
        Some(MatrixCost { n, data, symmetric })
    }

    /// Builds a matrix by evaluating `f(i, j)` for every pair.
    pub fn from_fn(n: usize, mut f: impl FnMut(usize, usize) -> Cost) -> Self {
        let mut data = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                data.push(f(i, j));
            }
        }
        // `from_fn` always produces n*n entries.
        let symmetric = (0..n).all(|i| (0..i).all(|j| data[i * n + j] == data[j * n + i]));
        MatrixCost { n, data, symmetric }
    }

    /// The row-major entries.
    pub fn data(&self) -> &[Cost] {
        &self.data
    }

    /// The dimension n.
    pub fn dimension(&self) -> usize {
        self.n
    }
}

impl CostModel for MatrixCost {
    fn num_states(&self) -> usize {
        self.n
    }
    #[inline]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        self.data[from.index() * self.n + to.index()]
    }
    fn is_symmetric(&self) -> bool {
        self.symmetric
    }
}

/// How a distance between two points is turned into a cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Euclidean distance, unrounded.
    Euclidean,
    /// Euclidean distance rounded to the nearest integer (TSPLIB `EUC_2D`, `EUC_3D`).
    EuclideanNint,
    /// Euclidean distance rounded up (TSPLIB `CEIL_2D`).
    EuclideanCeil,
    /// TSPLIB pseudo-Euclidean `ATT` distance.
    Att,
    /// Manhattan distance rounded to the nearest integer (TSPLIB `MAN_2D`, `MAN_3D`).
    ManhattanNint,
    /// Manhattan distance, unrounded.
    Manhattan,
    /// Chebyshev (maximum) distance rounded to the nearest integer (TSPLIB `MAX_2D`, `MAX_3D`).
    MaximumNint,
    /// TSPLIB geographical distance; coordinates are `DDD.MM` latitude/longitude.
    Geo,
}

/// Costs computed on demand from point coordinates, so no n² matrix is ever stored.
#[derive(Clone, Debug)]
pub struct PointCost {
    points: Vec<[f64; 3]>,
    metric: Metric,
    /// Precomputed radians for [`Metric::Geo`].
    geo: Vec<[f64; 2]>,
}

impl PointCost {
    /// Builds the model. For 2D data leave the third coordinate 0.
    pub fn new(points: Vec<[f64; 3]>, metric: Metric) -> Self {
        let geo = if metric == Metric::Geo {
            points.iter().map(|p| [geo_radians(p[0]), geo_radians(p[1])]).collect()
        } else {
            Vec::new()
        };
        PointCost { points, metric, geo }
    }

    /// The points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// The metric.
    pub fn metric(&self) -> Metric {
        self.metric
    }
}

/// Smallest integer not below `x` (x ≥ 0), without a libm call. For TSPLIB's `ATT` this equals
/// its "nint, plus one if below" rule.
#[inline]
fn ceil_pos(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t < x {
        t + 1.0
    } else {
        t
    }
}

impl PointCost {
    /// TSPLIB's geographical distance (kept out of line: it is rare and large).
    #[cold]
    #[inline(never)]
    fn geo_cost(&self, from: StateId, to: StateId) -> Cost {
        if from == to {
            return 0.0;
        }
        const RRR: f64 = 6378.388;
        let [lat1, lon1] = self.geo[from.index()];
        let [lat2, lon2] = self.geo[to.index()];
        let q1 = (lon1 - lon2).cos();
        let q2 = (lat1 - lat2).cos();
        let q3 = (lat1 + lat2).cos();
        (RRR * (0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)).acos() + 1.0).floor()
    }
}

/// TSPLIB's conversion of `DDD.MM` to radians (with its value of π).
fn geo_radians(x: f64) -> f64 {
    // TSPLIB's reference code uses this truncated value; distances must match it exactly.
    #[allow(clippy::approx_constant)]
    const PI: f64 = 3.141592;
    let deg = x.trunc();
    let min = x - deg;
    PI * (deg + 5.0 * min / 3.0) / 180.0
}

/// TSPLIB's `nint`: round half up, as `(int)(x + 0.5)` in the reference code (x ≥ 0 here, so
/// truncation is the floor; the cast avoids a libm call on baseline x86-64).
#[inline]
fn nint(x: f64) -> f64 {
    (x + 0.5) as i64 as f64
}

impl CostModel for PointCost {
    fn num_states(&self) -> usize {
        self.points.len()
    }

    #[inline(always)]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        let a = &self.points[from.index()];
        let b = &self.points[to.index()];
        let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
        match self.metric {
            Metric::Euclidean => (dx * dx + dy * dy + dz * dz).sqrt(),
            Metric::EuclideanNint => nint((dx * dx + dy * dy + dz * dz).sqrt()),
            Metric::EuclideanCeil => ceil_pos((dx * dx + dy * dy + dz * dz).sqrt()),
            Metric::Att => ceil_pos(((dx * dx + dy * dy) / 10.0).sqrt()),
            Metric::Manhattan => dx.abs() + dy.abs() + dz.abs(),
            Metric::ManhattanNint => nint(dx.abs() + dy.abs() + dz.abs()),
            Metric::MaximumNint => nint(dx.abs().max(dy.abs()).max(dz.abs())),
            Metric::Geo => self.geo_cost(from, to),
        }
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        match self.metric {
            // GEO coordinates are angles: a k-d tree on them would mislead near the poles and
            // the date line, so neighbour lists come from the costs instead.
            Metric::Geo => None,
            _ => Some(self.points[state.index()]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tsplib_roundings() {
        let p = PointCost::new(vec![[0.0, 0.0, 0.0], [3.0, 4.5, 0.0]], Metric::EuclideanNint);
        // sqrt(9 + 20.25) = 5.408 -> 5
        assert_eq!(p.cost(StateId(0), StateId(1)), 5.0);
        let p = PointCost::new(vec![[0.0, 0.0, 0.0], [3.0, 4.5, 0.0]], Metric::EuclideanCeil);
        assert_eq!(p.cost(StateId(0), StateId(1)), 6.0);
        // ATT: sqrt((100 + 0)/10) = 3.162 -> nint 3 < r -> 4
        let p = PointCost::new(vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]], Metric::Att);
        assert_eq!(p.cost(StateId(0), StateId(1)), 4.0);
    }

    #[test]
    fn matrix_symmetry_detected() {
        let m = MatrixCost::new(2, vec![0.0, 1.0, 1.0, 0.0]).unwrap();
        assert!(m.is_symmetric());
        let m = MatrixCost::new(2, vec![0.0, 1.0, 2.0, 0.0]).unwrap();
        assert!(!m.is_symmetric());
        assert!(MatrixCost::new(2, vec![0.0; 3]).is_none());
    }
}
