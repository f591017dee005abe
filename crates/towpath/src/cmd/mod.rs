//! One module per subcommand.

mod afp_common;
pub mod convert;
pub mod demo;
pub mod layup;
pub mod layup_report;
pub mod machine;
pub mod optimize;
pub mod order;
pub mod route;
pub mod serve;
pub mod solve;
pub mod solver_args;
pub mod spray;
mod surface_arg;
pub mod verify;
