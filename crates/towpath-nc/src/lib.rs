//! # towpath-nc: AFP programs
//!
//! Reads a qualified AFP program in a configurable [`Dialect`] into a [`Program`] (plies →
//! courses with approach, on-part and retract blocks), builds the sequencing problem of its
//! courses for a [`towpath_machine::Machine`] (course footprints, precedence, optional reversal),
//! and writes the program back in a new order with only the off-part motion regenerated. An
//! independent [`verify`] checks an optimized program against its original.

#![warn(missing_docs)]

pub mod demo;
mod dialect;
mod error;
mod footprint;
mod interp;
mod lex;
mod optimize;
mod parse;
mod precedence;
mod problem;
mod program;
mod report;
mod reverse;
mod rewrite;
mod safety;
mod sequencer;
mod verify;
mod verify_lines;
mod width;

pub use dialect::{Clearance, Code, Dialect, EventTiming, FeedUnit, Switch};
pub use error::NcError;
pub use footprint::{
    footprints, Footprint, Footprints, Frame, Quad, Width, MAX_PIECES, MAX_WIDTH_PER_SPAN, MIN_WIDTH, OVERLAP_TOLERANCE,
};
pub use interp::{Applied, ArcDir, Event, Interp, Marker, Modal, MotionMode, MoveKind, Plane};
pub use lex::{lex, LexIssue, Lexed, NumText, Word};
pub use optimize::{
    apply_steps, auto_time_limit, fallback_reason, optimize, Fallback, OptimizeOptions, Optimized, SafetyPair,
    SolverSummary, Stage, StageFn, Timings,
};
pub use parse::parse;
pub use precedence::{course_precedence, precedence_sets, MAX_VISITS};
pub use problem::{
    build_problem, build_problem_with, default_cost, placements, AfpCost, AfpOptions, AfpProblem, PrecedenceRule,
};
pub use program::{ply_name, Course, Item, LineBreak, Ply, Program, Region, Segment, SwitchKey};
pub use report::{cost_words, headline, totals, totals_table, GroupCost, GroupRow, OrderRow, Report, Totals};
pub use reverse::{reversal_of, reverse_course, Irreversible, Reversed};
pub use rewrite::{rewrite, rewrite_with, Placement};
pub use safety::{
    check_cell_under_path, check_courses_within_limits, check_program, limit_violations, LimitIssue, MoveIssue, Safety,
    SafetyOptions, SafetyReport, DEFAULT_CLEARANCE, MIN_MANDREL_RADIUS, MOLD_GAP,
};
pub use sequencer::{doherty_sets, sequence};
pub use towpath_baselines::{BaselineParams, SolverName};
pub use verify::{measure, verify, verify_parsed, Motion, Verification, VerifyError, VerifyOptions};
pub use width::{WidthSource, WidthUsed, PLAUSIBLE_FACTOR};
