//! # towpath-coverage: the open rural postman model of seed 004
//!
//! Seed 004 (Tewolde & Sheng, *Robot Path Integration in Manufacturing Processes*) integrates
//! the tool paths of separate patches into one robot path: each patch path becomes a
//! **required edge** of an undirected travel graph, and the robot must traverse every required
//! edge once, in either direction, travelling between them along shortest paths, on an open
//! path (the *open rural postman problem*, §III-C).
//!
//! - [`Instance`]: a validated travel graph (vertices with coordinates, edges with lengths),
//!   the required edges and an optional start vertex.
//! - [`ShortestPaths`]: Floyd–Warshall or Dijkstra, whichever fits the size, with path trees.
//! - [`RppModel`]: the instance as a [`towpath_seq::Problem`] (tasks = required edges with two
//!   modes, states = terminal vertices, cost = shortest-path distance, open path), and
//!   [`RppModel::route`] to expand a solution into the full vertex walk; [`verify_route`]
//!   checks a walk independently.
//! - [`read_instance`] / [`write_instance`] / [`RouteJson`]: the JSON format, with errors that
//!   name line and column.
//! - [`tewolde_sheng_like`]: instances shaped like the paper's Table I sample data.
//!
//! This crate knows no CLI; its only IO-adjacent part is the JSON text format of its own data.

#![warn(missing_docs)]

mod generate;
mod instance;
mod json;
mod model;
mod paths;

pub use generate::{tewolde_sheng_like, GenerateError, MAX_GENERATED_REQUIRED, TABLE_I_SIZES};
pub use instance::{Edge, Instance, InstanceError, InstanceErrorKind, Item};
pub use json::{read_instance, write_instance, ReadError, ReadErrorKind, RouteJson, ServiceJson, FORMAT, ROUTE_FORMAT};
pub use model::{
    model_bytes, verify_route, BuildError, PathCost, Route, RouteError, RppModel, Service, MODEL_MAX_BYTES,
};
pub use paths::{PathAlgorithm, ShortestPaths, Stopped, FLOYD_WARSHALL_MAX_VERTICES, NO_EDGE};
