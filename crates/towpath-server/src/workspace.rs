//! The workspace folder: everything a user uploads or saves, and every job's results, kept on
//! disk so that a bad request or a restart loses nothing.
//!
//! Layout: `machines/NAME.toml`, `dialects/NAME.toml`, `programs/NAME` with
//! `programs/NAME.meta.json` (the machine and dialect it was read with), `meshes/NAME`,
//! `results/job-N/` (the job's request and status, its optimized program, reports or courses).
//! Files are written to a temporary name and renamed, so a crash never leaves half a file.

use std::path::{Path, PathBuf};

use crate::error::ApiError;
use crate::names;

/// The kinds of things kept, one folder each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Machine files (TOML).
    Machines,
    /// Dialect files (TOML).
    Dialects,
    /// Programs and their `.meta.json` side files.
    Programs,
    /// Meshes (STL, OBJ, PLY).
    Meshes,
    /// Job results, one folder per job.
    Results,
}

impl Kind {
    fn dir(self) -> &'static str {
        match self {
            Kind::Machines => "machines",
            Kind::Dialects => "dialects",
            Kind::Programs => "programs",
            Kind::Meshes => "meshes",
            Kind::Results => "results",
        }
    }
}

/// The workspace folder.
#[derive(Clone, Debug)]
pub struct Workspace {
    root: PathBuf,
}

impl Workspace {
    /// Opens (creating if needed) a workspace folder.
    pub fn open(root: &Path) -> std::io::Result<Workspace> {
        for k in [Kind::Machines, Kind::Dialects, Kind::Programs, Kind::Meshes, Kind::Results] {
            std::fs::create_dir_all(root.join(k.dir()))?;
        }
        let root = root.canonicalize()?;
        Ok(Workspace { root })
    }

    /// The folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The path of `name` in the folder of `kind`; the name is checked first.
    pub fn path(&self, kind: Kind, name: &str) -> Result<PathBuf, ApiError> {
        names::check("file", name)?;
        Ok(self.root.join(kind.dir()).join(name))
    }

    /// Writes a file atomically (temporary file beside it, then rename).
    pub fn write(&self, kind: Kind, name: &str, bytes: &[u8]) -> Result<(), ApiError> {
        let path = self.path(kind, name)?;
        write_atomic(&path, bytes)
    }

    /// Reads a file, `None` if it does not exist.
    pub fn read(&self, kind: Kind, name: &str) -> Result<Option<Vec<u8>>, ApiError> {
        let path = self.path(kind, name)?;
        match std::fs::read(&path) {
            Ok(b) => Ok(Some(b)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e.into()),
        }
    }

    /// Removes a file if it exists.
    pub fn remove(&self, kind: Kind, name: &str) -> Result<(), ApiError> {
        let path = self.path(kind, name)?;
        match std::fs::remove_file(path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e.into()),
            _ => Ok(()),
        }
    }

    /// The names in a folder that pass the name check, sorted.
    pub fn list(&self, kind: Kind) -> Vec<String> {
        let mut out: Vec<String> = std::fs::read_dir(self.root.join(kind.dir()))
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| e.file_name().into_string().ok())
            .filter(|n| names::check("file", n).is_ok())
            .collect();
        out.sort();
        out
    }

    /// A job's result folder (created).
    pub fn job_dir(&self, job: &str) -> Result<PathBuf, ApiError> {
        let p = self.path(Kind::Results, job)?;
        std::fs::create_dir_all(&p)?;
        Ok(p)
    }
}

/// Writes `bytes` to `path` by way of a temporary file in the same folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ApiError> {
    let dir = path.parent().ok_or_else(|| ApiError::Internal(format!("{}: no folder", path.display())))?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })?;
    Ok(())
}
