//! Fuzz the designer's text inputs: curve and orientation CSV, analytic surface descriptions and
//! NURBS patch JSON (parsed, validated and evaluated). Never a panic.
//!
//! The body of the `layup_inputs` fuzz target: run by cargo-fuzz (`fuzz_targets/layup_inputs.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

use towpath_geom::surface::{tessellate, Analytic, Nurbs, Surface, Tessellation};
use towpath_layup::input::{read_curve, read_orientations};

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = read_curve(text);
    let _ = read_orientations(text);
    if let Ok(s) = Analytic::parse(text) {
        let _ = s.closest(towpath_geom::DVec3::new(1.0, 2.0, 3.0));
    }
    if let Ok(n) = serde_json::from_str::<Nurbs>(text) {
        if n.validate().is_ok() && n.control.len() <= 4096 {
            let [[u0, u1], [v0, v1]] = n.domain();
            let _ = n.derivatives(0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let _ = n.closest(towpath_geom::DVec3::ZERO);
            let _ = tessellate(&n, &Tessellation::Triangles(200));
        }
    }
}
