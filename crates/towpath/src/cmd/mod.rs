//! One module per subcommand.

mod afp_common;
pub mod demo;
pub mod solve;
pub mod layup;
pub mod optimize;
pub mod verify;
