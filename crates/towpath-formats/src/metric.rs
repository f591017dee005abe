//! The point metrics a problem file can name: towpath-seq's own [`Metric`]s and TSPLIB's two
//! conventions that are not plain geometry, `ATT` and `GEO` (Reinelt 1991, "TSPLIB — A
//! Traveling Salesman Problem Library", and its documentation of 1995). They live here, with
//! the format that defines them, and reach the solver through [`PointMetric`].

use towpath_seq::{ceil_nonneg, norm, Cost, Metric, PointMetric, Rounding};

/// The metric of a coordinate file (TSPLIB `EDGE_WEIGHT_TYPE` or towpath JSON `metric`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileMetric {
    /// One of the solver's own metrics.
    Plain(Metric),
    /// TSPLIB pseudo-Euclidean `ATT`: √((dx² + dy²)/10), rounded up.
    Att,
    /// TSPLIB geographical `GEO`: coordinates are `DDD.MM` latitude and longitude, the cost the
    /// great-circle distance in km on TSPLIB's idealised sphere, rounded down after adding 1.
    Geo,
}

/// TSPLIB's earth radius in km.
const GEO_RADIUS: f64 = 6378.388;

impl PointMetric for FileMetric {
    #[inline(always)]
    fn cost(self, points: &[[f64; 3]], from: usize, to: usize) -> Cost {
        match self {
            FileMetric::Plain(m) => m.cost(points, from, to),
            FileMetric::Att => {
                let (a, b) = (&points[from], &points[to]);
                let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
                // Rounding up equals the reference code's "nint, plus one if below".
                ceil_nonneg(((dx * dx + dy * dy) / 10.0).sqrt())
            }
            FileMetric::Geo => geo_cost(points, from, to),
        }
    }

    fn is_integral(self) -> bool {
        match self {
            FileMetric::Plain(m) => m.is_integral(),
            FileMetric::Att | FileMetric::Geo => true,
        }
    }

    fn bound(self, extent: [f64; 3]) -> Cost {
        match self {
            FileMetric::Plain(m) => m.bound(extent),
            FileMetric::Att => norm(extent[0], extent[1], 0.0) / 10f64.sqrt() + 1.0,
            // half the earth's circumference (acos ≤ π) plus the rounding
            FileMetric::Geo => GEO_RADIUS * std::f64::consts::PI + 1.0,
        }
    }

    fn euclid_rounding(self) -> Option<Rounding> {
        match self {
            FileMetric::Plain(m) => m.euclid_rounding(),
            FileMetric::Att | FileMetric::Geo => None,
        }
    }

    fn is_spatial(self) -> bool {
        // GEO coordinates are angles: a spatial tree on them would mislead near the poles and
        // the date line.
        self != FileMetric::Geo
    }
}

/// TSPLIB's geographical distance (kept out of line: it is rare and large).
#[cold]
#[inline(never)]
fn geo_cost(points: &[[f64; 3]], from: usize, to: usize) -> Cost {
    // Two cities at the same place are 1 apart (the reference code adds 1 before rounding
    // down), but a city is 0 from itself.
    if from == to {
        return 0.0;
    }
    let (a, b) = (&points[from], &points[to]);
    let (lat1, lon1) = (geo_radians(a[0]), geo_radians(a[1]));
    let (lat2, lon2) = (geo_radians(b[0]), geo_radians(b[1]));
    let q1 = (lon1 - lon2).cos();
    let q2 = (lat1 - lat2).cos();
    let q3 = (lat1 + lat2).cos();
    (GEO_RADIUS * (0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)).acos() + 1.0).floor()
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

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_seq::{CostModel, PointCost, StateId};

    #[test]
    fn att_rounds_up() {
        // √((100 + 0)/10) = 3.162 → 4; √(1000/10) = 10 exactly → 10
        let p =
            PointCost::new(vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 31.622776601683793, 0.0]], FileMetric::Att);
        assert_eq!(p.cost(StateId(0), StateId(1)), 4.0);
        let q = PointCost::new(vec![[0.0, 0.0, 0.0], [30.0, 10.0, 0.0]], FileMetric::Att);
        assert_eq!(q.cost(StateId(0), StateId(1)), 10.0);
    }

    /// Only the plain Euclidean metrics offer their points for inline pricing, and those
    /// points price every pair as the model does; ATT and GEO do not.
    #[test]
    fn only_euclidean_files_are_planar() {
        let pts = vec![[0.0, 0.0, 0.0], [3.0, 4.5, 0.0], [-7.25, 1.5, 0.0]];
        for m in [Metric::Euclidean, Metric::EuclideanNint, Metric::EuclideanCeil] {
            let p = PointCost::new(pts.clone(), FileMetric::Plain(m));
            let pl = p.planar_euclid().expect("plane points under a Euclidean metric");
            for a in 0..3 {
                for b in 0..3 {
                    assert_eq!(pl.cost(a, b), p.cost(StateId(a as u32), StateId(b as u32)), "{m:?} {a} {b}");
                }
            }
        }
        for f in [FileMetric::Att, FileMetric::Geo, FileMetric::Plain(Metric::ManhattanNint)] {
            assert!(PointCost::new(pts.clone(), f).planar_euclid().is_none(), "{f:?}");
        }
    }

    #[test]
    fn geo_is_symmetric_and_zero_on_the_diagonal() {
        let p = PointCost::new(vec![[51.30, 0.07, 0.0], [40.43, -74.0, 0.0]], FileMetric::Geo);
        assert_eq!(p.cost(StateId(0), StateId(0)), 0.0);
        assert_eq!(p.cost(StateId(0), StateId(1)), p.cost(StateId(1), StateId(0)));
        // London–New York is about 5,570 km; TSPLIB's sphere and DDD.MM reading stay close.
        let d = p.cost(StateId(0), StateId(1));
        assert!((5500.0..5650.0).contains(&d), "{d}");
        assert_eq!(p.position(StateId(0)), None);
        let twins = PointCost::new(vec![[51.30, 0.07, 0.0], [51.30, 0.07, 0.0]], FileMetric::Geo);
        assert_eq!(twins.cost(StateId(0), StateId(1)), 1.0);
    }

    #[test]
    fn bounds_cover_every_cost() {
        let mut x = 12345u64;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.3) * 2000.0
        };
        let pts: Vec<[f64; 3]> = (0..40).map(|_| [next(), next(), 0.0]).collect();
        let geo: Vec<[f64; 3]> = pts.iter().map(|p| [p[0] / 20.0, p[1] / 10.0, 0.0]).collect();
        for (metric, pts) in [(FileMetric::Att, pts), (FileMetric::Geo, geo)] {
            let p = PointCost::new(pts, metric);
            let bound = p.cost_bound().unwrap_or(0.0);
            let max = (0..40u32)
                .flat_map(|i| (0..40u32).map(move |j| (i, j)))
                .map(|(i, j)| p.cost(StateId(i), StateId(j)))
                .fold(0.0, f64::max);
            assert!(max <= bound && bound <= 2.0 * max + 2.0, "{metric:?}: max {max}, bound {bound}");
        }
    }
}
