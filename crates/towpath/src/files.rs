//! The files a command reads and writes, under one rule for every command:
//!
//! - an output may not name an input or another output (paths compared after resolving links,
//!   hard links by device and inode); such a run is refused before any work is done;
//! - an output that is an existing directory, or whose folder cannot be made, is refused up front;
//! - every output is written to a temporary file in its own folder and renamed over its path only
//!   when the whole run succeeded ([`Files::commit`]); a run that fails, or is interrupted by an
//!   error, leaves every existing file as it was and removes its temporary files and the folders
//!   it made;
//! - a replaced file keeps its permissions.
//!
//! Commands declare their inputs and outputs first ([`Files::input`], [`Files::output`]), stage
//! what they write ([`Files::write`]) and commit at the end.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};

use crate::exit;

/// The inputs and outputs of one run, and the outputs staged so far.
#[derive(Default)]
pub struct Files {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<(String, PathBuf)>,
    staged: Vec<Staged>,
    made_dirs: Vec<PathBuf>,
}

/// An output written to its temporary file, waiting for the commit.
struct Staged {
    temp: PathBuf,
    path: PathBuf,
}

impl Files {
    /// No files yet.
    pub fn new() -> Self {
        Files::default()
    }

    /// Declares an input (`what` names it in messages: "program", "machine file"). Refused when
    /// a declared output names the same file.
    pub fn input(&mut self, what: &str, path: &Path) -> anyhow::Result<()> {
        if let Some((out, p)) = self.outputs.iter().find(|(_, p)| same_file(p, path)) {
            return Err(exit::bad_input(anyhow!(
                "{}: the {out} would overwrite the {what}; give another path",
                p.display()
            )));
        }
        self.inputs.push((what.to_string(), path.to_path_buf()));
        Ok(())
    }

    /// Declares an output. Refused (exit code 2) when it names a declared input or output, is an
    /// existing directory, or has no file name.
    pub fn output(&mut self, what: &str, path: &Path) -> anyhow::Result<()> {
        if path.file_name().is_none() || path.as_os_str().is_empty() {
            return Err(exit::bad_input(anyhow!("{}: the {what} needs a file name", path.display())));
        }
        if path.is_dir() {
            return Err(exit::bad_input(anyhow!(
                "{}: the {what} is a directory; give a file name inside it",
                path.display()
            )));
        }
        if let Some((input, _)) = self.inputs.iter().find(|(_, p)| same_file(p, path)) {
            return Err(exit::bad_input(anyhow!(
                "{}: the {what} would overwrite the {input}; give another path",
                path.display()
            )));
        }
        if let Some((other, _)) = self.outputs.iter().find(|(_, p)| same_file(p, path)) {
            return Err(exit::bad_input(anyhow!(
                "{}: the {what} and the {other} would be the same file; give another path",
                path.display()
            )));
        }
        if let Some(dir) = folder(path).filter(|d| d.exists() && !d.is_dir()) {
            return Err(exit::bad_input(anyhow!(
                "{}: cannot write the {what}: {} is not a directory",
                path.display(),
                dir.display()
            )));
        }
        self.outputs.push((what.to_string(), path.to_path_buf()));
        Ok(())
    }

    /// True if `path` was declared as an output.
    pub fn is_output(&self, path: &Path) -> bool {
        self.outputs.iter().any(|(_, p)| p == path)
    }

    /// Stages the contents of a declared output: written to a temporary file beside it (its
    /// folder made if need be), renamed over it by [`Files::commit`].
    pub fn write(&mut self, path: &Path, contents: impl AsRef<[u8]>) -> anyhow::Result<()> {
        if !self.is_output(path) {
            anyhow::bail!("internal: {} was written without being declared as an output", path.display());
        }
        let dir = folder(path).unwrap_or_else(|| PathBuf::from("."));
        self.make_dir(&dir)?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temp = dir.join(format!(".{name}.towpath-{}.tmp", std::process::id()));
        std::fs::write(&temp, contents.as_ref())
            .with_context(|| format!("{}: cannot write", path.display()))
            .map_err(exit::bad_input)?;
        // The temporary file is ours from here on, whatever happens next.
        self.staged.retain(|s| s.path != path);
        self.staged.push(Staged { temp, path: path.to_path_buf() });
        Ok(())
    }

    /// Renames every staged output over its path, in the order they were staged.
    pub fn commit(mut self) -> anyhow::Result<()> {
        let staged = std::mem::take(&mut self.staged);
        let mut rest = staged.into_iter();
        while let Some(s) = rest.next() {
            if let Ok(meta) = std::fs::metadata(&s.path) {
                // A replaced file keeps its permissions (best effort).
                let _ = std::fs::set_permissions(&s.temp, meta.permissions());
            }
            if let Err(e) = std::fs::rename(&s.temp, &s.path) {
                let _ = std::fs::remove_file(&s.temp);
                for r in rest {
                    let _ = std::fs::remove_file(&r.temp);
                }
                return Err(exit::bad_input(anyhow!("{}: cannot write: {e}", s.path.display())));
            }
        }
        self.made_dirs.clear();
        Ok(())
    }

    fn make_dir(&mut self, dir: &Path) -> anyhow::Result<()> {
        if dir.as_os_str().is_empty() || dir.is_dir() {
            return Ok(());
        }
        // Remember the folders made, outermost first, to remove them if the run fails.
        let mut missing = Vec::new();
        let mut d = Some(dir);
        while let Some(x) = d.filter(|x| !x.as_os_str().is_empty() && !x.exists()) {
            missing.push(x.to_path_buf());
            d = x.parent();
        }
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the directory", dir.display()))
            .map_err(exit::bad_input)?;
        self.made_dirs.extend(missing.into_iter().rev());
        Ok(())
    }
}

impl Drop for Files {
    /// A run that did not commit leaves no temporary file and no folder it made.
    fn drop(&mut self) {
        for s in &self.staged {
            let _ = std::fs::remove_file(&s.temp);
        }
        for d in self.made_dirs.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// The folder of a path, if it names one.
fn folder(path: &Path) -> Option<PathBuf> {
    path.parent().filter(|d| !d.as_os_str().is_empty()).map(Path::to_path_buf)
}

/// True if two paths name the same file: the same device and inode when both exist, else the
/// same folder (links resolved) and file name.
pub fn same_file(a: &Path, b: &Path) -> bool {
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
        // A dangling symbolic link names the file it points to.
        let p = match std::fs::read_link(p) {
            Ok(target) if target.is_absolute() => target,
            Ok(target) => folder(p).unwrap_or_else(|| PathBuf::from(".")).join(target),
            Err(_) => p.to_path_buf(),
        };
        let name = p.file_name()?.to_owned();
        let dir = folder(&p).unwrap_or_else(|| PathBuf::from("."));
        Some(std::fs::canonicalize(dir).ok()?.join(name))
    };
    match (resolved(a), resolved(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

/// The files `towpath demo` wrote into a folder, kept in the folder (`.towpath-demo`), so a second
/// run may replace them but never a file of the user's own without `--force`.
pub struct DemoManifest {
    path: PathBuf,
    names: Vec<String>,
}

impl DemoManifest {
    /// File name of the manifest inside the demo folder.
    pub const NAME: &'static str = ".towpath-demo";

    /// Reads the manifest of `dir` (empty when there is none).
    pub fn read(dir: &Path) -> Self {
        let path = dir.join(Self::NAME);
        let names = std::fs::read_to_string(&path)
            .map(|t| t.lines().filter(|l| !l.is_empty() && !l.starts_with('#')).map(str::to_string).collect())
            .unwrap_or_default();
        DemoManifest { path, names }
    }

    /// Refuses (exit code 2) when any of `names` exists in `dir` but was not written by the demo,
    /// unless `force`.
    pub fn check(&self, dir: &Path, names: &[String], force: bool) -> anyhow::Result<()> {
        if force {
            return Ok(());
        }
        let foreign: Vec<&String> = names.iter().filter(|n| dir.join(n).exists() && !self.names.contains(n)).collect();
        if foreign.is_empty() {
            return Ok(());
        }
        let list: Vec<&str> = foreign.iter().take(5).map(|s| s.as_str()).collect();
        Err(exit::bad_input(anyhow!(
            "{}: {} file(s) the demo would write already exist and were not written by it ({}{}); \
             give another --dir, or --force to replace them",
            dir.display(),
            foreign.len(),
            list.join(", "),
            if foreign.len() > list.len() { ", …" } else { "" }
        )))
    }

    /// The manifest's path and its text after a run that wrote `names`.
    pub fn updated(&self, names: &[String]) -> (PathBuf, String) {
        let mut all = self.names.clone();
        for n in names {
            if !all.contains(n) {
                all.push(n.clone());
            }
        }
        let mut text = String::from("# files written by `towpath demo`; a later run may replace them\n");
        for n in &all {
            text.push_str(n);
            text.push('\n');
        }
        (self.path.clone(), text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("towpath-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn outputs_may_not_name_inputs_or_each_other() {
        let d = temp("names");
        let input = d.join("in.txt");
        std::fs::write(&input, "x").unwrap();
        std::fs::hard_link(&input, d.join("hard.txt")).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(&input, d.join("soft.txt")).unwrap();
        let mut f = Files::new();
        f.input("program", &input).unwrap();
        assert!(f.output("output", &d.join("hard.txt")).is_err());
        #[cfg(unix)]
        assert!(f.output("output", &d.join("soft.txt")).is_err());
        assert!(f.output("output", &d.join(".").join("in.txt")).is_err());
        f.output("output", &d.join("out.txt")).unwrap();
        assert!(f.output("report", &d.join("out.txt")).is_err());
        assert!(f.output("report", &d).is_err(), "a directory is refused");
        assert!(f.input("mesh", &d.join("out.txt")).is_err(), "an input declared after its output");
    }

    #[test]
    fn nothing_is_written_without_a_commit() {
        let d = temp("commit");
        let out = d.join("sub/deeper/out.txt");
        let keep = d.join("keep.txt");
        std::fs::write(&keep, "old").unwrap();
        {
            let mut f = Files::new();
            f.output("output", &out).unwrap();
            f.output("report", &keep).unwrap();
            f.write(&out, "new").unwrap();
            f.write(&keep, "new").unwrap();
            // dropped: the run failed
        }
        assert_eq!(std::fs::read_to_string(&keep).unwrap(), "old");
        assert!(!d.join("sub").exists(), "folders made by a failed run are removed");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "no temporary file left");
        let mut f = Files::new();
        f.output("output", &out).unwrap();
        f.output("report", &keep).unwrap();
        f.write(&out, "new").unwrap();
        f.write(&keep, "new").unwrap();
        f.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&keep).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
    }
}
