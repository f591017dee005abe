//! Fuzzes the machine and dialect files: refused with an error or read, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = towpath_machine::Machine::from_toml_str(&text) {
        let again = towpath_machine::Machine::from_toml_str(&m.to_toml_string());
        assert!(again.is_ok());
        let _ = m.kinematics().map(|k| k.part_point(&vec![1.0; m.dim()]));
    }
    if let Ok(d) = towpath_nc::Dialect::from_toml_str(&text) {
        assert!(towpath_nc::Dialect::from_toml_str(&d.to_toml_string()).is_ok());
    }
});
