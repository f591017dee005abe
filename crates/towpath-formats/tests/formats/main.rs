//! Integration tests of the readers: one test binary, one module per concern.

mod common;
mod errors;
mod export;
mod json;
mod known;
mod limits;
mod props;
