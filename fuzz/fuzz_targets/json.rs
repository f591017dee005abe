//! cargo-fuzz entry point of the `json` target; the body is `fuzz/bodies/json.rs`.
#![no_main]

#[path = "../bodies/json.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
