//! cargo-fuzz entry point of the `convert` target; the body is `fuzz/bodies/convert.rs`.
#![no_main]

#[path = "../bodies/convert.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
