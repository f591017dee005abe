//! cargo-fuzz entry point of the `mesh_ply` target; the body is `fuzz/bodies/mesh_ply.rs`.
#![no_main]

#[path = "../bodies/mesh_ply.rs"]
mod target;

libfuzzer_sys::fuzz_target!(|data: &[u8]| target::run(data));
