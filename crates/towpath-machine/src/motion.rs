//! Motion of single moves: the trapezoidal velocity profile of one axis, and the weighted axis
//! distance and simultaneous-axes time of a move whose per-axis travel is known.

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
}
