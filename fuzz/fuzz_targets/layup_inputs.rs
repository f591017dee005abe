//! cargo-fuzz entry point of the `layup_inputs` target; the body is `fuzz/bodies/layup_inputs.rs`.
#![no_main]

#[path = "../bodies/layup_inputs.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
