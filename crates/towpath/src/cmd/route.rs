//! `towpath route`: the open rural postman job of Tewolde & Sheng (2008). Reads a travel graph with required
//! edges (JSON), orders and orients the required edges so that the connecting travel along
//! shortest paths is least, and writes the full vertex walk.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{anyhow, Context};
use towpath_baselines::{solve_with, SolverName};
use towpath_coverage::{
    read_instance, tewolde_sheng_like, verify_route, write_instance, BuildError, Instance, RouteJson, RppModel,
};
use towpath_seq::{Clock, SolveOptions};

use crate::cmd::solver_args::{refused, SolverArgs};
use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath route`.
#[derive(clap::Args, Debug)]
#[command(after_long_help = "Integrates separate tool paths into one open route (the open rural postman \
problem of Tewolde & Sheng 2008). The input is a travel graph in JSON: vertices with coordinates, undirected edges with lengths, \
some edges marked \"required\" (each a tool path to be done once, in either direction). The tool travels \
between required edges along shortest paths. The output is the full vertex walk, including connecting paths.

Input format (towpath-rpp/1):
  {\"vertices\": [[x, y], ...], \"edges\": [{\"a\": 0, \"b\": 1, \"required\": true, \"length\": 1.5}, ...],
   \"start\": 0}
(length defaults to the straight-line distance; start is optional.)")]
pub struct Args {
    /// The travel graph (JSON). Omit with --generate.
    #[arg(value_name = "GRAPH.json", required_unless_present = "generate")]
    pub graph: Option<PathBuf>,
    /// Instead of reading a file, generate an instance shaped like Tewolde & Sheng's (2008) sample data with
    /// this many required edges (and twice as many vertices).
    #[arg(long, value_name = "R", conflicts_with = "graph")]
    pub generate: Option<usize>,
    /// Seed of the generated instance.
    #[arg(long, default_value_t = 1, requires = "generate")]
    pub generate_seed: u64,
    /// Write the instance (read or generated) to this JSON file.
    #[arg(long, value_name = "FILE")]
    pub save_instance: Option<PathBuf>,
    /// Time limit of the whole command, in seconds: reading or generating the graph, its shortest
    /// paths and the solver (the seed papers' solvers run their own budgets and stop early only if
    /// this passes). Shortest paths that cannot be done in time are refused with what they need.
    #[arg(long, default_value_t = 10.0)]
    pub time_limit: f64,
    /// Seed for the solver's random choices (same seed, same answer under a work budget).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Threads of the shortest paths and the solver (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write the route (JSON) to this file.
    #[arg(short, long, value_name = "ROUTE.json")]
    pub output: Option<PathBuf>,
    /// Print one JSON object (the route) instead of a summary.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub solver: SolverArgs,
}

/// Runs `towpath route`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let clock = Clock::start(Some(super::solver_args::time_limit(args.time_limit)?), None);
    let threads = super::solver_args::threads(args.threads)?;
    let mut files = Files::new();
    if let Some(g) = &args.graph {
        files.input("graph", g)?;
    }
    if let Some(path) = &args.output {
        files.output("route", path)?;
    }
    if let Some(path) = &args.save_instance {
        files.output("saved instance", path)?;
    }
    let instance = load(&args)?;
    if let Some(path) = &args.save_instance {
        files.write(path, write_instance(&instance))?;
    }
    let model = RppModel::build(instance, &clock, threads).map_err(|e| {
        let hint = match &e {
            BuildError::OutOfTime(stop) if !stop.cancelled => {
                format!("; give --time-limit {:.0} or more", (stop.estimate * 1.5 + 1.0).ceil())
            }
            _ => String::new(),
        };
        exit::bad_input(anyhow!("{}: {e}{hint}", source(&args)))
    })?;
    // The solver has what is left of the time limit.
    let mut opts = SolveOptions { time_limit: clock.remaining(), seed: args.seed, threads, ..SolveOptions::default() };
    let name = args.solver.solver;
    // A progress bar on stderr for the time-limited searches, only on a terminal.
    let bar =
        (std::io::stderr().is_terminal() && matches!(name, SolverName::Towpath | SolverName::Castelino)).then(|| {
            let bar = indicatif::ProgressBar::new(1000);
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {wide_bar} {elapsed_precise} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            bar
        });
    if let Some(bar) = &bar {
        let bar = bar.clone();
        opts.progress = Some(Arc::new(move |p: &towpath_seq::Progress| {
            bar.set_position((p.fraction * 1000.0) as u64);
            bar.set_message(format!("best {:.3}", p.best_cost));
        }));
    }
    let report = solve_with(name, model.problem(), &opts, &args.solver.params()).map_err(|e| refused(name, e))?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let route = model.route(&report.solution.steps).map_err(exit::check_failed)?;
    let length = verify_route(model.instance(), &route).map_err(exit::check_failed)?;
    let out = RouteJson::new(model.instance(), &route, name.as_str(), report.elapsed.as_secs_f64());
    if let Some(path) = &args.output {
        let text = serde_json::to_string_pretty(&out)?;
        files.write(path, text + "\n")?;
    }
    files.commit()?;
    if args.json {
        outln!("{}", serde_json::to_string(&out)?);
    } else {
        let i = model.instance();
        outln!("towpath route: {}", i.name().unwrap_or("(unnamed)"));
        outln!(
            "  graph              : {} vertices, {} edges, {} required",
            i.vertices().len(),
            i.edges().len(),
            i.required().len()
        );
        outln!("  solver             : {name} — {}", name.reference());
        outln!("  path length        : {length:>12.3}");
        outln!("  required edges     : {:>12.3}", out.required_length);
        outln!("  connecting travel  : {:>12.3}", out.deadhead_length);
        outln!("  vertices on walk   : {:>12}", route.vertices.len());
        outln!("  solver time        : {:>12.3} s", report.elapsed.as_secs_f64());
        outln!("  total time         : {:>12.3} s", clock.elapsed().as_secs_f64());
        outln!(
            "  verified           : yes (independent check: the walk follows the graph's edges, serves every \
             required edge once and is {length:.3} long)"
        );
        if let Some(path) = &args.output {
            outln!("  route written to   : {}", path.display());
        }
    }
    Ok(())
}

/// Names the graph in messages: its file, or the generated instance.
fn source(args: &Args) -> String {
    match (&args.graph, args.generate) {
        (Some(path), _) => path.display().to_string(),
        (None, Some(r)) => format!("--generate {r}"),
        (None, None) => "the graph".into(),
    }
}

fn load(args: &Args) -> anyhow::Result<Instance> {
    if let Some(r) = args.generate {
        return tewolde_sheng_like(r, args.generate_seed).map_err(|e| exit::bad_input(anyhow!("--generate {r}: {e}")));
    }
    let Some(path) = &args.graph else {
        return Err(exit::bad_input(anyhow!("give a GRAPH.json file or --generate R")));
    };
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading {}", path.display()))
        .map_err(exit::bad_input)?;
    read_instance(&text).map_err(|e| exit::bad_input(anyhow!("{}: {e}", path.display())))
}
