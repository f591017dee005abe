//! The `towpath` binary end to end, one test binary with a module per command (helpers in
//! `common`).

mod afp;
mod afp_hardening;
mod common;
mod convert;
mod cycle_time;
mod layup;
mod layup_report;
mod machine;
mod motion;
mod order;
mod outputs_and_pipes;
mod route;
mod serve;
mod solve;
mod spray;
