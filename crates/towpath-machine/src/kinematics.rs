//! Forward kinematics: from an axis state to the tool point, in the machine frame and in the
//! part frame (which turns with the mandrel).
//!
//! With a DH chain the tool point is the chain's end (plus `tool_offset` in the last frame).
//! Without one, linear axes labelled X, Y and Z are taken as the tool point's coordinates, as on a
//! machine under tool-centre-point control. A machine with neither has no kinematics.

use glam::{DMat3, DVec3};

use crate::config::{AxisKind, Machine};

/// One joint of the chain, ready to evaluate.
#[derive(Clone, Debug)]
struct Joint {
    a: f64,
    d: f64,
    alpha: f64,
    theta: f64,
    /// (axis index, true if the axis is linear and drives `d`).
    driver: Option<(usize, bool)>,
}

/// Where the tool point comes from.
#[derive(Clone, Debug)]
enum Source {
    Chain { joints: Vec<Joint>, tool: DVec3 },
    Xyz([Option<usize>; 3]),
}

/// Forward kinematics of a machine.
#[derive(Clone, Debug)]
pub struct Kinematics {
    source: Source,
    /// (axis index, point on the axis, unit direction).
    mandrel: Option<(usize, DVec3, DVec3)>,
}

impl Kinematics {
    /// Builds the kinematics of a machine, or `None` if it has no DH chain and no X/Y/Z axes.
    pub fn new(m: &Machine) -> Option<Self> {
        let source = if !m.dh.is_empty() {
            let joints =
                m.dh.iter()
                    .map(|j| Joint {
                        a: j.a,
                        d: j.d,
                        alpha: j.alpha.to_radians(),
                        theta: j.theta.to_radians(),
                        driver: j
                            .axis
                            .as_deref()
                            .and_then(|l| m.axis_index(l))
                            .map(|i| (i, m.axes[i].kind == AxisKind::Linear)),
                    })
                    .collect();
            Source::Chain { joints, tool: DVec3::from(m.tool_offset.unwrap_or([0.0; 3])) }
        } else {
            let find = |l: &str| m.axis_index(l).filter(|&i| m.axes[i].kind == AxisKind::Linear);
            let xyz = [find("X"), find("Y"), find("Z")];
            if xyz.iter().all(Option::is_none) {
                return None;
            }
            Source::Xyz(xyz)
        };
        let mandrel = m.mandrel_axis().map(|i| {
            let a = &m.axes[i];
            let d = DVec3::from(a.direction.unwrap_or([1.0, 0.0, 0.0]));
            (i, DVec3::from(a.origin.unwrap_or([0.0; 3])), d / d.length())
        });
        Some(Kinematics { source, mandrel })
    }

    /// The tool point in the machine frame.
    pub fn world_point(&self, state: &[f64]) -> [f64; 3] {
        self.world_point_vec(state).to_array()
    }

    fn world_point_vec(&self, state: &[f64]) -> DVec3 {
        match &self.source {
            Source::Xyz(idx) => {
                let v = |k: usize| idx[k].and_then(|i| state.get(i).copied()).unwrap_or(0.0);
                DVec3::new(v(0), v(1), v(2))
            }
            Source::Chain { joints, tool } => {
                // Accumulate the transform as a 3×3 rotation and a translation.
                let mut r = DMat3::IDENTITY;
                let mut t = DVec3::ZERO;
                for j in joints {
                    let (mut theta, mut d) = (j.theta, j.d);
                    if let Some((i, linear)) = j.driver {
                        let q = state.get(i).copied().unwrap_or(0.0);
                        if linear {
                            d += q;
                        } else {
                            theta += q.to_radians();
                        }
                    }
                    // Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha).
                    let (st, ct) = theta.sin_cos();
                    let local_t = DVec3::new(j.a * ct, j.a * st, d);
                    t += r * local_t;
                    r *= dh_rotation(theta, j.alpha);
                }
                t + r * *tool
            }
        }
    }

    /// The tool point in the part frame: the machine-frame point turned back by the mandrel
    /// angle (a positive mandrel move turns the part positively about its direction). Without a
    /// mandrel the part frame is the machine frame.
    pub fn part_point(&self, state: &[f64]) -> [f64; 3] {
        let p = self.world_point_vec(state);
        match self.mandrel {
            None => p.to_array(),
            Some((i, o, k)) => {
                let angle = -state.get(i).copied().unwrap_or(0.0).to_radians();
                (o + rotate(p - o, k, angle)).to_array()
            }
        }
    }

    /// The mandrel's axis of rotation (a point on it and its unit direction), if any.
    pub fn mandrel_axis(&self) -> Option<([f64; 3], [f64; 3])> {
        self.mandrel.map(|(_, o, k)| (o.to_array(), k.to_array()))
    }
}

/// The tool axis: the direction in which the tool points at the part (the head lies the other
/// way from the tool point).
impl Kinematics {
    /// True when the tool point comes from a DH chain (false: from X/Y/Z linear axes).
    pub fn has_chain(&self) -> bool {
        matches!(self.source, Source::Chain { .. })
    }

    /// The index of the mandrel axis in a state, if the machine has one.
    pub fn mandrel_index(&self) -> Option<usize> {
        self.mandrel.map(|(i, _, _)| i)
    }

    /// The tool axis in the machine frame, a unit vector pointing from the head towards the
    /// part: with a DH chain the z axis of the last frame; without one (X/Y/Z axes under
    /// tool-centre-point control) −Z, the head standing above the tool point along +Z.
    pub fn world_tool_axis(&self, state: &[f64]) -> [f64; 3] {
        self.world_tool_axis_vec(state).to_array()
    }

    fn world_tool_axis_vec(&self, state: &[f64]) -> DVec3 {
        match &self.source {
            Source::Xyz(_) => DVec3::NEG_Z,
            Source::Chain { joints, .. } => {
                let mut r = DMat3::IDENTITY;
                for j in joints {
                    let mut theta = j.theta;
                    if let Some((i, false)) = j.driver {
                        theta += state.get(i).copied().unwrap_or(0.0).to_radians();
                    }
                    r *= dh_rotation(theta, j.alpha);
                }
                r.z_axis
            }
        }
    }

    /// The tool axis in the part frame ([`Kinematics::world_tool_axis`] turned back by the
    /// mandrel angle, like [`Kinematics::part_point`]).
    pub fn part_tool_axis(&self, state: &[f64]) -> [f64; 3] {
        let u = self.world_tool_axis_vec(state);
        match self.mandrel {
            None => u.to_array(),
            Some((i, _, k)) => rotate(u, k, -state.get(i).copied().unwrap_or(0.0).to_radians()).to_array(),
        }
    }
}

/// The rotation of one standard DH joint, Rz(theta) Rx(alpha) (angles in radians).
fn dh_rotation(theta: f64, alpha: f64) -> DMat3 {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    // Rows (ct, −st·ca, st·sa), (st, ct·ca, −ct·sa), (0, sa, ca), given as columns.
    DMat3::from_cols(DVec3::new(ct, st, 0.0), DVec3::new(-st * ca, ct * ca, sa), DVec3::new(st * sa, -ct * sa, ca))
}

/// Rodrigues' rotation of `v` by `angle` (radians) about the unit vector `k`.
fn rotate(v: DVec3, k: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    let kv = k.dot(v);
    v * c + k.cross(v) * s + k * kv * (1.0 - c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Axis, DhJoint};

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn xyz_axes_are_the_tool_point() {
        let m = Machine::new(
            "g",
            vec![Axis::new("X", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), Axis::new("C", AxisKind::Rotary)],
        )
        .unwrap();
        let k = m.kinematics().unwrap();
        assert!(close(k.world_point(&[1.0, 3.0, 90.0]), [1.0, 0.0, 3.0]));
        let none = Machine::new("r", vec![Axis::new("A", AxisKind::Rotary)]).unwrap();
        assert!(none.kinematics().is_none());
    }

    #[test]
    fn planar_two_link_arm_matches_trigonometry() {
        // Two revolute joints in the plane, links 300 and 200: the tool point is the textbook
        // (l1 cos q1 + l2 cos(q1+q2), l1 sin q1 + l2 sin(q1+q2)).
        let mut m =
            Machine::new("arm", vec![Axis::new("A", AxisKind::Rotary), Axis::new("B", AxisKind::Rotary)]).unwrap();
        m.dh = vec![
            DhJoint { a: 300.0, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("A".into()) },
            DhJoint { a: 200.0, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("B".into()) },
        ];
        m.validate().unwrap();
        let k = m.kinematics().unwrap();
        for (q1, q2) in [(0.0f64, 0.0f64), (30.0, 45.0), (-120.0, 200.0)] {
            let (a, b) = (q1.to_radians(), (q1 + q2).to_radians());
            let expect = [300.0 * a.cos() + 200.0 * b.cos(), 300.0 * a.sin() + 200.0 * b.sin(), 0.0];
            assert!(close(k.world_point(&[q1, q2]), expect), "{q1} {q2}");
        }
    }

    #[test]
    fn prismatic_joint_and_twist() {
        // A vertical slide (d) then a 90° twist and a 100 mm link: moving the slide lifts the
        // tool point by the same amount.
        let mut m = Machine::new("s", vec![Axis::new("Z", AxisKind::Linear)]).unwrap();
        m.dh = vec![DhJoint { a: 100.0, d: 10.0, alpha: 90.0, theta: 0.0, axis: Some("Z".into()) }];
        m.tool_offset = Some([0.0, 0.0, 5.0]);
        m.validate().unwrap();
        let k = m.kinematics().unwrap();
        // After Rx(90°) the tool offset along local z points along world −y.
        assert!(close(k.world_point(&[0.0]), [100.0, -5.0, 10.0]));
        assert!(close(k.world_point(&[7.0]), [100.0, -5.0, 17.0]));
    }

    /// The tool axis: −Z for X/Y/Z machines (turned with the part frame on a mandrel), the
    /// last frame's z for a chain (a twist of 90° about x turns it from +z to −y).
    #[test]
    fn tool_axis_directions() {
        let mut mandrel = Axis::new("A", AxisKind::Mandrel);
        mandrel.direction = Some([1.0, 0.0, 0.0]);
        let m = Machine::new("cyl", vec![Axis::new("X", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), mandrel])
            .unwrap();
        let k = m.kinematics().unwrap();
        assert!(!k.has_chain());
        assert_eq!(k.mandrel_index(), Some(2));
        assert!(close(k.world_tool_axis(&[0.0, 100.0, 90.0]), [0.0, 0.0, -1.0]));
        // The part turned +90° about +x: in the part frame the tool stands at +y and points
        // towards −y, at the axis.
        assert!(close(k.part_tool_axis(&[0.0, 100.0, 90.0]), [0.0, -1.0, 0.0]));
        let mut s =
            Machine::new("s", vec![Axis::new("Z", AxisKind::Linear), Axis::new("C", AxisKind::Rotary)]).unwrap();
        s.dh = vec![
            DhJoint { a: 0.0, d: 0.0, alpha: 0.0, theta: 0.0, axis: Some("C".into()) },
            DhJoint { a: 100.0, d: 10.0, alpha: 90.0, theta: 0.0, axis: Some("Z".into()) },
        ];
        s.validate().unwrap();
        let k = s.kinematics().unwrap();
        assert!(k.has_chain());
        assert!(close(k.world_tool_axis(&[5.0, 0.0]), [0.0, -1.0, 0.0]));
        // Turning C by 90° about z turns −y into +x.
        assert!(close(k.world_tool_axis(&[5.0, 90.0]), [1.0, 0.0, 0.0]));
    }

    #[test]
    fn mandrel_turns_the_part_frame() {
        let mut mandrel = Axis::new("A", AxisKind::Mandrel);
        mandrel.direction = Some([2.0, 0.0, 0.0]);
        let m = Machine::new("cyl", vec![Axis::new("X", AxisKind::Linear), Axis::new("Z", AxisKind::Linear), mandrel])
            .unwrap();
        let k = m.kinematics().unwrap();
        // Tool above the axis at (x, 0, 100); turning the mandrel +90° about +x turns the part
        // so that its point at +y comes under the tool: in the part frame the tool is at +y.
        let p = k.part_point(&[50.0, 100.0, 90.0]);
        assert!(close(p, [50.0, 100.0, 0.0]), "{p:?}");
        // Radius is preserved whatever the angle.
        for a in [0.0, 33.0, 181.0, -725.0] {
            let q = k.part_point(&[0.0, 100.0, a]);
            assert!(((q[1] * q[1] + q[2] * q[2]).sqrt() - 100.0).abs() < 1e-9);
        }
    }
}
