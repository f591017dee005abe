//! `fuzz-cli`: fuzzes the `towpath` command line on stable Rust, the way a hostile user would
//! drive it: argument vectors (sane, boundary and nonsense values, output paths that name an
//! input, a folder or nowhere) together with input files mutated from the repository's test
//! data. Every run happens in its own folder, under a time and an address-space limit, and fails
//! when the program panics, aborts (an allocation beyond the limit: a size taken on trust), hangs,
//! exits 70 (a bug by its own account) or with a code towpath does not use, or changes one of its
//! inputs. A failing case is kept, with a script that replays it.
//!
//! ```text
//! fuzz-cli [--bin target/debug/towpath] [--seconds 150 | --cases N] [--seed N]
//!          [--targets solve,convert,route,layup,optimize,verify] [--jobs 2]
//!          [--timeout 30] [--memory-mb 4096] [--out fuzz/cli-failures] [--repo .] [--show]
//! ```
//!
//! See `fuzz/README.md`.

mod cases;
mod exec;
mod mutate;
mod rng;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use cases::{Corpus, Seed, Target};
use exec::{Limits, Verdict};

struct Options {
    bin: PathBuf,
    repo: PathBuf,
    seconds: Option<f64>,
    cases: Option<u64>,
    seed: u64,
    targets: Vec<Target>,
    jobs: usize,
    limits: Limits,
    out: PathBuf,
    /// Print every case (its arguments, exit code and first line of stderr).
    show: bool,
}

fn parse_options() -> Result<Options, String> {
    let mut o = Options {
        bin: PathBuf::from("target/debug/towpath"),
        repo: PathBuf::from("."),
        seconds: None,
        cases: None,
        seed: std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(1, |d| d.as_secs()),
        targets: Target::ALL.to_vec(),
        jobs: 2,
        limits: Limits { timeout: Duration::from_secs(30), memory: 4096 << 20 },
        out: PathBuf::from("fuzz/cli-failures"),
        show: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        let num = |v: String| v.parse::<f64>().map_err(|_| format!("{a}: `{v}` is not a number"));
        match a.as_str() {
            "--bin" => o.bin = PathBuf::from(value()?),
            "--repo" => o.repo = PathBuf::from(value()?),
            "--seconds" => o.seconds = Some(num(value()?)?),
            "--cases" => o.cases = Some(num(value()?)? as u64),
            "--seed" => o.seed = num(value()?)? as u64,
            "--jobs" => o.jobs = (num(value()?)? as usize).max(1),
            "--timeout" => o.limits.timeout = Duration::from_secs_f64(num(value()?)?.max(1.0)),
            "--memory-mb" => o.limits.memory = (num(value()?)? as u64) << 20,
            "--out" => o.out = PathBuf::from(value()?),
            "--show" => o.show = true,
            "--targets" => {
                let v = value()?;
                o.targets = v
                    .split(',')
                    .map(|t| Target::ALL.into_iter().find(|x| x.name() == t).ok_or(format!("unknown target {t}")))
                    .collect::<Result<_, _>>()?;
            }
            "-h" | "--help" => return Err(String::new()),
            _ => return Err(format!("unknown option {a}")),
        }
    }
    if o.seconds.is_none() && o.cases.is_none() {
        o.seconds = Some(60.0);
    }
    Ok(o)
}

fn main() -> ExitCode {
    let o = match parse_options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}\nusage: fuzz-cli [--bin PATH] [--seconds S | --cases N] [--seed N] [--targets a,b] [--jobs N] [--timeout S] [--memory-mb MB] [--out DIR] [--repo DIR] [--show] (see fuzz/README.md)");
            return ExitCode::from(2);
        }
    };
    let o = Options { bin: std::fs::canonicalize(&o.bin).unwrap_or(o.bin), ..o };
    let runs = std::process::Command::new(&o.bin).arg("--version").output().is_ok_and(|out| out.status.success());
    if !runs {
        eprintln!("fuzz-cli: {} does not run (build it first: cargo build -p towpath)", o.bin.display());
        return ExitCode::from(2);
    }
    let work = std::env::temp_dir().join(format!("towpath-fuzz-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    if let Err(e) = std::fs::create_dir_all(&work) {
        eprintln!("cannot make {}: {e}", work.display());
        return ExitCode::from(2);
    }
    let corpus = build_corpus(&o, &work.join("corpus"));
    eprintln!(
        "fuzz-cli: seed {}, {} problems, {} graphs, {} programs, {} meshes; binary {}",
        o.seed,
        corpus.problems.len(),
        corpus.graphs.len(),
        corpus.programs.len(),
        corpus.meshes.len(),
        o.bin.display()
    );
    let mut failures = 0;
    for (k, &target) in o.targets.iter().enumerate() {
        let budget = o.seconds.map(|s| Duration::from_secs_f64(s / o.targets.len() as f64));
        let seed = o.seed.wrapping_add(k as u64 * 0x9E37_79B9);
        failures += fuzz_target(&o, target, &corpus, &work, seed, budget);
    }
    let _ = std::fs::remove_dir_all(&work);
    if failures > 0 {
        eprintln!("fuzz-cli: {failures} failing case(s), kept in {}", o.out.display());
        ExitCode::from(1)
    } else {
        eprintln!("fuzz-cli: no failure");
        ExitCode::SUCCESS
    }
}

/// Runs one target on `jobs` threads until its budget (time or cases) is spent; returns the
/// number of failures.
fn fuzz_target(
    o: &Options,
    target: Target,
    corpus: &Corpus,
    work: &Path,
    seed: u64,
    budget: Option<Duration>,
) -> usize {
    let t0 = Instant::now();
    let next = AtomicUsize::new(0);
    let codes: Mutex<BTreeMap<i32, u64>> = Mutex::new(BTreeMap::new());
    let failed = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for job in 0..o.jobs {
            let (next, codes, failed) = (&next, &codes, &failed);
            s.spawn(move || {
                let mut rng = rng::Rng::new(seed ^ (job as u64).wrapping_mul(0xA24B_AED4_963E_E407));
                loop {
                    if budget.is_some_and(|b| t0.elapsed() >= b) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if o.cases.is_some_and(|n| i as u64 >= n) {
                        break;
                    }
                    let dir = work.join(format!("{}-{i}", target.name()));
                    let _ = std::fs::remove_dir_all(&dir);
                    if std::fs::create_dir_all(&dir).is_err() {
                        continue;
                    }
                    let case = cases::make(target, &mut rng, corpus, &dir);
                    let (verdict, stderr) = exec::run(&o.bin, &case, o.limits);
                    match verdict {
                        Verdict::Fine(c) => {
                            if o.show {
                                let first = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
                                eprintln!("  [{c}] towpath {}\n       {first}", case.argv.join(" "));
                            }
                            *codes.lock().unwrap_or_else(|p| p.into_inner()).entry(c).or_default() += 1;
                            let _ = std::fs::remove_dir_all(&dir);
                        }
                        Verdict::Failed(why) => {
                            failed.fetch_add(1, Ordering::Relaxed);
                            keep(o, target, i, &case, &why, &stderr);
                        }
                    }
                }
            });
        }
    });
    let codes = codes.into_inner().unwrap_or_else(|p| p.into_inner());
    let total: u64 = codes.values().sum::<u64>() + failed.load(Ordering::Relaxed) as u64;
    let by_code: Vec<String> = codes.iter().map(|(c, n)| format!("exit {c}: {n}")).collect();
    eprintln!(
        "  {:<9} {total:>6} cases in {:>5.1} s ({}), {} failing",
        target.name(),
        t0.elapsed().as_secs_f64(),
        by_code.join(", "),
        failed.load(Ordering::Relaxed)
    );
    failed.into_inner()
}

/// Keeps a failing case: its folder, what went wrong, and a script that replays it.
fn keep(o: &Options, target: Target, i: usize, case: &exec::Case, why: &str, stderr: &str) {
    let dest = o.out.join(format!("{}-{i}", target.name()));
    let _ = std::fs::remove_dir_all(&dest);
    let _ = std::fs::create_dir_all(&dest);
    copy_dir(&case.dir, &dest);
    let quoted: Vec<String> = case.argv.iter().map(|a| shell_quote(a)).collect();
    let bin = std::fs::canonicalize(&o.bin).unwrap_or_else(|_| o.bin.clone());
    let close = if case.close_stdout { " | true" } else { "" };
    let script = format!(
        "#!/bin/sh\n# {why}\ncd \"$(dirname \"$0\")\" && {} {}{close}\n",
        shell_quote(&bin.display().to_string()),
        quoted.join(" ")
    );
    let _ = std::fs::write(dest.join("replay.sh"), script);
    let _ = std::fs::write(dest.join("stderr.txt"), stderr);
    let telling = |l: &&str| l.contains("panicked at") || l.starts_with("error:") || l.contains("memory allocation");
    let line = stderr.lines().find(telling).or_else(|| stderr.lines().last()).unwrap_or("");
    eprintln!("  FAIL {} #{i}: {why}: towpath {}\n       {line}", target.name(), quoted.join(" "));
}

fn copy_dir(from: &Path, to: &Path) {
    let Ok(entries) = std::fs::read_dir(from) else { return };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name();
        if p.is_dir() {
            let _ = std::fs::create_dir_all(to.join(&name));
            copy_dir(&p, &to.join(&name));
        } else if p.is_file() {
            let _ = std::fs::copy(&p, to.join(&name));
        }
    }
}

fn shell_quote(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "-_./:=,+".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// The corpus: the repository's problem files and route fixtures, and the demo's programs,
/// machine and dialect, a generated travel graph and meshes written by the binary itself.
fn build_corpus(o: &Options, dir: &Path) -> Corpus {
    let _ = std::fs::create_dir_all(dir);
    let mut c = Corpus::default();
    let data = o.repo.join("crates/towpath-formats/tests/data");
    for ext in ["tsp", "atsp", "sop", "gtsp", "pcglns", "json", "tour"] {
        c.problems.extend(files_with(&data, ext, 200_000));
        c.problems.extend(files_with(&data.join("layouts"), ext, 200_000));
    }
    c.graphs.extend(files_with(&o.repo.join("crates/towpath/tests/fixtures"), "json", 200_000));
    let run = |args: &[&str]| {
        std::process::Command::new(&o.bin)
            .args(args)
            .current_dir(dir)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if run(&["route", "--generate", "6", "--time-limit", "0.1", "--save-instance", "gen.json"]) {
        c.graphs.extend(files_with(dir, "json", 200_000));
    }
    if run(&["demo", "--time-limit", "0.05", "--dir", "demo"]) {
        let demo = dir.join("demo");
        c.programs.extend(files_with(&demo, "nc", 400_000));
        for s in files_with(&demo, "toml", 100_000) {
            if s.name.contains("dialect") {
                c.dialects.push(s);
            } else {
                c.machines.push(s);
            }
        }
    }
    for ext in ["stl", "obj", "ply"] {
        let name = format!("plane.{ext}");
        if run(&[
            "layup",
            "plane:a=200,b=100",
            "--angle",
            "0",
            "--tow-width",
            "6.35",
            "--tows",
            "2",
            "-o",
            "c.json",
            "--write-mesh",
            &name,
        ]) {
            c.meshes.extend(files_with(dir, ext, 400_000));
        }
    }
    // Small hand-made problems that reach the fixed-edge, SOP and JSON paths quickly.
    c.problems.push(Seed {
        name: "fixed.atsp".into(),
        bytes: b"NAME: f\nTYPE: ATSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\n\
EDGE_WEIGHT_SECTION\n0 1 100\n1 0 1\n1 1 0\nFIXED_EDGES_SECTION\n1 3\n-1\nEOF\n"
            .to_vec(),
    });
    c.problems.push(Seed {
        name: "line.tsp".into(),
        bytes: b"NAME: line\nTYPE: TSP\nDIMENSION: 5\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n2 3 0\n3 1 0\n4 4 0\n5 2 0\nEOF\n"
            .to_vec(),
    });
    c
}

/// The files of `dir` with extension `ext` (not recursive), up to `max_bytes` each.
fn files_with(dir: &Path, ext: &str, max_bytes: u64) -> Vec<Seed> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut out: Vec<Seed> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.len() <= max_bytes))
        .filter_map(|p| {
            let bytes = std::fs::read(&p).ok()?;
            Some(Seed { name: p.file_name()?.to_string_lossy().into_owned(), bytes })
        })
        .collect();
    out.sort_by(|a, b| a.name.cmp(&b.name));
    out
}
