//! cargo-fuzz entry point of the `mesh_stl` target; the body is `fuzz/bodies/mesh_stl.rs`.
#![no_main]

#[path = "../bodies/mesh_stl.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
