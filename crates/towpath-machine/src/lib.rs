//! # towpath-machine: the machine model
//!
//! A [`Machine`] is what towpath knows of a CNC or robotic machine: its axes as they are labelled
//! in programs, the kind of each axis ([`AxisKind`]: linear, limited rotary, continuous rotary,
//! mandrel), a cost weight per axis (C(a) of seed 000), optional velocity and acceleration
//! limits, the axis that turns the head about the tool axis (the *heading* axis), and an optional
//! Denavit–Hartenberg chain for forward kinematics to the tool point. Machines are read from and
//! written to TOML ([`Machine::from_toml_str`], [`Machine::to_toml_string`]); `docs/machine.md`
//! documents every key.
//!
//! Motion between two axis vectors (*states*) is priced by a [`CostKind`]:
//! - [`CostKind::Axis`]: seed 000's weighted axis distance Σ C(a)·|Δa|;
//! - [`CostKind::Time`]: the time of a move with all axes moving together, each axis on a
//!   trapezoidal velocity profile, the move taking as long as its slowest axis;
//! - [`CostKind::Tool`]: the straight-line distance of the tool point, in the part frame.
//!
//! Continuous and mandrel axes take the short way round ([`Machine::short_delta`]). A
//! [`MachineCost`] holds a table of states and implements [`towpath_seq::CostModel`], so the
//! sequencing engine can price transitions between them. [`MachineCost::segment`] prices one
//! move whose per-axis travel is already known (a simulator's view of a program line).
//!
//! This crate knows nothing of programs or G-code.

#![warn(missing_docs)]

mod config;
mod cost;
mod kinematics;
mod locate;
mod motion;

pub use config::{
    Axis, AxisKind, DhJoint, Head, Machine, MachineError, ACCELERATION_RANGE, MAX_AXES, MAX_AXIS_VALUE, MAX_DH_ANGLE,
    MAX_WEIGHT, VELOCITY_RANGE,
};
pub use cost::{CostError, CostKind, MachineCost, StateTable};
pub use kinematics::Kinematics;
pub use motion::trapezoid_time;
