//! cargo-fuzz entry point of the `tsplib` target; the body is `fuzz/bodies/tsplib.rs`.
#![no_main]

#[path = "../bodies/tsplib.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
