//! Running one case: the binary in the case's folder with limits on time and memory, and the
//! verdict on what it did.

use std::io::Read;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One run of the binary.
pub struct Case {
    /// The folder the run happens in (its current directory; inputs and outputs live there).
    pub dir: PathBuf,
    /// The arguments after the program name.
    pub argv: Vec<String>,
    /// Files the run may read but never change.
    pub inputs: Vec<PathBuf>,
    /// Close standard output before the program writes to it.
    pub close_stdout: bool,
}

/// What went wrong in a run, if anything.
pub enum Verdict {
    /// The run ended as a run of towpath may: exit code 0, 2 (refused input) or 3 (failed check).
    Fine(i32),
    /// A failure, said in a line.
    Failed(String),
}

/// Limits of a run.
#[derive(Clone, Copy)]
pub struct Limits {
    /// Wall time before the run counts as hung.
    pub timeout: Duration,
    /// Address space of the process, bytes: an allocation beyond it aborts the run.
    pub memory: u64,
}

/// Runs a case and judges it. Returns the verdict and what the program wrote on stderr.
pub fn run(bin: &Path, case: &Case, limits: Limits) -> (Verdict, String) {
    let before: Vec<Option<Vec<u8>>> = case.inputs.iter().map(|p| std::fs::read(p).ok()).collect();
    let mut cmd = Command::new(bin);
    cmd.args(&case.argv).current_dir(&case.dir).stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
    let memory = limits.memory;
    // SAFETY: between fork and exec only async-signal-safe calls are made (setrlimit).
    unsafe {
        cmd.pre_exec(move || {
            let mem = libc::rlimit { rlim_cur: memory, rlim_max: memory };
            let none = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
            libc::setrlimit(libc::RLIMIT_AS, &mem);
            libc::setrlimit(libc::RLIMIT_CORE, &none);
            Ok(())
        });
    }
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => return (Verdict::Failed(format!("cannot start {}: {e}", bin.display())), String::new()),
    };
    let stdout = child.stdout.take();
    let out_reader = if case.close_stdout {
        drop(stdout);
        None
    } else {
        stdout.map(|mut s| {
            std::thread::spawn(move || {
                let mut sink = Vec::new();
                let _ = s.read_to_end(&mut sink);
            })
        })
    };
    let err_reader = child.stderr.take().map(|mut s| {
        std::thread::spawn(move || {
            let mut text = Vec::new();
            let _ = s.read_to_end(&mut text);
            text
        })
    });
    let t0 = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if t0.elapsed() > limits.timeout => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            Err(_) => break None,
        }
    };
    if let Some(h) = out_reader {
        let _ = h.join();
    }
    let stderr = err_reader.and_then(|h| h.join().ok()).unwrap_or_default();
    let stderr = String::from_utf8_lossy(&stderr).into_owned();
    let Some(status) = status else {
        return (Verdict::Failed(format!("hung: still running after {:.0} s", limits.timeout.as_secs_f64())), stderr);
    };
    let verdict = judge(status, &stderr);
    if let Verdict::Fine(_) = verdict {
        for (p, old) in case.inputs.iter().zip(before) {
            if std::fs::read(p).ok() != old {
                return (Verdict::Failed(format!("the input {} was changed", p.display())), stderr);
            }
        }
    }
    (verdict, stderr)
}

fn judge(status: std::process::ExitStatus, stderr: &str) -> Verdict {
    if stderr.contains("panicked at") {
        return Verdict::Failed("panicked".into());
    }
    if stderr.contains("memory allocation of") {
        return Verdict::Failed("an allocation failed (a size taken on trust?)".into());
    }
    if let Some(sig) = status.signal() {
        return Verdict::Failed(format!("killed by signal {sig}"));
    }
    match status.code() {
        Some(c @ (0 | 2 | 3)) => Verdict::Fine(c),
        Some(70) => Verdict::Failed("exit code 70: a bug by towpath's own account".into()),
        Some(101) => Verdict::Failed("exit code 101: a panic".into()),
        Some(c) => Verdict::Failed(format!("exit code {c}, which towpath does not use")),
        None => Verdict::Failed("no exit code".into()),
    }
}
