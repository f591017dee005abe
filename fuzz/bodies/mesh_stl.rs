//! Fuzz the STL reader and the mesh build behind it: any bytes give a soup or an error, and a soup
//! gives a mesh or an error, never a panic.
//!
//! The body of the `mesh_stl` fuzz target: run by cargo-fuzz (`fuzz_targets/mesh_stl.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use towpath_geom::io::{read_bytes, Format};
use towpath_geom::{BuildOptions, Mesh};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    if let Ok(soup) = read_bytes(data, Format::Stl) {
        if soup.triangles.len() <= 10_000 {
            if let Ok((mesh, _)) = Mesh::build(&soup, &BuildOptions::default()) {
                let _ = mesh.closest_point(towpath_geom::DVec3::ZERO);
            }
        }
    }
}
