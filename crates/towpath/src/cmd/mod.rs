//! One module per subcommand.

mod afp_common;
pub mod bench;
pub mod bench_baselines;
pub mod convert;
pub mod demo;
pub mod layup;
pub mod optimize;
pub mod route;
pub mod solve;
pub mod solver_args;
pub mod spray;
pub mod verify;
