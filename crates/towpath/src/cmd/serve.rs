//! `towpath serve`: the local web application (machine set-up, programs, 3D view, solves with
//! live progress, layup, reports) on http://127.0.0.1:8437/ by default.

use std::path::PathBuf;

use anyhow::anyhow;
use towpath_server::Config;

use crate::{exit, outln};

/// Arguments of `towpath serve`.
#[derive(clap::Args, Debug)]
#[command(after_help = "The page is served from the binary itself; nothing is fetched from outside the machine.\n\
Everything uploaded, saved or produced is kept in the workspace folder, so a restart loses nothing.\n\n\
Examples:\n  towpath serve --open\n  towpath serve --port 9000 --workspace ~/towpath-work")]
pub struct Args {
    /// Port to listen on (0: any free port, printed at start).
    #[arg(long, default_value_t = 8437)]
    pub port: u16,
    /// Address to listen on. The default answers this machine only; give another address (e.g.
    /// 0.0.0.0) only on a network you trust: the app has no log-in.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Open the app in the default browser.
    #[arg(long)]
    pub open: bool,
    /// Folder for machine files, programs, meshes and results (created if missing).
    #[arg(long, value_name = "DIR", default_value = "towpath-workspace")]
    pub workspace: PathBuf,
    /// Largest upload, MiB.
    #[arg(long, value_name = "MIB", default_value_t = 64)]
    pub max_upload_mb: usize,
    /// Jobs (solves, layups) running at once; more wait in a queue.
    #[arg(long, value_name = "N", default_value_t = 2)]
    pub jobs: usize,
    /// Longest solver time limit a request may ask, seconds.
    #[arg(long, value_name = "S", default_value_t = 600.0)]
    pub max_time_limit: f64,
}

/// Runs `towpath serve`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.jobs == 0 {
        return Err(exit::bad_input(anyhow!("--jobs must be at least 1")));
    }
    if !(args.max_time_limit.is_finite() && args.max_time_limit > 0.0) {
        return Err(exit::bad_input(anyhow!("--max-time-limit must be a number of seconds > 0")));
    }
    let config = Config {
        host: args.host.clone(),
        port: args.port,
        workspace: args.workspace.clone(),
        max_upload: args.max_upload_mb.max(1) << 20,
        max_jobs: args.jobs,
        max_time_limit: args.max_time_limit,
        job_wall_limit: args.max_time_limit + 300.0,
        prewarm_panel: true,
        ..Config::default()
    };
    let open = args.open;
    towpath_server::serve_blocking(config, |addr, state| {
        let url = format!("http://{addr}/");
        outln!("towpath serve: {url}");
        outln!("  workspace {}", state.ws.root().display());
        for p in &state.read().load_problems {
            outln!("  not loaded: {p}");
        }
        outln!("  Ctrl-C stops the server");
        if open {
            open_browser(&url);
        }
    })
    .map_err(|e| exit::bad_input(anyhow!("cannot serve on {}:{}: {e}", args.host, args.port)))
}

fn open_browser(url: &str) {
    let cmd = if cfg!(target_os = "macos") {
        ("open", vec![url])
    } else if cfg!(windows) {
        ("cmd", vec!["/C", "start", "", url])
    } else {
        ("xdg-open", vec![url])
    };
    if std::process::Command::new(cmd.0).args(cmd.1).spawn().is_err() {
        outln!("  (could not open a browser: open {url} yourself)");
    }
}
