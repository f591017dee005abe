//! cargo-fuzz entry point of the `afp_config` target; the body is `fuzz/bodies/afp_config.rs`.
#![no_main]

#[path = "../bodies/afp_config.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
