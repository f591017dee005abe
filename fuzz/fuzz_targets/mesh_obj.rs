//! cargo-fuzz entry point of the `mesh_obj` target; the body is `fuzz/bodies/mesh_obj.rs`.
#![no_main]

#[path = "../bodies/mesh_obj.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
