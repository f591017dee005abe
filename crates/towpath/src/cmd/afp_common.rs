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

/// Reads a text file, naming it on failure.
pub fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display())).map_err(exit::bad_input)
}

/// Reads and validates a machine file.
pub fn load_machine(path: &Path) -> anyhow::Result<Machine> {
    let text = read(path)?;
    Machine::from_toml_str(&text).map_err(|e| exit::bad_input(anyhow::anyhow!("{}: {e}", path.display())))
}

/// Writes a file, naming it on failure.
pub fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the directory", dir.display()))?;
    }
    std::fs::write(path, text).with_context(|| format!("{}: cannot write", path.display()))
}
