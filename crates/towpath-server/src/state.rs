//! What the server holds: the configuration, the workspace, the machines, dialects, programs
//! and meshes it knows (built-in and from the workspace), and the jobs.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock, RwLock};

use serde::{Deserialize, Serialize};

use crate::adapt::{machine as am, nc};
use crate::error::{ApiError, ApiResult};
use crate::jobs::Jobs;
use crate::workspace::{Kind, Workspace};

/// How the server runs.
#[derive(Clone, Debug)]
pub struct Config {
    /// Address to listen on (loopback by default).
    pub host: String,
    /// Port (0: any free port).
    pub port: u16,
    /// Workspace folder.
    pub workspace: PathBuf,
    /// Largest upload, bytes.
    pub max_upload: usize,
    /// Jobs running at once; the rest wait in a queue.
    pub max_jobs: usize,
    /// Jobs waiting at most; more are refused with 429.
    pub max_queue: usize,
    /// Longest solver time limit a request may ask, seconds.
    pub max_time_limit: f64,
    /// Wall time after which any job is stopped, seconds.
    pub job_wall_limit: f64,
    /// Build the large panel's geometry in the background at start.
    pub prewarm_panel: bool,
    /// Plies and courses per ply of the large panel.
    pub panel: (usize, usize),
}

impl Default for Config {
    fn default() -> Self {
        Config {
            host: "127.0.0.1".into(),
            port: 8437,
            workspace: PathBuf::from("towpath-workspace"),
            max_upload: 64 << 20,
            max_jobs: 2,
            max_queue: 8,
            max_time_limit: 600.0,
            job_wall_limit: 900.0,
            prewarm_panel: false,
            panel: (100, 100),
        }
    }
}

/// Where a program came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// A built-in demo part.
    Demo,
    /// The large generated panel.
    Panel,
    /// Uploaded by the user (kept in the workspace).
    Upload,
    /// Written by an optimize job.
    Result,
}

/// The side file of an uploaded or result program: how to read it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProgramMeta {
    /// Machine name.
    pub machine: String,
    /// Dialect name.
    pub dialect: String,
    /// Description.
    #[serde(default)]
    pub description: String,
    /// For a result: the original program's id.
    #[serde(default)]
    pub original: Option<String>,
    /// For a result: the new order as (original course, reversed).
    #[serde(default)]
    pub order: Option<Vec<(usize, bool)>>,
    /// For a result: the job.
    #[serde(default)]
    pub job: Option<String>,
    /// Tow width for precedence footprints when a request gives none, mm.
    #[serde(default)]
    pub tow_width: Option<f64>,
    /// The meshes of the program's cell (mesh names): a demo part's own, or those a result was
    /// optimized against. The solve panel starts with them chosen.
    #[serde(default)]
    pub cell: Vec<String>,
}

/// A program the server knows.
pub struct ProgramEntry {
    /// Its id (a workspace-safe name).
    pub id: String,
    /// Where it came from.
    pub source: Source,
    /// How to read it.
    pub meta: ProgramMeta,
    text: OnceLock<Arc<String>>,
    make: Option<fn((usize, usize)) -> String>,
    panel: (usize, usize),
    /// The geometry response, built on first request.
    pub geometry: OnceLock<Arc<Vec<u8>>>,
}

impl ProgramEntry {
    fn new(id: &str, source: Source, meta: ProgramMeta, text: String) -> ProgramEntry {
        let cell = OnceLock::new();
        let _ = cell.set(Arc::new(text));
        ProgramEntry { id: id.into(), source, meta, text: cell, make: None, panel: (0, 0), geometry: OnceLock::new() }
    }

    /// The program text (the large panel is generated on first use).
    pub fn text(&self) -> Arc<String> {
        self.text.get_or_init(|| Arc::new(self.make.map(|f| f(self.panel)).unwrap_or_default())).clone()
    }

    /// The listing entry.
    pub fn listing(&self) -> serde_json::Value {
        serde_json::json!({
            "id": self.id,
            "source": self.source,
            "machine": self.meta.machine,
            "dialect": self.meta.dialect,
            "description": self.meta.description,
            "original": self.meta.original,
            "job": self.meta.job,
            "tow_width": self.meta.tow_width,
            "cell": self.meta.cell,
        })
    }
}

/// A machine the server knows.
#[derive(Clone)]
pub struct MachineEntry {
    /// The machine.
    pub machine: am::MachineModel,
    /// Built in (cannot be deleted; saving under its name is refused).
    pub builtin: bool,
}

/// A dialect the server knows.
#[derive(Clone)]
pub struct DialectEntry {
    /// The dialect.
    pub dialect: am::DialectModel,
    /// Its TOML.
    pub text: String,
    /// Built in.
    pub builtin: bool,
}

/// Machines, dialects, programs and meshes.
#[derive(Default)]
pub struct Store {
    /// By name.
    pub machines: BTreeMap<String, MachineEntry>,
    /// By name.
    pub dialects: BTreeMap<String, DialectEntry>,
    /// By id.
    pub programs: BTreeMap<String, Arc<ProgramEntry>>,
    /// Mesh names in the workspace.
    pub meshes: Vec<String>,
    /// Built-in meshes (the demo parts' cells) by name: their file bytes.
    pub builtin_meshes: BTreeMap<String, Arc<Vec<u8>>>,
    /// What could not be loaded from the workspace at start, and why.
    pub load_problems: Vec<String>,
}

/// The server's state, shared by every handler.
pub struct AppState {
    /// Configuration.
    pub config: Config,
    /// The workspace folder.
    pub ws: Workspace,
    /// What the server knows.
    pub store: RwLock<Store>,
    /// Background jobs.
    pub jobs: Jobs,
}

/// Id of the large panel.
pub const PANEL_ID: &str = "panel-10000-courses";

fn make_panel(size: (usize, usize)) -> String {
    nc::panel(size.0, size.1).0
}

impl AppState {
    /// Opens the workspace and loads the built-in parts and everything saved there.
    pub fn new(config: Config) -> std::io::Result<Arc<AppState>> {
        let ws = Workspace::open(&config.workspace)?;
        let mut store = Store::default();
        for m in am::builtin_machines() {
            store.machines.insert(m.name.clone(), MachineEntry { machine: m, builtin: true });
        }
        store.dialects.insert(
            am::REFERENCE_DIALECT.into(),
            DialectEntry { dialect: am::DialectModel::default(), text: am::reference_dialect_toml(), builtin: true },
        );
        for d in nc::demo_parts() {
            let id = format!("demo-{}", d.name);
            let cell: Vec<String> = d.cell.iter().map(|(name, _)| name.clone()).collect();
            for (name, bytes) in d.cell {
                store.builtin_meshes.insert(name, Arc::new(bytes));
            }
            let meta = ProgramMeta {
                machine: d.machine.name.clone(),
                dialect: am::REFERENCE_DIALECT.into(),
                description: d.description,
                original: None,
                order: None,
                job: None,
                tow_width: Some(nc::DEMO_TOW_WIDTH),
                cell,
            };
            store.programs.insert(id.clone(), Arc::new(ProgramEntry::new(&id, Source::Demo, meta, d.program)));
        }
        let panel = ProgramEntry {
            id: PANEL_ID.into(),
            source: Source::Panel,
            meta: ProgramMeta {
                machine: nc::panel(0, 0).1.name,
                dialect: am::REFERENCE_DIALECT.into(),
                description: format!(
                    "large stacked panel: {} plies of about {} courses (0°, ±45°, 90°)",
                    config.panel.0, config.panel.1
                ),
                original: None,
                order: None,
                job: None,
                tow_width: Some(nc::DEMO_TOW_WIDTH),
                cell: Vec::new(),
            },
            text: OnceLock::new(),
            make: Some(make_panel),
            panel: config.panel,
            geometry: OnceLock::new(),
        };
        store.programs.insert(PANEL_ID.into(), Arc::new(panel));
        load_workspace(&ws, &mut store);
        let jobs = Jobs::new(&config);
        let state = Arc::new(AppState { config, ws, store: RwLock::new(store), jobs });
        state.jobs.restore(&state);
        Ok(state)
    }

    /// Reads the store.
    pub fn read(&self) -> std::sync::RwLockReadGuard<'_, Store> {
        self.store.read().unwrap_or_else(|e| e.into_inner())
    }

    /// Writes the store.
    pub fn write(&self) -> std::sync::RwLockWriteGuard<'_, Store> {
        self.store.write().unwrap_or_else(|e| e.into_inner())
    }

    /// A program by id.
    pub fn program(&self, id: &str) -> ApiResult<Arc<ProgramEntry>> {
        crate::names::check("program", id)?;
        self.read().programs.get(id).cloned().ok_or_else(|| ApiError::NotFound(format!("no program {id:?}")))
    }

    /// A machine by name.
    pub fn machine(&self, name: &str) -> ApiResult<am::MachineModel> {
        crate::names::check("machine", name)?;
        self.read()
            .machines
            .get(name)
            .map(|m| m.machine.clone())
            .ok_or_else(|| ApiError::bad(format!("no machine {name:?}: upload or save it first")))
    }

    /// A dialect by name.
    pub fn dialect(&self, name: &str) -> ApiResult<am::DialectModel> {
        crate::names::check("dialect", name)?;
        self.read()
            .dialects
            .get(name)
            .map(|d| d.dialect.clone())
            .ok_or_else(|| ApiError::bad(format!("no dialect {name:?}: upload it first")))
    }

    /// Every mesh name: built-in first, then the workspace's.
    pub fn mesh_names(&self) -> Vec<String> {
        let st = self.read();
        st.builtin_meshes.keys().cloned().chain(st.meshes.iter().cloned()).collect()
    }

    /// A mesh's file bytes by name: a built-in one, else the workspace's.
    pub fn mesh_bytes(&self, name: &str) -> ApiResult<Arc<Vec<u8>>> {
        crate::names::check("mesh", name)?;
        if let Some(b) = self.read().builtin_meshes.get(name) {
            return Ok(b.clone());
        }
        self.ws
            .read(Kind::Meshes, name)?
            .map(Arc::new)
            .ok_or_else(|| ApiError::bad(format!("no mesh {name:?}: upload it first")))
    }

    /// Registers a program written by a job (and saved in the workspace by the caller).
    pub fn add_program(&self, id: &str, source: Source, meta: ProgramMeta, text: String) {
        self.write().programs.insert(id.into(), Arc::new(ProgramEntry::new(id, source, meta, text)));
    }
}

fn strip(name: &str, ext: &str) -> Option<String> {
    name.strip_suffix(ext).map(str::to_string)
}

/// Loads machines, dialects, programs and meshes saved in the workspace. A file that no longer
/// reads is skipped and named in `load_problems` (it stays on disk).
fn load_workspace(ws: &Workspace, store: &mut Store) {
    for f in ws.list(Kind::Machines) {
        let Some(name) = strip(&f, ".toml") else { continue };
        let text = ws.read(Kind::Machines, &f).ok().flatten().unwrap_or_default();
        match am::parse_machine(&f, &String::from_utf8_lossy(&text)) {
            Ok(m) if !store.machines.get(&name).is_some_and(|e| e.builtin) => {
                store.machines.insert(name, MachineEntry { machine: m, builtin: false });
            }
            Ok(_) => {}
            Err(e) => store.load_problems.push(format!("machines/{f}: {e}")),
        }
    }
    for f in ws.list(Kind::Dialects) {
        let Some(name) = strip(&f, ".toml") else { continue };
        let text =
            String::from_utf8_lossy(&ws.read(Kind::Dialects, &f).ok().flatten().unwrap_or_default()).into_owned();
        match am::parse_dialect(&f, &text) {
            Ok(d) if name != am::REFERENCE_DIALECT => {
                store.dialects.insert(name, DialectEntry { dialect: d, text, builtin: false });
            }
            Ok(_) => {}
            Err(e) => store.load_problems.push(format!("dialects/{f}: {e}")),
        }
    }
    for f in ws.list(Kind::Programs) {
        if f.ends_with(".meta.json") {
            continue;
        }
        let meta_name = format!("{f}.meta.json");
        let meta: Option<ProgramMeta> =
            ws.read(Kind::Programs, &meta_name).ok().flatten().and_then(|b| serde_json::from_slice(&b).ok());
        let Some(meta) = meta else {
            store.load_problems.push(format!("programs/{f}: no readable {meta_name}"));
            continue;
        };
        let text =
            String::from_utf8_lossy(&ws.read(Kind::Programs, &f).ok().flatten().unwrap_or_default()).into_owned();
        let source = if meta.job.is_some() { Source::Result } else { Source::Upload };
        store.programs.insert(f.clone(), Arc::new(ProgramEntry::new(&f, source, meta, text)));
    }
    store.meshes = ws.list(Kind::Meshes);
}
