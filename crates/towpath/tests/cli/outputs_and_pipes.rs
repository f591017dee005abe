//! One rule for every command's files and standard output: a closed pipe ends printing quietly
//! (the run still does its work), outputs never replace inputs or each other, a failed run writes
//! nothing, and a bad output path is the user's error (exit code 2), not a bug.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use super::common::*;

/// Runs a command whose stdout is closed before it prints: it must exit 0 with nothing on stderr
/// but, possibly, a progress bar.
fn closed_stdout(cmd: &mut Command) {
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("the binary runs");
    drop(child.stdout.take());
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        e.read_to_string(&mut err).unwrap();
    }
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(0), "{cmd:?}: {err}");
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{cmd:?}: {err}");
}

/// The demo's files in a fresh folder.
fn demo(tag: &str) -> PathBuf {
    let d = scratch(tag);
    let (code, _, err) = run(towpath().args(["demo", "--time-limit", "0.05", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{err}");
    d
}

fn afp_args(cmd: &mut Command, d: &Path) {
    cmd.arg("--machine").arg(d.join("gantry-afp.toml")).arg("--dialect").arg(d.join("dialect.toml"));
}

/// The subcommands `towpath --help` lists (without `help`).
fn subcommands() -> Vec<String> {
    let (code, out, err) = run(towpath().arg("--help"));
    assert_eq!(code, 0, "{err}");
    let listed = out.split("Commands:").nth(1).expect("a list of commands");
    let names: Vec<String> = listed
        .lines()
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect();
    assert!(names.len() >= 8, "{out}");
    names
}

#[test]
fn every_command_ends_quietly_on_a_closed_stdout() {
    // Every subcommand is run below; a new one fails this test until it is added.
    let mut ran: Vec<&str> = Vec::new();
    let d = demo("pipes");
    closed_stdout(towpath().arg("--help"));
    closed_stdout(towpath().args(["solve", "--help"]));
    closed_stdout(towpath().arg("--version"));
    ran.push("demo");
    closed_stdout(towpath().args(["demo", "--time-limit", "0.05", "--dir"]).arg(d.join("again")));
    assert!(d.join("again/planar-45.opt.nc").exists(), "the demo still wrote its files");

    let out = d.join("p45.nc");
    ran.push("optimize");
    let mut opt = towpath();
    opt.arg("optimize").arg(d.join("planar-45.nc")).args(["--iterations", "200", "-o"]).arg(&out);
    afp_args(&mut opt, &d);
    closed_stdout(&mut opt);
    assert!(out.exists(), "optimize still wrote its output");

    ran.push("verify");
    let mut ver = towpath();
    ver.arg("verify").arg(d.join("planar-45.nc")).arg(&out);
    afp_args(&mut ver, &d);
    closed_stdout(&mut ver);

    ran.extend(["solve", "convert", "route", "layup"]);
    closed_stdout(towpath().arg("solve").arg(data("att48.tsp")).args(["--iterations", "100", "--threads", "1"]));
    closed_stdout(towpath().arg("solve").arg(data("att48.tsp")).args(["--iterations", "100", "--json"]));
    closed_stdout(towpath().arg("convert").arg(data("att48.tsp")));
    closed_stdout(towpath().arg("route").arg(fixture("rpp_6re.json")).args(["--time-limit", "0.2"]));
    let courses = d.join("c.json");
    closed_stdout(
        towpath()
            .args(["layup", "plane:a=200,b=100", "--angle", "30", "--tow-width", "6.35", "--tows", "4", "-o"])
            .arg(&courses),
    );
    assert!(courses.exists(), "layup still wrote its courses");

    ran.push("spray");
    let plan = d.join("spray.json");
    closed_stdout(
        towpath()
            .args([
                "spray",
                "plane:a=300,b=200",
                "--standoff",
                "200",
                "--spray-radius",
                "60",
                "--target-thickness",
                "50",
                "-o",
            ])
            .arg(&plan),
    );
    assert!(plan.exists(), "spray still wrote its plan");

    // order prints the ordered drawing when no output is named.
    ran.push("order");
    let svg = d.join("strokes.svg");
    std::fs::write(
        &svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 100 100">
<path id="a" d="M 70 70 L 90 70" stroke="black"/><path id="b" d="M 10 10 L 30 10" stroke="black"/>
<path id="c" d="M 40 40 L 60 40" stroke="black"/></svg>"#,
    )
    .unwrap();
    closed_stdout(towpath().arg("order").arg(&svg).args(["--iterations", "50"]));

    ran.push("machine");
    let part = d.join("part.json");
    std::fs::write(
        &part,
        r#"{"format": "towpath-part/1", "origin": [0, 0], "clearance": 5,
 "features": [{"id": "pocket", "boundary": [[0,0],[80,0],[80,40],[0,40]], "depth": 6}],
 "tools": [{"number": 1, "radius": 4, "step_over": 3, "features": ["pocket"]}]}"#,
    )
    .unwrap();
    let nc = d.join("part.nc");
    closed_stdout(towpath().arg("machine").arg(&part).args(["--iterations", "50", "-o"]).arg(&nc));
    assert!(nc.exists(), "machine still wrote its G-code");

    // A server goes on serving with nobody reading its banner: no panic, no exit.
    ran.push("serve");
    let mut child = towpath()
        .args(["serve", "--port", "0", "--workspace"])
        .arg(d.join("ws"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let early = child.try_wait().unwrap();
    let _ = child.kill();
    let _ = child.wait();
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        e.read_to_string(&mut err).unwrap();
    }
    assert!(early.is_none() || early.is_some_and(|s| s.success()), "serve ended with {early:?}: {err}");
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{err}");

    let mut missing = subcommands();
    missing.retain(|c| !ran.contains(&c.as_str()));
    assert!(missing.is_empty(), "not run with a closed stdout: {missing:?}");
}

#[test]
fn outputs_never_replace_inputs_or_each_other() {
    let d = scratch("clobber");
    let mesh = d.join("m.stl");
    let (code, _, err) = run(towpath()
        .args(["layup", "plane:a=200,b=100", "--angle", "0", "--tow-width", "6.35", "--tows", "4", "-o"])
        .arg(d.join("first.json"))
        .arg("--write-mesh")
        .arg(&mesh));
    assert_eq!(code, 0, "{err}");
    let before = std::fs::read(&mesh).unwrap();
    std::fs::hard_link(&mesh, d.join("hard.stl")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&mesh, d.join("soft.stl")).unwrap();
    let layup = |extra: &[&str]| {
        let mut c = towpath();
        c.current_dir(&d).args(["layup", "m.stl", "--angle", "0", "--tow-width", "6.35", "--tows", "4"]).args(extra);
        run(&mut c)
    };
    for extra in [
        &["-o", "m.stl"][..],
        &["-o", "x.json", "--write-mesh", "hard.stl"],
        &["-o", "x.json", "--write-mesh", "soft.stl"],
        &["-o", "x.json", "--gcode", "x.json"],
        &["-o", "x.json", "--csv", "./x.json"],
    ] {
        let (code, _, err) = layup(extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("would overwrite") || err.contains("same file"), "{extra:?}: {err}");
    }
    assert_eq!(std::fs::read(&mesh).unwrap(), before, "the input mesh is untouched");
    assert!(!d.join("x.json").exists(), "a refused run writes nothing");

    let (code, _, err) = run(towpath().current_dir(&d).args(["route", "--generate", "5", "--save-instance", "g.json"]));
    assert_eq!(code, 0, "{err}");
    let graph = std::fs::read(d.join("g.json")).unwrap();
    for extra in [&["-o", "g.json"][..], &["--save-instance", "g.json"], &["-o", "r.json", "--save-instance", "r.json"]]
    {
        let (code, _, err) =
            run(towpath().current_dir(&d).args(["route", "g.json", "--time-limit", "0.1"]).args(extra));
        assert_eq!(code, 2, "{extra:?}: {err}");
    }
    assert_eq!(std::fs::read(d.join("g.json")).unwrap(), graph, "the graph is untouched");

    std::fs::copy(data("att48.tsp"), d.join("a.tsp")).unwrap();
    std::fs::hard_link(d.join("a.tsp"), d.join("a-link.tsp")).unwrap();
    let (code, _, err) = run(towpath().current_dir(&d).args(["convert", "a.tsp", "-o", "a-link.tsp"]));
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read(d.join("a.tsp")).unwrap(), std::fs::read(data("att48.tsp")).unwrap());
}

#[test]
fn a_failed_run_writes_nothing() {
    let d = demo("failed");
    // The report names a folder: refused before any work, the output not written.
    std::fs::create_dir_all(d.join("reports")).unwrap();
    std::fs::write(d.join("keep.nc"), "mine").unwrap();
    let mut opt = towpath();
    opt.arg("optimize")
        .arg(d.join("planar-45.nc"))
        .arg("-o")
        .arg(d.join("keep.nc"))
        .arg("--report")
        .arg(d.join("reports"));
    afp_args(&mut opt, &d);
    let (code, _, err) = run(&mut opt);
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read_to_string(d.join("keep.nc")).unwrap(), "mine");

    std::fs::write(d.join("keep.json"), "mine").unwrap();
    let (code, _, err) = run(towpath()
        .args(["layup", "plane:a=200,b=100", "--angle", "0", "--tow-width", "6.35", "--tows", "4", "-o"])
        .arg(d.join("keep.json"))
        .arg("--gcode")
        .arg(d.join("reports")));
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read_to_string(d.join("keep.json")).unwrap(), "mine");

    // A program that fails to parse: nothing written, no folder made, no temporary file left.
    std::fs::write(d.join("bad.nc"), "G1 X1\nM20\nG0 X5\n").unwrap();
    let mut opt = towpath();
    opt.arg("optimize").arg(d.join("bad.nc")).arg("-o").arg(d.join("new/out.nc"));
    afp_args(&mut opt, &d);
    let (code, _, err) = run(&mut opt);
    assert_eq!(code, 2, "{err}");
    assert!(!d.join("new").exists(), "{err}");
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn bad_output_paths_are_the_users_error() {
    let d = scratch("paths");
    std::fs::write(d.join("file"), "x").unwrap();
    let cases: Vec<Vec<String>> = vec![
        vec!["convert".into(), data("att48.tsp").display().to_string(), "-o".into(), d.display().to_string()],
        vec![
            "convert".into(),
            data("att48.tsp").display().to_string(),
            "-o".into(),
            d.join("file/x.json").display().to_string(),
        ],
        vec!["route".into(), "--generate".into(), "4".into(), "-o".into(), d.display().to_string()],
        vec![
            "layup".into(),
            "plane:a=200,b=100".into(),
            "--angle".into(),
            "0".into(),
            "--tow-width".into(),
            "6".into(),
            "--tows".into(),
            "2".into(),
            "-o".into(),
            d.join("file/c.json").display().to_string(),
        ],
    ];
    for args in cases {
        let (code, _, err) = run(towpath().args(&args));
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(!err.contains("bug"), "{args:?}: {err}");
    }
}

#[test]
fn convert_and_route_outputs_where_nothing_may_be_written_exit_2() {
    let d = scratch("paths2");
    let att = data("att48.tsp").display().to_string();
    let graph = fixture("rpp_6re.json").display().to_string();
    let nowhere = "/proc/towpath-no-such-file.json".to_string();
    let mut cases: Vec<Vec<String>> = vec![
        vec!["convert".into(), att.clone(), "-o".into(), nowhere.clone()],
        vec!["route".into(), graph.clone(), "--time-limit".into(), "0.1".into(), "-o".into(), nowhere.clone()],
        vec!["route".into(), graph.clone(), "--time-limit".into(), "0.1".into(), "--save-instance".into(), nowhere],
        vec!["route".into(), graph.clone(), "--time-limit".into(), "0.1".into(), "-o".into(), d.display().to_string()],
    ];
    // Permission denied (not testable as root, who may write anywhere).
    let locked = d.join("locked");
    std::fs::create_dir_all(&locked).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o500)).unwrap();
        if std::fs::write(locked.join("probe"), "x").is_err() {
            cases.push(vec!["convert".into(), att.clone(), "-o".into(), locked.join("x.json").display().to_string()]);
            cases.push(vec![
                "route".into(),
                graph.clone(),
                "--time-limit".into(),
                "0.1".into(),
                "-o".into(),
                locked.join("r.json").display().to_string(),
            ]);
        }
    }
    for args in &cases {
        let (code, _, err) = run(towpath().args(args));
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(!err.contains("bug") && !err.contains("panicked"), "{args:?}: {err}");
    }
    // Missing folders are made.
    let deep = d.join("new/deeper/att48.json");
    let (code, _, err) = run(towpath().args(["convert", &att, "-o"]).arg(&deep));
    assert_eq!(code, 0, "{err}");
    assert!(deep.exists());
    let deep = d.join("more/route.json");
    let (code, _, err) = run(towpath().args(["route", &graph, "--time-limit", "0.1", "-o"]).arg(&deep));
    assert_eq!(code, 0, "{err}");
    assert!(deep.exists());
    // solve writes no file; an input that is a folder is the user's error too.
    let (code, _, err) = run(towpath().arg("solve").arg(&d));
    assert_eq!(code, 2, "{err}");
}

#[test]
fn demo_replaces_only_its_own_files() {
    let d = demo("demo-own");
    // A second run replaces the demo's own files.
    let (code, _, err) = run(towpath().args(["demo", "--time-limit", "0.05", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{err}");
    // A file of the user's own with a demo name is kept unless --force.
    let user = scratch("demo-user");
    std::fs::write(user.join("planar-45.nc"), "mine").unwrap();
    let (code, _, err) = run(towpath().args(["demo", "--time-limit", "0.05", "--dir"]).arg(&user));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("planar-45.nc") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(user.join("planar-45.nc")).unwrap(), "mine");
    assert!(!user.join("planar-0.nc").exists(), "a refused demo writes nothing");
    let (code, _, err) = run(towpath().args(["demo", "--time-limit", "0.05", "--force", "--dir"]).arg(&user));
    assert_eq!(code, 0, "{err}");
    assert_ne!(std::fs::read_to_string(user.join("planar-45.nc")).unwrap(), "mine");
}
