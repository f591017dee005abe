//! cargo-fuzz entry point of the `afp_program` target; the body is `fuzz/bodies/afp_program.rs`.
#![no_main]

#[path = "../bodies/afp_program.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
