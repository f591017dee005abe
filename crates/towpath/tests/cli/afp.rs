//! The AFP subcommands end to end: `demo`, `optimize`, `verify`, their exit codes and messages.

use std::path::Path;
use std::process::Command;

use super::common::*;

fn demo(dir: &Path) {
    let (code, out, err) = run(towpath().args(["demo", "--time-limit", "0.05", "--dir"]).arg(dir));
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(out.contains("planar-45") && out.contains("cylinder-base-3-pads"), "{out}");
}

#[test]
fn demo_optimize_verify_round() {
    let d = scratch("round");
    demo(&d);
    for f in
        ["gantry-afp.toml", "mandrel-afp.toml", "dialect.toml", "planar-45.nc", "planar-45.opt.nc", "planar-45.html"]
    {
        assert!(d.join(f).exists(), "{f} missing");
    }
    let out = d.join("p45.nc");
    let report = d.join("p45.json");
    let (code, stdout, err) = run(towpath()
        .arg("optimize")
        .arg(d.join("planar-45.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--dialect")
        .arg(d.join("dialect.toml"))
        .args(["--bidirectional", "--cost", "time", "--iterations", "300", "--json", "-o"])
        .arg(&out)
        .arg("--report")
        .arg(&report));
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(json["courses"], 49);
    assert_eq!(json["cost"], "time");
    let time = json["totals"].as_array().unwrap().iter().find(|t| t["kind"] == "time").unwrap();
    assert!(time["off_after"].as_f64().unwrap() < time["off_before"].as_f64().unwrap());
    assert!(std::fs::read_to_string(&report).unwrap().contains("\"per_set\""));

    let (code, stdout, err) = run(towpath()
        .arg("verify")
        .arg(d.join("planar-45.nc"))
        .arg(&out)
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--dialect")
        .arg(d.join("dialect.toml")));
    assert_eq!(code, 0, "{err}");
    assert!(stdout.starts_with("verified: 49 courses"), "{stdout}");
    assert!(stdout.contains("time") && stdout.contains("axis") && stdout.contains("tool"), "{stdout}");

    // A tampered program fails verification with exit code 3.
    let text = std::fs::read_to_string(&out).unwrap();
    let line = text.lines().position(|l| l.starts_with("M60")).unwrap();
    let tampered: Vec<&str> = text.lines().enumerate().filter(|(i, _)| *i != line).map(|(_, l)| l).collect();
    let bad = d.join("bad.nc");
    std::fs::write(&bad, tampered.join("\n")).unwrap();
    let (code, _, err) = run(towpath()
        .arg("verify")
        .arg(d.join("planar-45.nc"))
        .arg(&bad)
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--dialect")
        .arg(d.join("dialect.toml")));
    assert!(code == 3 || code == 2, "{code} {err}");
    assert!(err.contains("bad.nc"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_names_file_and_line() {
    let d = scratch("bad");
    demo(&d);
    let text = std::fs::read_to_string(d.join("planar-0.nc")).unwrap();
    let bad = d.join("bad.nc");
    // Line 9 of the program gets an axis the machine does not have.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let n = lines.iter().position(|l| l.starts_with("G1 ") && l.contains('X')).unwrap();
    lines[n].push_str(" W3");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(&bad)
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .args(["--tow-width", "6.35", "-o"])
        .arg(d.join("out.nc")));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.nc") && err.contains(&format!("line {}", n + 1)) && err.contains("unknown axis W"),
        "{err}"
    );
    // Several plies and no width: refused, saying what to give.
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(d.join("planar-0.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("-o")
        .arg(d.join("out.nc")));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--tow-width"), "{err}");
    // A broken machine file names its line.
    let m = d.join("m.toml");
    std::fs::write(&m, "name = \"m\"\n[[axis]]\nlabel = \"X\"\nkind = \"lineer\"\n").unwrap();
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(d.join("planar-0.nc"))
        .arg("--machine")
        .arg(&m)
        .arg("-o")
        .arg(d.join("o.nc")));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("m.toml") && err.contains("line 4"), "{err}");
    // Text that is not UTF-8 (a Latin-1 degree sign in a comment): the line and byte.
    let latin1 = d.join("latin1.nc");
    let mut bytes = text.as_bytes().to_vec();
    let at = text.find("(PLY 2").unwrap() + 4;
    bytes.insert(at, 0xb0);
    std::fs::write(&latin1, &bytes).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(&latin1)
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("-o")
        .arg(d.join("o.nc")));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&format!("latin1.nc: line {line}: byte 5 (0xb0) is not UTF-8")), "{err}");
    // A dialect that does not fit the machine names both files, not the program's first line.
    let dialect = d.join("clash.toml");
    std::fs::write(&dialect, "[clearance]\naxis = \"C\"\nvalue = 100.0\n").unwrap();
    let (code, _, err) = run(towpath()
        .arg("verify")
        .arg(d.join("planar-0.nc"))
        .arg(d.join("planar-0.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--dialect")
        .arg(&dialect));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("gantry-afp.toml with")
            && err.contains("clash.toml: dialect: clearance.axis: C is not a linear axis"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `towpath optimize --solver NAME`: the published solvers (docs/references.md) sequence the same program, their
/// answers are written and verified like towpath's, and the report says which solver ran.
#[test]
fn optimize_with_each_solver() {
    let d = scratch("solvers");
    demo(&d);
    let optimize = |solver: &str, extra: &[&str]| {
        run(towpath()
            .arg("optimize")
            .arg(d.join("planar-0.nc"))
            .arg("--machine")
            .arg(d.join("gantry-afp.toml"))
            .arg("--dialect")
            .arg(d.join("dialect.toml"))
            .args(["--bidirectional", "--time-limit", "0.3", "--threads", "1", "--json", "--solver", solver])
            .args(extra)
            .arg("-o")
            .arg(d.join(format!("{solver}.nc"))))
    };
    for solver in ["doherty", "ga", "aco1", "aco2", "castelino", "towpath"] {
        let (code, stdout, err) = optimize(solver, &[]);
        assert_eq!(code, 0, "{solver}: {err}");
        let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
        assert_eq!(json["solver"]["solver"], solver);
        assert_eq!(json["verified"], true);
        let axis = json["totals"].as_array().unwrap().iter().find(|t| t["kind"] == "axis").unwrap();
        let (before, after) = (axis["off_before"].as_f64().unwrap(), axis["off_after"].as_f64().unwrap());
        assert!(after <= before, "{solver}: {before} -> {after}");
        // The written program verifies on its own.
        let (code, stdout, err) = run(towpath()
            .arg("verify")
            .arg(d.join("planar-0.nc"))
            .arg(d.join(format!("{solver}.nc")))
            .arg("--machine")
            .arg(d.join("gantry-afp.toml"))
            .arg("--dialect")
            .arg(d.join("dialect.toml")));
        assert_eq!(code, 0, "{solver}: {err}");
        assert!(stdout.starts_with("verified: 30 courses"), "{solver}: {stdout}");
    }
    // Doherty et al.'s solver lays each precedence set freely: it cannot keep the ply order.
    let (code, _, err) = optimize("doherty", &["--keep-ply-order"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("planar-0.nc") && err.contains("doherty") && err.contains("--keep-ply-order"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The flags not shown above: `--course-width`, `--report x.html`, the two widths
/// refused together, and `verify --precedence sets` holding an output to seed 000's sets.
#[test]
fn course_width_html_report_and_sets_precedence() {
    let d = scratch("sets");
    demo(&d);
    let out = d.join("sets.nc");
    let html = d.join("sets.html");
    let base = |cmd: &mut Command| {
        cmd.arg("--machine").arg(d.join("gantry-afp.toml")).args(["--course-width", "50.8"]);
    };
    let mut cmd = towpath();
    cmd.arg("optimize").arg(d.join("planar-0.nc"));
    base(&mut cmd);
    cmd.args(["--precedence", "sets", "--time-limit", "0.2", "--threads", "1", "-o"])
        .arg(&out)
        .arg("--report")
        .arg(&html);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("verified"), "{stdout}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.starts_with("<!doctype html>") && page.matches("<svg").count() == 2,
        "{}",
        &page[..200.min(page.len())]
    );
    // Plan view: plies coloured with a legend, an arrow per laid course, a start marker and a
    // scale bar in each of the two views.
    assert_eq!(page.matches("class=\"start\"").count(), 2, "start markers");
    assert_eq!(page.matches("<g class=\"scale\">").count(), 2, "scale bars");
    assert!(page.matches("marker-end=").count() >= 2 * 30, "an arrow per course in each view");
    for ply in 1..=4 {
        assert!(page.contains(&format!("</i>ply {ply}</span>")), "legend for ply {ply}");
    }
    assert!(page.find("cycle time: off-part").unwrap() < page.find("<h2>Totals").unwrap(), "time leads");
    let mut cmd = towpath();
    cmd.arg("verify").arg(d.join("planar-0.nc")).arg(&out);
    base(&mut cmd);
    cmd.args(["--precedence", "sets"]);
    let (code, stdout, err) = run(&mut cmd);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("Doherty et al.'s precedence sets in order"), "{stdout}");
    // Both widths at once: refused by the argument parser.
    let mut cmd = towpath();
    cmd.arg("verify").arg(d.join("planar-0.nc")).arg(&out);
    base(&mut cmd);
    cmd.args(["--tow-width", "6.35"]);
    let (code, _, err) = run(&mut cmd);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--tow-width") && err.contains("--course-width"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `-o` or `--report` naming an input (however spelt, or through a link) is refused before
/// anything is written, so the input survives; so is a report over the output. A path that
/// cannot be written is a bad argument (exit 2), and a time limit too large for a duration is
/// refused, not a panic.
#[test]
fn outputs_never_overwrite_inputs() {
    let d = scratch("overwrite");
    demo(&d);
    let program = d.join("planar-0.nc");
    let original = std::fs::read(&program).unwrap();
    let hard = d.join("hard.nc");
    std::fs::hard_link(&program, &hard).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&program, d.join("link.nc")).unwrap();
    let spelt_again = d.join(".").join("planar-0.nc");
    let optimize = |extra: &[&std::ffi::OsStr]| {
        run(towpath()
            .arg("optimize")
            .arg(&program)
            .arg("--machine")
            .arg(d.join("gantry-afp.toml"))
            .arg("--dialect")
            .arg(d.join("dialect.toml"))
            .args(["--time-limit", "0.05", "--threads", "1"])
            .args(extra))
    };
    let os = |p: &Path| p.as_os_str().to_owned();
    let cases: Vec<(Vec<std::ffi::OsString>, &str)> = vec![
        (vec!["-o".into(), os(&program)], "the output would overwrite the program"),
        (vec!["-o".into(), os(&spelt_again)], "the output would overwrite the program"),
        (vec!["-o".into(), os(&hard)], "the output would overwrite the program"),
        #[cfg(unix)]
        (vec!["-o".into(), os(&d.join("link.nc"))], "the output would overwrite the program"),
        (vec!["-o".into(), os(&d.join("dialect.toml"))], "the output would overwrite the dialect file"),
        (
            vec!["-o".into(), os(&d.join("x.nc")), "--report".into(), os(&program)],
            "the report would overwrite the program",
        ),
        (
            vec!["-o".into(), os(&d.join("x.nc")), "--report".into(), os(&d.join(".").join("x.nc"))],
            "the report and the output would be the same file",
        ),
    ];
    for (extra, message) in cases {
        let args: Vec<&std::ffi::OsStr> = extra.iter().map(|a| a.as_os_str()).collect();
        let (code, _, err) = optimize(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(message), "{extra:?}: {err}");
        assert_eq!(std::fs::read(&program).unwrap(), original, "{extra:?} changed the input");
        assert!(!d.join("x.nc").exists(), "{extra:?} wrote an output before refusing");
    }
    // An output under a file (not a directory): refused as a bad argument, naming the path.
    let under_a_file = program.join("out.nc");
    let (code, _, err) = optimize(&["-o".as_ref(), under_a_file.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is not a directory"), "{err}");
    for cmd in [&["optimize"][..], &["demo"][..]] {
        let mut c = towpath();
        c.args(cmd);
        if cmd[0] == "optimize" {
            c.arg(&program).arg("--machine").arg(d.join("gantry-afp.toml")).arg("-o").arg(d.join("y.nc"));
        } else {
            c.arg("--dir").arg(d.join("demo2"));
        }
        let (code, _, err) = run(c.args(["--time-limit", "1e300"]));
        assert_eq!(code, 2, "{cmd:?}: {err}");
        assert!(err.contains("--time-limit 1e300: too large"), "{cmd:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
