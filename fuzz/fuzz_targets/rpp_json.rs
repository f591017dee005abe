//! cargo-fuzz entry point of the `rpp_json` target; the body is `fuzz/bodies/rpp_json.rs`.
#![no_main]

#[path = "../bodies/rpp_json.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
