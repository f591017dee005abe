//! Helpers shared by the CLI tests: run the built binary, fresh scratch folders, fixtures.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The built `towpath` binary, ready for arguments.
pub fn towpath() -> Command {
    Command::new(env!("CARGO_BIN_EXE_towpath"))
}

/// Runs `towpath ARGS` and returns its output.
pub fn towpath_out(args: &[&str]) -> Output {
    towpath().args(args).output().expect("the binary runs")
}

/// Runs `towpath ARGS` in `dir` and returns its output.
pub fn towpath_in(dir: &Path, args: &[&str]) -> Output {
    towpath().current_dir(dir).args(args).output().expect("the binary runs")
}

/// Runs a command: exit code, stdout and stderr.
pub fn run(cmd: &mut Command) -> (i32, String, String) {
    let out = cmd.output().expect("the binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh, empty folder for one test.
pub fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("towpath-cli-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("make a scratch folder");
    d
}

/// A file name in a folder shared by tests that each use their own names.
pub fn scratch_file(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("towpath-cli-{}-files", std::process::id()));
    std::fs::create_dir_all(&d).expect("make a scratch folder");
    d.join(name)
}

/// A fixture of this crate's tests.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// A problem file of the formats crate's test data (TSPLIB, SOP, GTSP, ...).
pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../towpath-formats/tests/data").join(name)
}

/// The one JSON object a successful run printed.
pub fn json_of(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}
