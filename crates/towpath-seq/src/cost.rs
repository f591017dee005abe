//! Transition cost models.
//!
//! A cost model prices the move from one *state* (a machine configuration, a point) to another.
//! Tasks refer to states through their modes' entry and exit states; the solvers only ever ask a
//! [`CostModel`] for `cost(from, to)`, so a model may hold a dense matrix, compute distances on
//! demand from coordinates (so 100,000-task instances never need an n² matrix), or run a machine
//! motion model supplied by another crate.

use std::sync::Arc;

/// The cost of a transition. Integer-valued models (TSPLIB) are represented exactly while
/// the sums stay below [`EXACT_INTEGER_LIMIT`].
pub type Cost = f64;

/// The largest cost a route may reach (a bound taken from [`CostModel::cost_bound`] when the
/// problem is built). Far beyond any real job, it leaves room for what is computed from costs:
/// squared coordinate differences of point models, and the solver's price of a forbidden move
/// (a million times the largest cost) summed over a whole route, all stay finite.
pub const MAX_ROUTE_COST: Cost = 1e150;

/// 2⁵³: every integer up to it is exact in a [`Cost`]. Integer costs (TSPLIB's rounded
/// distances and matrices) sum exactly while a route's total stays below it; readers of integer
/// formats refuse instances whose routes could exceed it.
pub const EXACT_INTEGER_LIMIT: Cost = 9_007_199_254_740_992.0;

/// 2⁵²: from here on every `f64` is an integer, so rounding leaves it unchanged (and adding
/// one half would round to even).
const INTEGRAL_FROM: f64 = 4_503_599_627_370_496.0;

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

    /// An upper bound on the magnitude of every finite cost, if the model knows one without
    /// pricing every pair. [`crate::ProblemBuilder::build`] uses it to refuse problems whose
    /// routes could cost more than [`MAX_ROUTE_COST`]. `None` (the default) means unknown.
    fn cost_bound(&self) -> Option<Cost> {
        None
    }

    /// When every cost is the Euclidean distance between two points of a plane (rounded as the
    /// answer says), those points, by state: a solver may then compute costs inline in its
    /// innermost loop. The answer must give exactly what [`CostModel::cost`] gives. `None`
    /// (the default) means costs come only from `cost`.
    fn planar_euclid(&self) -> Option<PlanarEuclid> {
        None
    }
}

/// How a Euclidean distance is rounded into a cost (see [`PlanarEuclid`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rounding {
    /// Not rounded.
    None,
    /// To the nearest integer, halves up ([`nint`]).
    Nint,
    /// Up ([`ceil_nonneg`]).
    Ceil,
}

/// Points of a plane whose rounded Euclidean distances are a model's costs (see
/// [`CostModel::planar_euclid`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarEuclid {
    /// The point of each state.
    pub xy: Vec<[f64; 2]>,
    /// How a distance becomes a cost.
    pub rounding: Rounding,
}

impl PlanarEuclid {
    /// The cost between states `a` and `b`: the same arithmetic as [`Metric::cost`] with no
    /// third coordinate.
    #[inline(always)]
    pub fn cost(&self, a: usize, b: usize) -> Cost {
        let (p, q) = (self.xy[a], self.xy[b]);
        let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
        let d = (dx * dx + dy * dy).sqrt();
        match self.rounding {
            Rounding::None => d,
            Rounding::Nint => nint(d),
            Rounding::Ceil => ceil_nonneg(d),
        }
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
    fn cost_bound(&self) -> Option<Cost> {
        (**self).cost_bound()
    }
    fn planar_euclid(&self) -> Option<PlanarEuclid> {
        (**self).planar_euclid()
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
    fn cost_bound(&self) -> Option<Cost> {
        (**self).cost_bound()
    }
    fn planar_euclid(&self) -> Option<PlanarEuclid> {
        (**self).planar_euclid()
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
    fn cost_bound(&self) -> Option<Cost> {
        (**self).cost_bound()
    }
    fn planar_euclid(&self) -> Option<PlanarEuclid> {
        (**self).planar_euclid()
    }
}

/// A dense, row-major cost matrix; asymmetric costs allowed.
#[derive(Clone, Debug)]
pub struct MatrixCost {
    n: usize,
    data: Vec<Cost>,
    symmetric: bool,
    /// The largest magnitude of a finite entry.
    bound: Cost,
}

impl MatrixCost {
    /// Builds a matrix from `n * n` row-major entries (`data[i * n + j]` is the cost i → j).
    /// Returns `None` if the length is not `n * n`.
    pub fn new(n: usize, data: Vec<Cost>) -> Option<Self> {
        if n.checked_mul(n)? != data.len() {
            return None;
        }
        let symmetric = (0..n).all(|i| (0..i).all(|j| data[i * n + j] == data[j * n + i]));
        let bound = finite_bound(&data);
        Some(MatrixCost { n, data, symmetric, bound })
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
        let bound = finite_bound(&data);
        MatrixCost { n, data, symmetric, bound }
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
    fn cost_bound(&self) -> Option<Cost> {
        Some(self.bound)
    }
}

/// The largest magnitude of the finite values (0 if none).
fn finite_bound(data: &[Cost]) -> Cost {
    data.iter().filter(|c| c.is_finite()).fold(0.0, |m: Cost, c| m.max(c.abs()))
}

/// How a distance between two points becomes a cost: the inner loop of every point-based
/// problem. [`Metric`] holds the usual ones; a reader of a file format with its own conventions
/// (TSPLIB's `ATT` and `GEO`, in `towpath-formats`) supplies its own, and the solver is compiled
/// for it with no dynamic dispatch.
pub trait PointMetric: Copy + PartialEq + std::fmt::Debug + Send + Sync + 'static {
    /// The cost from point `from` to point `to` of `points` (must equal the cost back). Indices
    /// rather than coordinates, so that a metric may tell a state from another at the same
    /// place (TSPLIB's `GEO` prices those 1, not 0).
    fn cost(self, points: &[[f64; 3]], from: usize, to: usize) -> Cost;

    /// True when every cost is an integer.
    fn is_integral(self) -> bool;

    /// A bound on the cost between any two points whose coordinates differ by at most
    /// `extent` along each axis (infinite if an extent is).
    fn bound(self, extent: [f64; 3]) -> Cost;

    /// True when the coordinates are positions in space, so that a spatial tree over them finds
    /// near states (false for angles such as latitude and longitude).
    fn is_spatial(self) -> bool {
        true
    }

    /// When the cost is the Euclidean distance of the points, rounded as the answer says
    /// (exactly the arithmetic of [`PlanarEuclid::cost`] where the third coordinates are 0).
    fn euclid_rounding(self) -> Option<Rounding> {
        None
    }
}

/// How a distance between two points is turned into a cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Euclidean distance, unrounded.
    Euclidean,
    /// Euclidean distance rounded to the nearest integer, halves up (TSPLIB `EUC_2D`, `EUC_3D`).
    EuclideanNint,
    /// Euclidean distance rounded up (TSPLIB `CEIL_2D`).
    EuclideanCeil,
    /// Manhattan distance rounded to the nearest integer (TSPLIB `MAN_2D`, `MAN_3D`).
    ManhattanNint,
    /// Manhattan distance, unrounded.
    Manhattan,
    /// Chebyshev (maximum) distance rounded to the nearest integer (TSPLIB `MAX_2D`, `MAX_3D`).
    MaximumNint,
}

/// Costs computed on demand from point coordinates, so no n² matrix is ever stored.
#[derive(Clone, Debug)]
pub struct PointCost<M: PointMetric = Metric> {
    points: Vec<[f64; 3]>,
    metric: M,
    /// A bound on every cost (see [`CostModel::cost_bound`]).
    bound: Cost,
}

impl<M: PointMetric> PointCost<M> {
    /// Builds the model. For 2D data leave the third coordinate 0.
    pub fn new(points: Vec<[f64; 3]>, metric: M) -> Self {
        let bound = metric.bound(extents(&points));
        PointCost { points, metric, bound }
    }

    /// The two states whose coordinates differ most along one axis (the first such pair by
    /// index), if there are two states: where a message about too large distances points.
    pub fn farthest_apart(&self) -> Option<(StateId, StateId)> {
        if self.points.len() < 2 {
            return None;
        }
        let mut best: Option<(f64, usize, usize)> = None;
        for k in 0..3 {
            let (mut lo, mut hi) = (0, 0);
            for (i, p) in self.points.iter().enumerate() {
                if p[k] < self.points[lo][k] {
                    lo = i;
                }
                if p[k] > self.points[hi][k] {
                    hi = i;
                }
            }
            let spread = self.points[hi][k] - self.points[lo][k];
            if best.is_none_or(|b| spread > b.0) && lo != hi {
                best = Some((spread, lo.min(hi), lo.max(hi)));
            }
        }
        let (_, a, b) = best.unwrap_or((0.0, 0, 1));
        Some((StateId(a as u32), StateId(b as u32)))
    }

    /// True when every cost is an integer (the rounded metrics).
    pub fn is_integral(&self) -> bool {
        self.metric.is_integral()
    }

    /// The points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// The metric.
    pub fn metric(&self) -> M {
        self.metric
    }
}

impl PointMetric for Metric {
    #[inline(always)]
    fn cost(self, points: &[[f64; 3]], from: usize, to: usize) -> Cost {
        let (a, b) = (&points[from], &points[to]);
        let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
        match self {
            Metric::Euclidean => (dx * dx + dy * dy + dz * dz).sqrt(),
            Metric::EuclideanNint => nint((dx * dx + dy * dy + dz * dz).sqrt()),
            Metric::EuclideanCeil => ceil_nonneg((dx * dx + dy * dy + dz * dz).sqrt()),
            Metric::Manhattan => dx.abs() + dy.abs() + dz.abs(),
            Metric::ManhattanNint => nint(dx.abs() + dy.abs() + dz.abs()),
            Metric::MaximumNint => nint(dx.abs().max(dy.abs()).max(dz.abs())),
        }
    }

    fn is_integral(self) -> bool {
        !matches!(self, Metric::Euclidean | Metric::Manhattan)
    }

    fn euclid_rounding(self) -> Option<Rounding> {
        match self {
            Metric::Euclidean => Some(Rounding::None),
            Metric::EuclideanNint => Some(Rounding::Nint),
            Metric::EuclideanCeil => Some(Rounding::Ceil),
            Metric::Manhattan | Metric::ManhattanNint | Metric::MaximumNint => None,
        }
    }

    fn bound(self, extent: [f64; 3]) -> Cost {
        let [x, y, z] = extent;
        match self {
            Metric::Euclidean => norm(x, y, z),
            Metric::EuclideanNint | Metric::EuclideanCeil => norm(x, y, z) + 1.0,
            Metric::Manhattan => x + y + z,
            Metric::ManhattanNint => x + y + z + 1.0,
            Metric::MaximumNint => x.max(y).max(z) + 1.0,
        }
    }
}

/// The Euclidean norm of a vector without overflow in the squares.
pub fn norm(x: f64, y: f64, z: f64) -> f64 {
    let m = x.abs().max(y.abs()).max(z.abs());
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let (a, b, c) = (x / m, y / m, z / m);
    m * (a * a + b * b + c * c).sqrt()
}

/// How far apart the points are along each axis (max − min; infinite if that overflows).
fn extents(points: &[[f64; 3]]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (k, e) in out.iter_mut().enumerate() {
        let lo = points.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = points.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        if hi >= lo {
            *e = hi - lo;
        }
        if points.iter().any(|p| p[k].is_nan()) {
            *e = f64::INFINITY;
        }
    }
    out
}

/// Smallest integer not below `x` (x ≥ 0), without a libm call. Exact for every `x`: from 2⁵²
/// on `x` is an integer.
#[inline]
pub fn ceil_nonneg(x: f64) -> f64 {
    if x >= INTEGRAL_FROM || x.is_nan() {
        return x;
    }
    let t = x as i64 as f64;
    if t < x {
        t + 1.0
    } else {
        t
    }
}

/// TSPLIB's `nint`: round half up, as `(int)(x + 0.5)` in the reference code (x ≥ 0 here, so
/// truncation is the floor; the cast avoids a libm call on baseline x86-64). Exact for every
/// `x`, where the reference code's `int` would overflow: from 2⁵² on `x` is an integer (and
/// the cast would saturate at 2⁶³).
#[inline]
pub fn nint(x: f64) -> f64 {
    if x >= INTEGRAL_FROM || x.is_nan() {
        return x;
    }
    (x + 0.5) as i64 as f64
}

impl<M: PointMetric> CostModel for PointCost<M> {
    fn num_states(&self) -> usize {
        self.points.len()
    }

    #[inline(always)]
    fn cost(&self, from: StateId, to: StateId) -> Cost {
        self.metric.cost(&self.points, from.index(), to.index())
    }

    fn is_symmetric(&self) -> bool {
        true
    }

    fn cost_bound(&self) -> Option<Cost> {
        Some(self.bound)
    }

    fn position(&self, state: StateId) -> Option<[f64; 3]> {
        // Angles (latitude and longitude) would mislead a spatial tree near the poles and the
        // date line, so their neighbour lists come from the costs instead.
        self.metric.is_spatial().then(|| self.points[state.index()])
    }

    fn planar_euclid(&self) -> Option<PlanarEuclid> {
        let rounding = self.metric.euclid_rounding()?;
        // a third coordinate of -0.0 squares to +0.0 as 0.0 does, so "== 0.0" is enough
        self.points
            .iter()
            .all(|p| p[2] == 0.0)
            .then(|| PlanarEuclid { xy: self.points.iter().map(|p| [p[0], p[1]]).collect(), rounding })
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
    }

    proptest::proptest! {
        /// The roundings agree with libm's `floor`/`ceil` (an independent computation) on
        /// every magnitude, far beyond where the integer cast would saturate.
        #[test]
        fn roundings_exact_at_every_magnitude(mantissa in 1.0f64..10.0, exp in -3i32..300) {
            let x = mantissa * 10f64.powi(exp);
            // round half up: the floor, plus one if the fraction (exact in floating point) is ≥ ½
            let half_up = x.floor() + if x - x.floor() >= 0.5 { 1.0 } else { 0.0 };
            proptest::prop_assert_eq!(nint(x), half_up);
            proptest::prop_assert_eq!(ceil_nonneg(x), x.ceil());
        }
    }

    #[test]
    fn large_coordinates_do_not_saturate() {
        // Points on a line at 0, 1e19, 2e19, 3e19, 4e19 (issue 17): every rounded distance is
        // the exact difference, not 2^63.
        let xs = [0.0, 3e19, 1e19, 4e19, 2e19];
        let pts: Vec<[f64; 3]> = xs.iter().map(|&x| [x, 0.0, 0.0]).collect();
        for metric in [Metric::EuclideanNint, Metric::EuclideanCeil, Metric::ManhattanNint, Metric::MaximumNint] {
            let p = PointCost::new(pts.clone(), metric);
            for i in 0..5 {
                for j in 0..5 {
                    assert_eq!(p.cost(StateId(i), StateId(j)), (xs[i as usize] - xs[j as usize]).abs(), "{metric:?}");
                }
            }
            assert!(p.cost_bound().unwrap() >= 4e19);
            assert_eq!(p.farthest_apart(), Some((StateId(0), StateId(3))));
        }
    }

    #[test]
    fn bounds_cover_every_cost() {
        // Pseudo-random points; the bound is at least every pairwise cost, for every metric.
        let mut x = 12345u64;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.3) * 2000.0
        };
        let pts: Vec<[f64; 3]> = (0..40).map(|_| [next(), next(), next()]).collect();
        for metric in [
            Metric::Euclidean,
            Metric::EuclideanNint,
            Metric::EuclideanCeil,
            Metric::Manhattan,
            Metric::ManhattanNint,
            Metric::MaximumNint,
        ] {
            let p = PointCost::new(pts.clone(), metric);
            let bound = p.cost_bound().unwrap();
            let max = (0..40u32)
                .flat_map(|i| (0..40u32).map(move |j| (i, j)))
                .map(|(i, j)| p.cost(StateId(i), StateId(j)))
                .fold(0.0, f64::max);
            assert!(max <= bound && bound <= 2.0 * max + 2.0, "{metric:?}: max {max}, bound {bound}");
        }
        let m = MatrixCost::new(2, vec![0.0, -7.0, f64::INFINITY, 3.0]).unwrap();
        assert_eq!(m.cost_bound(), Some(7.0));
        let far = vec![[0.0, 0.0, 0.0], [f64::MAX, 0.0, 0.0], [-f64::MAX, 0.0, 0.0]];
        assert_eq!(PointCost::new(far, Metric::Euclidean).cost_bound(), Some(f64::INFINITY));
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
