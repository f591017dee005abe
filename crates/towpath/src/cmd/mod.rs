//! One module per subcommand.

pub mod bench;
pub mod bench_baselines;
pub mod demo;
pub mod route;
pub mod solver_args;
