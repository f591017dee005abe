//! The rig: a machine's kinematics with its head, as the move checker needs them: where the tool
//! point and the head's axis are in the part frame for an axis state, how a move interpolates
//! the axes, and how sharply the path of any point of the head can bend during a move.

use towpath_geom::DVec3;
use towpath_machine::{AxisKind, Head, Kinematics, Machine};

use crate::error::SetupError;

/// Where the tool is for one axis state, in the part frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The tool point.
    pub tool: DVec3,
    /// The tool axis, a unit vector pointing from the head towards the part.
    pub axis: DVec3,
    /// The lower end of the head capsule's axis (the tool point if there is no head).
    pub bottom: DVec3,
    /// The upper end of the head capsule's axis (the tool point if there is no head).
    pub top: DVec3,
}

/// One joint of a DH chain as the bend bound needs it: |a|, the fixed |d|, and the driving
/// axis with whether it is linear.
type ChainJoint = (f64, f64, Option<(usize, bool)>);

/// A machine with its kinematics and optional head model.
#[derive(Clone, Debug)]
pub struct Rig {
    machine: Machine,
    kin: Kinematics,
    head: Option<Head>,
    /// The mandrel: (axis index, point on its axis, unit direction), if any.
    mandrel: Option<(usize, DVec3, DVec3)>,
    /// For machines with a DH chain: its joints and |tool_offset|.
    chain: Option<(Vec<ChainJoint>, f64)>,
    /// Indices of the X, Y, Z linear axes (machines without a chain).
    xyz: [Option<usize>; 3],
}

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::new(a[0], a[1], a[2])
}

impl Rig {
    /// The rig of a machine, refused when the machine has no kinematics or the head is invalid.
    pub fn new(machine: &Machine, head: Option<Head>) -> Result<Rig, SetupError> {
        let kin = machine.kinematics().ok_or(SetupError::NoKinematics)?;
        if let Some(h) = &head {
            h.validate()?;
        }
        let mandrel = kin.mandrel_axis().and_then(|(o, k)| kin.mandrel_index().map(|i| (i, v3(o), v3(k))));
        let chain = (!machine.dh.is_empty()).then(|| {
            let joints = machine
                .dh
                .iter()
                .map(|j| {
                    let driver = j
                        .axis
                        .as_deref()
                        .and_then(|l| machine.axis_index(l))
                        .map(|i| (i, machine.axes[i].kind == AxisKind::Linear));
                    (j.a.abs(), j.d.abs(), driver)
                })
                .collect();
            (joints, v3(machine.tool_offset.unwrap_or([0.0; 3])).length())
        });
        let find = |l: &str| machine.axis_index(l).filter(|&i| machine.axes[i].kind == AxisKind::Linear);
        Ok(Rig { machine: machine.clone(), kin, head, mandrel, chain, xyz: [find("X"), find("Y"), find("Z")] })
    }

    /// The machine.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The kinematics.
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }

    /// The head model, if any.
    pub fn head(&self) -> Option<&Head> {
        self.head.as_ref()
    }

    /// The mandrel's axis index, a point on its axis and its unit direction, if any.
    pub fn mandrel(&self) -> Option<(usize, DVec3, DVec3)> {
        self.mandrel
    }

    /// True when the tool point comes from a DH chain.
    pub fn has_chain(&self) -> bool {
        self.chain.is_some()
    }

    /// Indices of the linear axes labelled X, Y and Z (machines without a chain, whose tool
    /// point they are).
    pub fn xyz_axes(&self) -> [Option<usize>; 3] {
        if self.chain.is_some() {
            [None; 3]
        } else {
            self.xyz
        }
    }

    /// Number of axes.
    pub fn dim(&self) -> usize {
        self.machine.dim()
    }

    /// Checks that a state has one finite value per axis.
    pub fn check_state(&self, state: &[f64]) -> Result<(), SetupError> {
        if state.len() != self.dim() {
            return Err(SetupError::WrongDimension { got: state.len(), expected: self.dim() });
        }
        if let Some(i) = state.iter().position(|v| !v.is_finite()) {
            return Err(SetupError::NotFinite { axis: self.machine.axes[i].label.clone() });
        }
        Ok(())
    }

    /// Checks a state against the axes' travel limits (`min`/`max`), with `eps` of slack.
    pub fn check_limits(&self, state: &[f64], eps: f64) -> Result<(), SetupError> {
        self.check_state(state)?;
        for (a, &v) in self.machine.axes.iter().zip(state) {
            if a.min.is_some_and(|m| v < m - eps) || a.max.is_some_and(|m| v > m + eps) {
                return Err(SetupError::OutsideLimits { axis: a.label.clone(), value: v, min: a.min, max: a.max });
            }
        }
        Ok(())
    }

    /// The tool point and head axis for an axis state, in the part frame.
    pub fn pose(&self, state: &[f64]) -> Pose {
        let tool = v3(self.kin.part_point(state));
        let axis = v3(self.kin.part_tool_axis(state));
        match &self.head {
            Some(h) => Pose { tool, axis, bottom: tool - axis * h.bottom, top: tool - axis * h.top },
            None => Pose { tool, axis, bottom: tool, top: tool },
        }
    }

    /// The travel of every axis on a move from `from` to `to` (wrapping axes the short way
    /// round, as the machine moves them).
    pub fn deltas(&self, from: &[f64], to: &[f64]) -> Vec<f64> {
        (0..self.dim()).map(|i| self.machine.short_delta(i, from[i], to[i])).collect()
    }

    /// The axis state at parameter `t` ∈ [0, 1] of a move: every axis interpolated linearly
    /// from `from` by `t · deltas` (all axes start and stop together, as the time model moves
    /// them).
    pub fn at(&self, from: &[f64], deltas: &[f64], t: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend(from.iter().zip(deltas).map(|(a, d)| if t >= 1.0 { a + d } else { a + t * d }));
    }

    /// A bound M on the second derivative, with respect to the move parameter t ∈ [0, 1], of
    /// the part-frame path of every point of the tool and head during the move from `from` by
    /// `deltas`. A piece [t0, t0 + h] of the path then stays within M·h²/8 of its chord.
    ///
    /// Derivation: a serial chain whose revolute joints turn at rates ωⱼ (Ω = Σ|ωⱼ|, radians)
    /// and prismatic joints slide at rates vⱼ (V = Σ|vⱼ|) moves a point at most ρ from every
    /// joint axis with |p'| ≤ Ωρ + V and |p''| ≤ 2Ω²ρ + 2ΩV (each joint's axis turns at most
    /// at Ω and the point moves relative to it at most at Ωρ + V). The mandrel turning at ω
    /// adds 2ω|p'| + ω²r, r the largest distance from its axis. Without a chain, X/Y/Z are the
    /// tool point (Ω = 0, V = |ΔXYZ|).
    pub fn bend_bound(&self, from: &[f64], deltas: &[f64]) -> f64 {
        let extent = self.head.map_or(0.0, |h| h.top);
        let (omega, v, rho) = match &self.chain {
            Some((joints, tool)) => {
                let (mut om, mut v, mut rho) = (0.0f64, 0.0f64, tool + extent);
                for &(a, d, driver) in joints {
                    rho += a + d;
                    match driver {
                        Some((i, true)) => {
                            let (q0, dq) = (from[i], deltas[i]);
                            v += dq.abs();
                            rho += q0.abs().max((q0 + dq).abs());
                        }
                        Some((i, false)) => om += deltas[i].to_radians().abs(),
                        None => {}
                    }
                }
                (om, v, rho)
            }
            None => {
                let d = |k: usize| self.xyz[k].map_or(0.0, |i| deltas[i]);
                (0.0, (d(0) * d(0) + d(1) * d(1) + d(2) * d(2)).sqrt(), 0.0)
            }
        };
        let mut m = 2.0 * omega * omega * rho + 2.0 * omega * v;
        if let Some((i, o, k)) = self.mandrel {
            let w = deltas[i].to_radians().abs();
            if w > 0.0 {
                let speed = omega * rho + v;
                // Largest distance from the mandrel axis of a head point: at the start at most
                // the tool point's plus the head's extent, growing at most at `speed`.
                let p = v3(self.kin.world_point(from)) - o;
                let r0 = (p - k * p.dot(k)).length() + extent;
                let r = match &self.chain {
                    Some(_) => r0 + speed,
                    None => {
                        // Without a chain the machine point moves on a straight line, whose
                        // distance from the axis is largest at an end.
                        let mut to = from.to_vec();
                        for (t, d) in to.iter_mut().zip(deltas) {
                            *t += d;
                        }
                        let q = v3(self.kin.world_point(&to)) - o;
                        r0.max((q - k * q.dot(k)).length() + extent)
                    }
                };
                m += 2.0 * w * speed + w * w * r;
            }
        }
        m
    }
}
