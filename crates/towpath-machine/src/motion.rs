//! Motion of single moves: the trapezoidal velocity profile of one axis, and the weighted axis
//! distance and simultaneous-axes time of a move whose per-axis travel is known, at the axes'
//! limits (a rapid) or at a programmed feed.

use crate::config::Machine;

/// Time to travel `distance` (≥ 0) from rest to rest under a maximum velocity and, optionally, a
/// maximum acceleration: a trapezoidal profile (accelerate, cruise, decelerate), or a triangular
/// one when the distance is too short to reach full speed. Without an acceleration limit the
/// axis moves at full speed throughout.
pub fn trapezoid_time(distance: f64, max_velocity: f64, max_acceleration: Option<f64>) -> f64 {
    let d = distance.abs();
    if d == 0.0 {
        return 0.0;
    }
    match max_acceleration {
        None => d / max_velocity,
        Some(a) => {
            // Distance needed to reach full speed and stop again.
            let ramp = max_velocity * max_velocity / a;
            if d <= ramp {
                2.0 * (d / a).sqrt()
            } else {
                d / max_velocity + max_velocity / a
            }
        }
    }
}

impl Machine {
    /// Seed 000's weighted axis distance of a move with these per-axis travels: Σ C(a)·|Δa|.
    pub fn weighted_distance(&self, deltas: &[f64]) -> f64 {
        self.axes.iter().zip(deltas).map(|(a, d)| a.weight * d.abs()).sum()
    }

    /// Time of a move with these per-axis travels, all axes starting and stopping together: the
    /// slowest axis's trapezoidal time. Axes without a velocity limit take no time (see
    /// [`crate::MachineCost::new`], which refuses a time cost on such a machine).
    pub fn move_time(&self, deltas: &[f64]) -> f64 {
        let mut t: f64 = 0.0;
        for (a, d) in self.axes.iter().zip(deltas) {
            if let Some(v) = a.max_velocity {
                t = t.max(trapezoid_time(*d, v, a.max_acceleration));
            }
        }
        t
    }

    /// The path length a programmed feed applies to (the RS274/NGC rule): the straight-line
    /// length of the linear axes' travel when any linear axis moves (angular axes then move in
    /// step with them), else the straight-line length of the angular axes' travel, in degrees.
    pub fn feed_length(&self, deltas: &[f64]) -> f64 {
        let (mut linear, mut angular) = (0.0f64, 0.0f64);
        for (a, d) in self.axes.iter().zip(deltas) {
            if a.kind.is_angular() {
                angular += d * d;
            } else {
                linear += d * d;
            }
        }
        if linear > 0.0 {
            linear.sqrt()
        } else {
            angular.sqrt()
        }
    }

    /// Time of a feed move with these per-axis travels at a programmed feed of `feed` (mm/s,
    /// or deg/s for a move of angular axes alone; see [`Machine::feed_length`]), all axes
    /// starting and stopping together: each axis moves on a trapezoidal profile whose cruise
    /// speed is its share of the feed, `feed · |Δa| / length`, capped by its `max_velocity`; the
    /// move takes the slowest axis's time. Without an acceleration limit and below every
    /// velocity limit this is `length / feed`. A feed that is not a positive number is ignored
    /// (the move is timed like a rapid, [`Machine::move_time`]).
    pub fn feed_move_time(&self, deltas: &[f64], feed: f64) -> f64 {
        let length = self.feed_length(deltas);
        if !(feed > 0.0 && feed.is_finite()) || length == 0.0 {
            return self.move_time(deltas);
        }
        let mut t: f64 = 0.0;
        for (a, d) in self.axes.iter().zip(deltas) {
            if *d == 0.0 {
                continue;
            }
            let share = feed * d.abs() / length;
            let v = a.max_velocity.map_or(share, |m| m.min(share));
            t = t.max(trapezoid_time(*d, v, a.max_acceleration));
        }
        t
    }

    /// The axes a time cost cannot price: those without `max_velocity`.
    pub fn axes_without_velocity(&self) -> Vec<&str> {
        self.axes.iter().filter(|a| a.max_velocity.is_none()).map(|a| a.label.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Axis, AxisKind};

    #[test]
    fn trapezoid_matches_closed_forms() {
        // v = 100, a = 1000: full speed is reached after 10 mm of ramp (5 up, 5 down).
        assert_eq!(trapezoid_time(0.0, 100.0, Some(1000.0)), 0.0);
        // Triangular: d = 4 -> t = 2 sqrt(4/1000).
        assert!((trapezoid_time(4.0, 100.0, Some(1000.0)) - 2.0 * (0.004f64).sqrt()).abs() < 1e-12);
        // Exactly the ramp: both forms agree at 0.2 s.
        assert!((trapezoid_time(10.0, 100.0, Some(1000.0)) - 0.2).abs() < 1e-12);
        // Trapezoidal: d = 110 -> 1.1 + 0.1.
        assert!((trapezoid_time(110.0, 100.0, Some(1000.0)) - 1.2).abs() < 1e-12);
        assert!((trapezoid_time(-50.0, 100.0, None) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn simultaneous_move_takes_the_slowest_axis() {
        let mut x = Axis::new("X", AxisKind::Linear);
        x.max_velocity = Some(100.0);
        x.weight = 2.0;
        let mut c = Axis::new("C", AxisKind::Continuous);
        c.max_velocity = Some(10.0);
        let m = Machine::new("m", vec![x, c]).unwrap();
        assert_eq!(m.move_time(&[100.0, 5.0]), 1.0);
        assert_eq!(m.move_time(&[10.0, -20.0]), 2.0);
        assert_eq!(m.weighted_distance(&[10.0, -20.0]), 40.0);
    }

    /// Feed moves, timed by hand: the feed sets each axis's cruise speed (its share of the
    /// path), acceleration ramps included; angular axes alone take the feed in degrees.
    #[test]
    fn feed_moves_take_their_programmed_feed() {
        let mut x = Axis::new("X", AxisKind::Linear);
        (x.max_velocity, x.max_acceleration) = (Some(1000.0), Some(2000.0));
        let mut y = Axis::new("Y", AxisKind::Linear);
        (y.max_velocity, y.max_acceleration) = (Some(1000.0), Some(2000.0));
        let mut c = Axis::new("C", AxisKind::Continuous);
        (c.max_velocity, c.max_acceleration) = (Some(180.0), Some(720.0));
        let m = Machine::new("m", vec![x, y, c]).unwrap();
        // 300 mm at 100 mm/s: 3 s cruising plus 100/2000 s of ramps (at the machine's limits it
        // never reaches full speed: 2·√(300/2000) s).
        assert!((m.feed_move_time(&[300.0, 0.0, 0.0], 100.0) - 3.05).abs() < 1e-12);
        assert!((m.move_time(&[300.0, 0.0, 0.0]) - 2.0 * 0.15f64.sqrt()).abs() < 1e-12);
        // A 3-4-5 move at 50 mm/s: X cruises at 30 mm/s, Y at 40; Y is slower (5 + 0.02 s).
        assert_eq!(m.feed_length(&[30.0, 40.0, 10.0]), 50.0);
        assert!((m.feed_move_time(&[150.0, 200.0, 0.0], 50.0) - (200.0 / 40.0 + 40.0 / 2000.0)).abs() < 1e-12);
        // C alone: 90° at 30°/s, 3 s plus 30/720 s.
        assert_eq!(m.feed_length(&[0.0, 0.0, -90.0]), 90.0);
        assert!((m.feed_move_time(&[0.0, 0.0, -90.0], 30.0) - (3.0 + 30.0 / 720.0)).abs() < 1e-12);
        // X 100 mm at 100 mm/s with C turning 90° in step: C's share is 90°/s (under its 180),
        // 1 + 90/720 s, slower than X's 1 + 100/2000 s.
        assert!((m.feed_move_time(&[100.0, 0.0, 90.0], 100.0) - 1.125).abs() < 1e-12);
        // A feed faster than the machine: the velocity limits rule, as for a rapid.
        assert_eq!(m.feed_move_time(&[300.0, 0.0, 0.0], 1e6), m.move_time(&[300.0, 0.0, 0.0]));
        assert_eq!(m.feed_move_time(&[300.0, 0.0, 0.0], f64::NAN), m.move_time(&[300.0, 0.0, 0.0]));
        assert_eq!(m.feed_move_time(&[0.0, 0.0, 0.0], 100.0), 0.0);
    }
}
