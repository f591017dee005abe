//! The open rural postman JSON reader must never panic; whatever it accepts must build a model,
//! and its own output must read back to the same instance.
//!
//! The body of the `rpp_json` fuzz target: run by cargo-fuzz (`fuzz_targets/rpp_json.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(instance) = towpath_coverage::read_instance(text) {
        let again = towpath_coverage::read_instance(&towpath_coverage::write_instance(&instance));
        assert_eq!(again.as_ref().ok(), Some(&instance));
        if instance.vertices().len() <= 200 {
            let _ = towpath_coverage::RppModel::new(instance);
        }
    }
}
