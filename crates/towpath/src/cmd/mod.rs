//! One module per subcommand.

pub mod demo;
pub mod solve;
pub mod layup;
