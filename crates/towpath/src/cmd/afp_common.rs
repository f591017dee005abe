//! Arguments and loading shared by the AFP subcommands (`optimize`, `verify`, `demo`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use towpath_machine::Machine;
use towpath_nc::{Dialect, Width};

use crate::exit;

/// Machine, dialect and course width options.
#[derive(clap::Args, Debug, Clone)]
pub struct MachineArgs {
    /// Machine file (TOML): axes, kinds, weights, limits, optional DH chain. See docs/machine.md.
    #[arg(long, value_name = "MACHINE.toml")]
    pub machine: PathBuf,
    /// Program dialect (TOML); without it the reference dialect (ISO G-code, M20/M21 contact,
    /// `M60`/`M61 P<mask>` tows, (PLY n) and (COURSE n) comments). See docs/dialect.md.
    #[arg(long, value_name = "DIALECT.toml")]
    pub dialect: Option<PathBuf>,
    /// Tow width in mm: course width = tow width × tows on (read from the restart/cut masks).
    #[arg(long, value_name = "MM", conflicts_with = "course_width")]
    pub tow_width: Option<f64>,
    /// Fixed course width in mm.
    #[arg(long, value_name = "MM")]
    pub course_width: Option<f64>,
}

impl MachineArgs {
    /// Loads the machine and dialect files and checks the width.
    pub fn load(&self) -> anyhow::Result<(Machine, Dialect, Option<Width>)> {
        let machine = load_machine(&self.machine)?;
        let dialect = match &self.dialect {
            Some(p) => {
                let text = read(p)?;
                Dialect::from_toml_str(&text).map_err(|e| exit::bad_input(anyhow::anyhow!("{}: {e}", p.display())))?
            }
            None => Dialect::default(),
        };
        // The two files must fit each other (axis labels against the dialect's words, the
        // clearance axis): said here, naming both, rather than at the program's first line.
        if let Err(e) = towpath_nc::Interp::new(&dialect, &machine) {
            let files = match &self.dialect {
                Some(d) => format!("{} with {}", self.machine.display(), d.display()),
                None => format!("{} with the reference dialect", self.machine.display()),
            };
            return Err(exit::bad_input(anyhow::anyhow!("{files}: {e}")));
        }
        let width = match (self.tow_width, self.course_width) {
            (Some(w), _) => Some(Width::Tow(positive("--tow-width", w)?)),
            (_, Some(w)) => Some(Width::Course(positive("--course-width", w)?)),
            _ => None,
        };
        Ok((machine, dialect, width))
    }
}

fn positive(name: &str, w: f64) -> anyhow::Result<f64> {
    if w.is_finite() && w > 0.0 {
        Ok(w)
    } else {
        Err(exit::bad_input(anyhow::anyhow!("{name} {w}: a width must be a number > 0")))
    }
}

/// Reads a text file, naming it on failure (for text that is not UTF-8, the line and byte).
pub fn read(path: &Path) -> anyhow::Result<String> {
    let bytes =
        std::fs::read(path).with_context(|| format!("{}: cannot read", path.display())).map_err(exit::bad_input)?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        let column = at - bytes[..at].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1) + 1;
        exit::bad_input(anyhow::anyhow!(
            "{}: line {line}: byte {column} (0x{:02x}) is not UTF-8 text; towpath reads UTF-8 (ASCII) programs and \
             copies their lines byte for byte, so it does not guess another encoding",
            path.display(),
            bytes[at]
        ))
    })
}

/// Reads and validates a machine file.
pub fn load_machine(path: &Path) -> anyhow::Result<Machine> {
    let text = read(path)?;
    Machine::from_toml_str(&text).map_err(|e| exit::bad_input(anyhow::anyhow!("{}: {e}", path.display())))
}

/// Writes a file, creating its directory if need be, naming it on failure (a path that cannot
/// be written is refused like a bad argument: exit code 2).
pub fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the directory", dir.display()))
            .map_err(exit::bad_input)?;
    }
    std::fs::write(path, text).with_context(|| format!("{}: cannot write", path.display())).map_err(exit::bad_input)
}

/// Refuses outputs that would overwrite an input (or each other) before anything is written:
/// the same path, however spelt, a symbolic link to it, or a hard link.
pub fn guard_outputs(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    for (i, (what, out)) in outputs.iter().enumerate() {
        if let Some((input, _)) = inputs.iter().find(|(_, p)| same_file(p, out)) {
            return Err(exit::bad_input(anyhow::anyhow!(
                "{}: the {what} would overwrite the {input}; give another path",
                out.display()
            )));
        }
        if let Some((other, _)) = outputs[..i].iter().find(|(_, p)| same_file(p, out)) {
            return Err(exit::bad_input(anyhow::anyhow!(
                "{}: the {what} and the {other} would be the same file; give another path",
                out.display()
            )));
        }
    }
    Ok(())
}

/// True if two paths name the same file: the same inode when both exist, else the same
/// directory (symbolic links resolved) and file name.
fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
        #[cfg(not(unix))]
        {
            let _ = (x, y);
            return std::fs::canonicalize(a).ok() == std::fs::canonicalize(b).ok();
        }
    }
    let resolved = |p: &Path| -> Option<PathBuf> {
        let name = p.file_name()?;
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        Some(std::fs::canonicalize(dir).ok()?.join(name))
    };
    match (resolved(a), resolved(b)) {
        (Some(x), Some(y)) => x == y,
        _ => false,
    }
}
