//! Arguments and loading shared by the AFP subcommands (`optimize`, `verify`, `demo`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use towpath_machine::Machine;
use towpath_nc::{Dialect, NcError, Width, WidthSource};

use crate::exit;
use crate::files::Files;

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
    /// Declares the machine and dialect files as inputs.
    pub fn declare(&self, files: &mut Files) -> anyhow::Result<()> {
        files.input("machine file", &self.machine)?;
        if let Some(d) = &self.dialect {
            files.input("dialect file", d)?;
        }
        Ok(())
    }

    /// The dialect file's name, or `the reference dialect`.
    pub fn dialect_name(&self) -> String {
        match &self.dialect {
            Some(d) => d.display().to_string(),
            None => "the reference dialect".into(),
        }
    }

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

/// What the user can do about a library error, in this command line's terms: the flag that
/// gives what is missing, or where the machine file sets what the error points at (the
/// mandrel's axis for a tool point on or near it), so the message names the file to fix as
/// well as the program. The libraries' messages name no flags.
pub fn hint(e: &NcError, machine: &Path) -> String {
    match e {
        NcError::NeedsWidth { .. } => {
            " (give --tow-width MM or --course-width MM, or tow_width / course_width in the dialect; or use \
             --precedence plies)"
                .into()
        }
        NcError::TowWidthWithoutTows { .. } => " (give --course-width MM)".into(),
        NcError::NoToolPoint => " (or use --precedence plies)".into(),
        NcError::DohertyKeepsNoPlyOrder => " (drop --keep-ply-order, or choose another --solver)".into(),
        NcError::MandrelAxis { axis, label, .. } => format!(
            " (they are `origin` and `direction` of axis {label}, the [[axis]] table number {} in {})",
            axis + 1,
            machine.display()
        ),
        _ => String::new(),
    }
}

/// Words for where a width came from, as the user gave it.
pub fn width_from(args: &MachineArgs, used: &towpath_nc::WidthUsed, dialect: &str) -> String {
    match used.source {
        WidthSource::Given if args.tow_width.is_some() => "the command line, --tow-width".into(),
        WidthSource::Given => "the command line, --course-width".into(),
        WidthSource::Dialect => format!("the dialect, {dialect}"),
        WidthSource::Default => "none given".into(),
    }
}

/// Prints a warning on stderr (a closed stderr is ignored).
pub fn warn(text: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "warning: {text}");
}

/// Counts lines holding `code`, whatever the line ends (LF, CRLF or CR).
pub fn lines_with(text: &str, code: &str) -> usize {
    text.split(['\n', '\r']).filter(|l| l.contains(code)).count()
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

/// The cell of a job, for motion safety (docs/motion.md).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct CellArgs {
    /// An obstacle mesh (STL, OBJ or PLY, mm, in the part frame: on a mandrel machine it turns
    /// with the mandrel): the mold tool, a fixture, a stringer; repeat for each. With it every
    /// move is checked against the cell and the machine's travel limits, and `optimize` plans
    /// each transit over the obstacles only as high as they require. The mold tool must be
    /// among them: every laid point must lie within 25 mm of the cell. See docs/motion.md.
    #[arg(long = "mold", value_name = "MESH")]
    pub molds: Vec<PathBuf>,
    /// Clearance in mm (default 5): a move closer than this to the cell is a near miss, and
    /// planned transits keep it. Needs --mold.
    #[arg(long, value_name = "MM", requires = "molds")]
    pub clearance: Option<f64>,
}

impl CellArgs {
    /// Declares the meshes as inputs.
    pub fn declare(&self, files: &mut Files) -> anyhow::Result<()> {
        for m in &self.molds {
            files.input("mold mesh", m)?;
        }
        Ok(())
    }

    /// Reads the meshes into a cell and sets up the checks, or `None` without `--mold`.
    pub fn load(&self, machine: &Machine, dialect: &Dialect) -> anyhow::Result<Option<towpath_nc::Safety>> {
        if self.molds.is_empty() {
            return Ok(None);
        }
        let mut meshes = Vec::with_capacity(self.molds.len());
        for path in &self.molds {
            let soup = towpath_geom::io::read_path(path)
                .map_err(|e| exit::bad_input(anyhow::anyhow!("{}: {e}", path.display())))?;
            meshes.push((path.display().to_string(), soup));
        }
        let opts = towpath_nc::SafetyOptions {
            clearance: self.clearance.unwrap_or(towpath_nc::DEFAULT_CLEARANCE),
            ..towpath_nc::SafetyOptions::default()
        };
        towpath_nc::Safety::from_meshes(machine, dialect, &meshes, opts)
            .map(Some)
            .map_err(|e| exit::bad_input(anyhow::anyhow!("--mold: {e}")))
    }
}
