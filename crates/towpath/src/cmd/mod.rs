//! One module per subcommand.

pub mod demo;
pub mod route;
pub mod solver_args;
