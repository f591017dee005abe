//! Issue 19, motion safety end to end: `optimize --mold` plans transits over the demo's
//! stringer and writes a safe program (warning that the input is not), `verify --mold` checks
//! both programs and exits 3 when the optimized one collides, and the report marks collisions.

use std::path::{Path, PathBuf};

use super::common::*;

fn cell_args(cmd: &mut std::process::Command, d: &Path) {
    cmd.arg("--machine").arg(d.join("gantry-afp.toml")).arg("--dialect").arg(d.join("dialect.toml"));
    for m in ["tool", "stringer", "clamp"] {
        cmd.arg("--mold").arg(d.join(format!("planar-stringer.{m}.stl")));
    }
}

fn demo(tag: &str) -> PathBuf {
    let d = scratch(tag);
    let (code, _, err) = run(towpath().args(["demo", "--iterations", "60", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{err}");
    d
}

#[test]
fn optimize_and_verify_in_a_cell() {
    let d = demo("motion-cli");
    let input = d.join("planar-stringer.nc");
    let out = d.join("mine.nc");
    let report = d.join("mine.html");
    let mut cmd = towpath();
    cmd.arg("optimize").arg(&input).args(["--bidirectional", "--iterations", "200", "--json", "-o"]).arg(&out);
    cmd.arg("--report").arg(&report);
    cell_args(&mut cmd, &d);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the input program is not safe in this cell: 2 collisions"), "{err}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(json["safety"]["after"]["collisions"].as_array().unwrap().len(), 0, "{json}");
    assert_eq!(json["safety"]["before"]["collisions"].as_array().unwrap().len(), 2, "{json}");
    let html = std::fs::read_to_string(&report).unwrap();
    assert_eq!(html.matches("class=\"safety\"").count(), 2, "the input's two collisions are marked");
    assert!(html.contains("collision</span>"), "the legend names the marks");

    // verify checks both programs against the cell.
    let mut cmd = towpath();
    cmd.arg("verify").arg(&input).arg(&out);
    cell_args(&mut cmd, &d);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("motion safety, original:  2 collisions"), "{stdout}");
    assert!(stdout.contains("motion safety, optimized: 0 collisions, 0 near misses"), "{stdout}");

    // The input as "optimized" collides: exit 3, saying the original already did.
    let mut cmd = towpath();
    cmd.arg("verify").arg(&input).arg(&input).arg("--json");
    cell_args(&mut cmd, &d);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("not safe: 2 collisions") && err.contains("the original already has 2 collisions"), "{err}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["safety"]["optimized"]["collisions"], 2, "{v}");
    assert_eq!(v["safety"]["optimized"]["min_clearance"], 0.0, "{v}");
}

#[test]
fn cell_arguments_are_checked() {
    let d = demo("motion-cli-args");
    let input = d.join("planar-stringer.nc");
    // --clearance needs --mold.
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(&input)
        .args(["--clearance", "5", "-o"])
        .arg(d.join("x.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml")));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--mold"), "{err}");
    // A missing mesh, a bad clearance, a mold away from the part.
    let missing = d.join("nope.stl");
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(&input)
        .arg("-o")
        .arg(d.join("x.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--mold")
        .arg(&missing));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("nope.stl"), "{err}");
    let mut cmd = towpath();
    cmd.arg("optimize").arg(&input).args(["--clearance", "0", "-o"]).arg(d.join("x.nc"));
    cell_args(&mut cmd, &d);
    let (code, _, err) = run(&mut cmd);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("clearance 0 mm"), "{err}");
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(&input)
        .arg("-o")
        .arg(d.join("x.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--mold")
        .arg(d.join("planar-stringer.clamp.stl")));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the mold does not lie under the laid path"), "{err}");
    assert!(!d.join("x.nc").exists(), "nothing written on a refusal");
}
