//! Fuzzes the machine and dialect files: refused with an error or read, never a panic.
//!
//! The body of the `afp_config` fuzz target: run by cargo-fuzz (`fuzz_targets/afp_config.rs`) and, on the
//! stable toolchain, by the mutation harness `crates/towpath/tests/fuzz_targets.rs`.

/// Runs the target on one input; panics on a finding.
pub fn run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = towpath_machine::Machine::from_toml_str(&text) {
        let again = towpath_machine::Machine::from_toml_str(&m.to_toml_string());
        assert!(again.is_ok());
        let _ = m.kinematics().map(|k| k.part_point(&vec![1.0; m.dim()]));
    }
    if let Ok(d) = towpath_nc::Dialect::from_toml_str(&text) {
        assert!(towpath_nc::Dialect::from_toml_str(&d.to_toml_string()).is_ok());
    }
}
