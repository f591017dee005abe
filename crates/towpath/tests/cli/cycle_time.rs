//! Issue 18, cycle time first: the demo and `optimize` minimize cycle time by default on
//! machines with velocities, never return a slower program (checked here by `verify`, the
//! independent evaluation, on the written files), and every summary leads with time. The
//! demo's suggested commands work as pasted from where the user stands.

use std::path::{Path, PathBuf};

use super::common::*;

/// A fresh folder under the target directory, so that the binary's relative path is short.
fn near_binary(tag: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cycle-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every demo part's written output, verified again by `towpath verify --json`: its cycle time
/// is no longer than the input's; the demo's table and JSON lead with cycle time.
#[test]
fn demo_outputs_are_never_slower_by_verify() {
    let d = scratch("cycle-demo");
    let (code, out, err) = run(towpath().args(["demo", "--iterations", "60", "--json", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let parts = json["parts"].as_array().unwrap();
    assert_eq!(parts.len(), towpath_nc::demo::demo_parts().len());
    for part in parts {
        let name = part["part"].as_str().unwrap();
        assert_eq!(part["totals"][0]["kind"], "time", "{name}: time first");
        let machine = if name.starts_with("cylinder") { "mandrel-afp.toml" } else { "gantry-afp.toml" };
        let mut cmd = towpath();
        cmd.arg("verify")
            .arg(d.join(format!("{name}.nc")))
            .arg(d.join(format!("{name}.opt.nc")))
            .arg("--machine")
            .arg(d.join(machine))
            .arg("--dialect")
            .arg(d.join("dialect.toml"))
            .arg("--json");
        // Parts in a cell: their meshes, checked by verify too.
        let meshes: Vec<PathBuf> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.file_name().is_some_and(|f| f.to_string_lossy().starts_with(&format!("{name}."))))
            .filter(|p| p.extension().is_some_and(|e| e == "stl"))
            .collect();
        for m in &meshes {
            cmd.arg("--mold").arg(m);
        }
        let (code, out, err) = run(&mut cmd);
        assert_eq!(code, 0, "{name}: {err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        let t = &v["cycle_time"];
        let (before, after) = (t["total_before"].as_f64().unwrap(), t["total_after"].as_f64().unwrap());
        // With a cell, the input's transits collide, so the output's safe transits may take
        // longer than the input's unsafe ones; otherwise never slower.
        if meshes.is_empty() {
            assert!(after <= before * (1.0 + 1e-9), "{name}: cycle time {before} -> {after}");
        } else {
            assert!(v["safety"]["original"]["collisions"].as_u64().unwrap() > 0, "{name}: {v}");
            assert_eq!(v["safety"]["optimized"]["collisions"], 0, "{name}: {v}");
            assert_eq!(v["safety"]["optimized"]["near_misses"], 0, "{name}: {v}");
        }
        let (ob, oa) = (t["off_before"].as_f64().unwrap(), t["off_after"].as_f64().unwrap());
        assert!(oa <= ob * (1.0 + 1e-9) + 1e-9, "{name}: off-part time {ob} -> {oa}");
        // The demo's own figure is the verifier's.
        let mine = part["cycle_time"]["total_after"].as_f64().unwrap();
        assert!((mine - after).abs() < 1e-6 * after.max(1.0), "{name}: demo {mine}, verify {after}");
    }
    let (code, table, err) = run(towpath().args(["demo", "--iterations", "20", "--dir"]).arg(d.join("t")));
    assert_eq!(code, 0, "{err}");
    let header = table.lines().find(|l| l.starts_with("part ")).unwrap();
    assert!(
        header.find("off-part time (s)").unwrap() < header.find("cycle time (s)").unwrap()
            && header.find("cycle time (s)").unwrap() < header.find("axis dist.").unwrap(),
        "{header}"
    );
    assert!(table.contains("for cycle time"), "{table}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `optimize` and `verify` summaries: the line after the title is the cycle time, then the
/// distances; `--cost axis` is still there, and when its order is slower the input is kept
/// and the summary says why.
#[test]
fn summaries_lead_with_cycle_time() {
    let d = scratch("cycle-summary");
    let (code, _, err) = run(towpath().args(["demo", "--iterations", "20", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{err}");
    let args = |cmd: &mut std::process::Command| {
        cmd.arg("--machine").arg(d.join("gantry-afp.toml")).arg("--dialect").arg(d.join("dialect.toml"));
    };
    let out = d.join("mine.nc");
    let mut cmd = towpath();
    cmd.arg("optimize").arg(d.join("planar-45.nc")).args(["--bidirectional", "--iterations", "60", "-o"]).arg(&out);
    args(&mut cmd);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines[0].contains("optimized for cycle time"), "{stdout}");
    assert!(lines[1].starts_with("  cycle time: off-part ") && lines[1].contains(" s -> "), "{stdout}");
    assert!(lines[2].starts_with("  off-part distance: weighted axis"), "{stdout}");
    let mut cmd = towpath();
    cmd.arg("verify").arg(d.join("planar-45.nc")).arg(&out);
    args(&mut cmd);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines[1].starts_with("  cycle time: off-part "), "{stdout}");
    // The paper's cost: still available; the output is never slower than the input.
    let mut cmd = towpath();
    cmd.arg("optimize")
        .arg(d.join("planar-45.nc"))
        .args(["--bidirectional", "--cost", "axis", "--iterations", "60", "--json", "-o"])
        .arg(&out);
    args(&mut cmd);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(json["cost"], "axis");
    let t = &json["cycle_time"];
    assert!(t["total_after"].as_f64().unwrap() <= t["total_before"].as_f64().unwrap() * (1.0 + 1e-9), "{t}");
    if json["fell_back"] == true {
        assert_eq!(json["fallback"]["reason"], "cycle_time", "{json}");
        assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(d.join("planar-45.nc")).unwrap());
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The commands the demo prints after its table, pasted into a shell in the folder the demo
/// ran from: they run (the binary by a path that reaches it from there, or by name when it is
/// on the PATH), and write into the demo's folder, nothing beside it.
#[test]
fn demo_follow_up_commands_work_as_pasted() {
    for on_path in [false, true] {
        let here = near_binary(if on_path { "path" } else { "rel" });
        let bin_dir = Path::new(env!("CARGO_BIN_EXE_towpath")).parent().unwrap().to_path_buf();
        let path = match (on_path, std::env::var_os("PATH")) {
            (true, Some(p)) => {
                std::env::join_paths(std::iter::once(bin_dir.clone()).chain(std::env::split_paths(&p))).unwrap()
            }
            (_, p) => p.unwrap_or_default(),
        };
        let (code, out, err) = run(towpath().current_dir(&here).env("PATH", &path).args([
            "demo",
            "--iterations",
            "20",
            "--dir",
            "my demo",
        ]));
        assert_eq!(code, 0, "{err}");
        let tail = &out[out.find("To run one part yourself:").unwrap()..];
        let script: String = tail.lines().skip(1).collect::<Vec<_>>().join("\n");
        let first = script.trim_start();
        if on_path {
            assert!(first.starts_with("towpath optimize"), "{script}");
        } else {
            assert!(first.starts_with("../") || first.starts_with('/'), "{script}");
        }
        assert!(script.contains("'my demo/planar-45.nc'"), "a folder with a space is quoted: {script}");
        let (code, sh_out, sh_err) =
            run(std::process::Command::new("sh").current_dir(&here).env("PATH", &path).args(["-e", "-c", &script]));
        assert_eq!(code, 0, "{script}\n{sh_out}\n{sh_err}");
        assert!(sh_out.contains("verified: 49 courses"), "{sh_out}");
        assert!(here.join("my demo/planar-45.mine.nc").exists() && here.join("my demo/planar-45.mine.html").exists());
        assert!(sh_out.contains("motion safety, output: 0 collisions"), "{sh_out}");
        assert!(here.join("my demo/planar-stringer.mine.nc").exists());
        let beside: Vec<_> = std::fs::read_dir(&here).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(beside, vec![std::ffi::OsString::from("my demo")], "nothing written beside the demo folder");
        let _ = std::fs::remove_dir_all(&here);
    }
}
