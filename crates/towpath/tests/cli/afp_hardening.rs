//! Issue 17 ("hardening"), the AFP commands: what `optimize`, `verify` and `demo` do with
//! the classes of input the issue found (a mandrel program on its axis, codes inside a course,
//! lines slipped into a program, widths, machine numbers, rapids in contact, CR line ends, a
//! failed run's outputs), each checked by exit code, message and files.

use std::path::{Path, PathBuf};

use super::common::*;

/// The demo's files in a fresh folder.
fn demo(tag: &str) -> PathBuf {
    let d = scratch(tag);
    let (code, out, err) = run(towpath().args(["demo", "--iterations", "50", "--dir"]).arg(&d));
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(out.contains("Course width: tow width 6.35 mm × tows on, from the demo's dialect"), "{out}");
    d
}

fn optimize(d: &Path, program: &Path, machine: &str, extra: &[&str], out: &Path) -> (i32, String, String) {
    run(towpath()
        .arg("optimize")
        .arg(program)
        .arg("--machine")
        .arg(d.join(machine))
        .args(["--iterations", "100", "--threads", "1"])
        .args(extra)
        .arg("-o")
        .arg(out))
}

fn verify(d: &Path, original: &Path, optimized: &Path, machine: &str, extra: &[&str]) -> (i32, String, String) {
    run(towpath().arg("verify").arg(original).arg(optimized).arg("--machine").arg(d.join(machine)).args(extra))
}

fn dialect(d: &Path) -> String {
    d.join("dialect.toml").display().to_string()
}

/// A mandrel program laid on (or 0.1 µm from) the mandrel axis: refused with exit 2, naming the
/// program's line, the mandrel axis's origin and the machine file; nothing written.
#[test]
fn a_program_on_the_mandrel_axis_is_refused() {
    let d = demo("mandrel-axis");
    let text = std::fs::read_to_string(d.join("cylinder-base-3-pads.nc")).unwrap();
    for z in ["0", "0.0001"] {
        let bad = d.join(format!("axis-{z}.nc"));
        std::fs::write(&bad, text.replace("Z400 ", &format!("Z{z} "))).unwrap();
        let out = d.join("axis.opt.nc");
        let (code, _, err) = optimize(&d, &bad, "mandrel-afp.toml", &["--dialect", &dialect(&d)], &out);
        assert_eq!(code, 2, "{err}");
        let lines: Vec<&str> = text.lines().collect();
        let restart = lines.iter().position(|l| l.starts_with("M60")).unwrap();
        let line = restart + lines[restart..].iter().position(|l| l.starts_with("G1")).unwrap() + 1;
        assert!(err.contains(&format!("axis-{z}.nc: line {line}: the tool point is")), "{err}");
        assert!(err.contains("`origin` and `direction` of axis A") && err.contains("mandrel-afp.toml"), "{err}");
        assert!(!out.exists());
        let (code, _, err) = verify(&d, &bad, &bad, "mandrel-afp.toml", &["--dialect", &dialect(&d)]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("mandrel axis"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A run that fails after its work (the report names a folder) writes nothing: the output
/// program is not there afterwards, and the folder is untouched.
#[test]
fn a_failed_optimize_writes_nothing() {
    let d = demo("no-write");
    let folder = d.join("reports");
    std::fs::create_dir(&folder).unwrap();
    let out = d.join("x.nc");
    let (code, _, err) = run(towpath()
        .arg("optimize")
        .arg(d.join("planar-0.nc"))
        .arg("--machine")
        .arg(d.join("gantry-afp.toml"))
        .arg("--dialect")
        .arg(d.join("dialect.toml"))
        .args(["--iterations", "50", "-o"])
        .arg(&out)
        .arg("--report")
        .arg(&folder));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("reports"), "{err}");
    assert!(!out.exists(), "x.nc was written by a failed run");
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0);
    let _ = std::fs::remove_dir_all(&d);
}

/// A rapid move while the roller is in contact is refused by both commands, naming the line;
/// a program with CR line ends is optimized into one with CR line ends that verifies.
#[test]
fn rapids_in_contact_and_cr_line_ends() {
    let d = demo("rapid-cr");
    let text = std::fs::read_to_string(d.join("planar-0.nc")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let contact = lines.iter().position(|l| l == "M20").unwrap();
    let mv = contact + lines[contact..].iter().position(|l| l.starts_with("G1 X")).unwrap();
    lines[mv] = lines[mv].replacen("G1", "G0", 1);
    let bad = d.join("rapid.nc");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    let (code, _, err) = optimize(&d, &bad, "gantry-afp.toml", &["--dialect", &dialect(&d)], &d.join("o.nc"));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("rapid.nc: line {}: a rapid move (G0) while the roller is in contact", mv + 1)),
        "{err}"
    );
    let (code, _, err) = verify(&d, &d.join("planar-0.nc"), &bad, "gantry-afp.toml", &["--dialect", &dialect(&d)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&format!("rapid.nc: line {}", mv + 1)), "{err}");
    // CR line ends.
    let cr = d.join("cr.nc");
    std::fs::write(&cr, text.replace('\n', "\r")).unwrap();
    let out = d.join("cr.opt.nc");
    let (code, stdout, err) =
        optimize(&d, &cr, "gantry-afp.toml", &["--dialect", &dialect(&d), "--bidirectional"], &out);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("30 courses in 4 plies"), "{stdout}");
    let written = std::fs::read(&out).unwrap();
    assert!(!written.contains(&b'\n') && written.iter().filter(|&&b| b == b'\r').count() > 300);
    let (code, stdout, err) = verify(&d, &cr, &out, "gantry-afp.toml", &["--dialect", &dialect(&d)]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.starts_with("verified: 30 courses"), "{stdout}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Ply by ply needs no widths; a width far wider than the part and an absurd machine weight
/// are refused (the weight with the machine file's line); a command-line width far from the
/// dialect's is used with a warning on stderr and in the JSON, and every summary says which
/// width was used and where it came from.
#[test]
fn widths_and_machine_numbers() {
    let d = demo("widths");
    let program = d.join("planar-0.nc");
    let out = d.join("w.nc");
    let (code, stdout, err) = optimize(&d, &program, "gantry-afp.toml", &["--precedence", "plies"], &out);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("width: none (ply by ply: no footprints needed)"), "{stdout}");
    let (code, stdout, err) = verify(&d, &program, &out, "gantry-afp.toml", &["--precedence", "plies"]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("precedence kept (ply by ply)") && stdout.contains("width: none"), "{stdout}");
    let (code, _, err) = optimize(&d, &program, "gantry-afp.toml", &["--course-width", "1e20"], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a course width of 1e20 mm is more than 2 times the whole laid part"), "{err}");
    let machine = std::fs::read_to_string(d.join("gantry-afp.toml")).unwrap();
    let line = machine.lines().position(|l| l.starts_with("weight")).unwrap() + 1;
    std::fs::write(d.join("heavy.toml"), machine.replacen("weight = 1.0", "weight = 1e308", 1)).unwrap();
    let (code, _, err) = optimize(&d, &program, "heavy.toml", &[], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&format!("heavy.toml: line {line}: axis[0].weight: 1e308 is above 1e6")), "{err}");
    // An inch user's tow width beside the dialect's 6.35 mm.
    let (code, stdout, err) =
        optimize(&d, &program, "gantry-afp.toml", &["--dialect", &dialect(&d), "--tow-width", "0.25", "--json"], &out);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the tow width 0.25 mm given is 25.4 times narrower"), "{err}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(json["width"]["source"], "given");
    assert_eq!(json["width_from"], "the command line, --tow-width");
    assert!(json["warnings"][0].as_str().unwrap().contains("inches"), "{json}");
    let (code, stdout, err) =
        verify(&d, &program, &out, "gantry-afp.toml", &["--dialect", &dialect(&d), "--tow-width", "0.25"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the tow width 0.25 mm given"), "{err}");
    assert!(stdout.contains("width: tow width 0.25 mm × tows on (from the command line, --tow-width)"), "{stdout}");
    // The dialect's width, said so.
    let (code, stdout, err) = optimize(&d, &program, "gantry-afp.toml", &["--dialect", &dialect(&d)], &out);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("width: tow width 6.35 mm × tows on (from the dialect, "), "{stdout}");
    assert!(!err.contains("warning"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Heater codes inside the courses keep them forward (said on stderr and in the summary) until
/// the dialect declares them a switch; then courses reverse and verify. A stop slipped into a
/// course or into the footer fails verification (exit 3), naming its line.
#[test]
fn codes_inside_courses_and_slipped_lines() {
    let d = demo("codes");
    let text = std::fs::read_to_string(d.join("planar-0.nc")).unwrap();
    let heated = text.replace("M20\n", "M20\nM8 (heater on)\n").replace("M21\n", "M9 (heater off)\nM21\n");
    let program = d.join("heat.nc");
    std::fs::write(&program, &heated).unwrap();
    let out = d.join("heat.opt.nc");
    let (code, stdout, err) =
        optimize(&d, &program, "gantry-afp.toml", &["--dialect", &dialect(&d), "--bidirectional"], &out);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("0 courses reversed (30 kept forward: see the report)"), "{stdout}");
    assert!(err.contains("warning: 30 courses are laid forward only") && err.contains("M8"), "{err}");
    let switch = d.join("switch.toml");
    let base = std::fs::read_to_string(d.join("dialect.toml")).unwrap();
    let base = base.replace("switch = []\n", "");
    std::fs::write(&switch, format!("{base}\n[[switch]]\non = \"M8\"\noff = \"M9\"\n")).unwrap();
    let sw = switch.display().to_string();
    let (code, stdout, err) = optimize(&d, &program, "gantry-afp.toml", &["--dialect", &sw, "--bidirectional"], &out);
    assert_eq!(code, 0, "{err}");
    assert!(!stdout.contains(" 0 courses reversed"), "{stdout}");
    let (code, _, err) = verify(&d, &program, &out, "gantry-afp.toml", &["--dialect", &sw]);
    assert_eq!(code, 0, "{err}");
    // Without the switch, the same output is not a legal reversal.
    let (code, _, err) = verify(&d, &program, &out, "gantry-afp.toml", &["--dialect", &dialect(&d)]);
    assert_eq!(code, 3, "{err}");
    // M0 slipped in after a tow restart.
    let mut lines: Vec<String> = std::fs::read_to_string(&out).unwrap().lines().map(str::to_string).collect();
    let at = lines.iter().position(|l| l.starts_with("M60")).unwrap() + 1;
    lines.insert(at, "M0".into());
    let slipped = d.join("slipped.nc");
    std::fs::write(&slipped, lines.join("\n") + "\n").unwrap();
    let (code, _, err) = verify(&d, &program, &slipped, "gantry-afp.toml", &["--dialect", &sw]);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains(&format!("line {} (\"M0\")", at + 1)), "{err}");
    // An extra line in the footer is named as itself, not as another line missing.
    let mut lines: Vec<String> = std::fs::read_to_string(&out).unwrap().lines().map(str::to_string).collect();
    let at = lines.len() - 1;
    lines.insert(at, "M0".into());
    std::fs::write(&slipped, lines.join("\n") + "\n").unwrap();
    let (code, _, err) = verify(&d, &program, &slipped, "gantry-afp.toml", &["--dialect", &sw]);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains(&format!("line {} (\"M0\") in the footer is not a line of the original", at + 1)), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
