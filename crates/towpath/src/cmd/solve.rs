//! `towpath solve FILE`: reads a problem (TSPLIB TSP/ATSP/SOP, GTSP-LIB, PCGLNS or towpath
//! JSON), solves it, checks the answer independently and prints it in the file's numbering.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use anyhow::anyhow;
use towpath_baselines::{solve_with, SolverName};
use towpath_formats::{read_instance, with_problem, Instance, Kind};
use towpath_seq::{End, Progress, SolveOptions, SolveReport};

use crate::cmd::solver_args::{refusal, SolverArgs};
use crate::{exit, outln};

/// Arguments of `towpath solve`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  towpath solve kroA100.tsp                      # 10 s on all cores
  towpath solve ESC07.sop --iterations 2000 --threads 1 --seed 3 --json
  towpath solve part.json --time-limit 60

The file kind is recognised from its content: a JSON object is towpath's JSON problem format
(docs/json-format.md); otherwise TSPLIB keywords, with TYPE TSP, ATSP, SOP, GTSP, AGTSP or
PCGLNS. The tour is printed in the file's numbering: 1-based nodes (TSP/ATSP from node 1, SOP
from node 1 to node n, GTSP/PCGLNS one node per set), or task ids with mode indices for JSON.
With --iterations and no --time-limit the answer depends only on the file, --seed and --threads.")]
pub struct Args {
    /// The problem file.
    pub file: PathBuf,
    /// Stop after this many seconds (default 10, unless --iterations is given).
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Work budget: improvement kicks summed over threads. Without --time-limit there is then
    /// no time limit.
    #[arg(long, value_name = "N")]
    pub iterations: Option<u64>,
    /// Seed for the solver's random choices.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: the machine's available cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print one JSON object on stdout instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// After the search, prove how far from optimal the answer can be: a Held–Karp lower
    /// bound (symmetric tours, and two-way tasks through their ends; up to 50,000 nodes),
    /// printed as "x % above a lower bound of b" (JSON: lower_bound). Takes O(n²) time on top
    /// of the time limit: about 1 s at 5,000 nodes, 13 s at 20,000.
    #[arg(long)]
    pub bound: bool,
    /// On plain symmetric tours, the first-level moves each Lin–Kernighan chain tries before
    /// giving up, 1 to 4 (default by the budget's kicks per node: 3 from 200, 2 from 40, else
    /// 1).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=4))]
    pub lk_breadth: Option<u8>,
    #[command(flatten)]
    pub solver: SolverArgs,
}

/// The default time limit when neither a time limit nor a work budget is given.
const DEFAULT_TIME_LIMIT: f64 = 10.0;

/// Runs `towpath solve`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let time_limit = match (args.time_limit, args.iterations) {
        (Some(t), _) => Some(super::solver_args::time_limit(t)?),
        (None, Some(_)) => None,
        (None, None) => Some(Duration::from_secs_f64(DEFAULT_TIME_LIMIT)),
    };
    let threads = super::solver_args::threads(args.threads)?;
    let instance = read_instance(&args.file).map_err(|e| match other_command(&args.file) {
        Some(hint) => exit::bad_input(anyhow!("{}: {hint}", args.file.display())),
        None => exit::bad_input(e),
    })?;

    // Only towpath's search (alone or inside castelino) reports progress.
    let reports_progress = matches!(args.solver.solver, SolverName::Towpath | SolverName::Castelino);
    let bar = progress_bar(reports_progress && (time_limit.is_some() || args.iterations.is_some()));
    let progress = bar.clone().map(|bar| {
        Arc::new(move |p: &Progress| {
            bar.set_position((p.fraction * 1000.0) as u64);
            bar.set_message(format!("best {}", p.best_cost));
        }) as towpath_seq::ProgressFn
    });
    let options = SolveOptions {
        time_limit,
        iterations: args.iterations,
        seed: args.seed,
        threads,
        progress,
        held_karp_bound: args.bound,
        lk_breadth: args.lk_breadth.map(usize::from),
        ..SolveOptions::default()
    };
    let name = args.solver.solver;
    let params = args.solver.params();
    let report: SolveReport = with_problem!(&instance.problem, p => solve_with(name, p, &options, &params))
        .map_err(|e| exit::bad_input(anyhow!("{}: {}", args.file.display(), refusal(name, &e))))?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let cost = instance.problem.check(&report.solution.steps).map_err(|v| {
        exit::check_failed(anyhow!("{}: the solver's answer does not verify: {v}", args.file.display()))
    })?;
    print_answer(&args, &instance, &report, cost, threads);
    Ok(())
}

/// For a file `solve` cannot read: the command it is meant for, if it is recognisably one of
/// the other commands' inputs (an AFP program, a travel graph, a mesh).
fn other_command(path: &Path) -> Option<String> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let bytes = std::fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(64 * 1024)]);
    let program = |text: &str| {
        let mut codes = 0;
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty()).take(50) {
            let word = line.trim_start_matches(|c: char| c == 'N' || c.is_ascii_digit()).trim_start();
            let first = word.chars().next().unwrap_or(' ').to_ascii_uppercase();
            if matches!(first, 'G' | 'M') && word[1..].starts_with(|c: char| c.is_ascii_digit()) {
                codes += 1;
            }
        }
        codes >= 2
    };
    if matches!(ext.as_str(), "nc" | "ngc" | "gcode" | "tap" | "cnc") || program(&text) {
        return Some(format!(
            "this is an AFP program (G-code), not a sequencing problem: re-sequence it with `towpath optimize {} \
             --machine MACHINE.toml`",
            path.display()
        ));
    }
    if text.contains("\"vertices\"") && text.contains("\"edges\"") {
        return Some(format!(
            "this is a travel graph with required edges (towpath-rpp/1), not a sequencing problem: route it with \
             `towpath route {}`",
            path.display()
        ));
    }
    if matches!(ext.as_str(), "stl" | "obj" | "ply") {
        return Some(format!(
            "this is a mesh, not a sequencing problem: lay fiber courses on it with `towpath layup {} …`",
            path.display()
        ));
    }
    None
}

/// A progress bar on stderr, only when stderr is a terminal.
fn progress_bar(bounded: bool) -> Option<indicatif::ProgressBar> {
    if !bounded || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(1000);
    if let Ok(style) = indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    Some(bar)
}

fn print_answer(args: &Args, instance: &Instance, report: &SolveReport, cost: f64, threads: usize) {
    let tour = instance.answer(&report.solution.steps);
    let closed = with_problem!(&instance.problem, p => p.end() == End::Closed);
    // The bound in the answer's units (the cost printed may leave out a fixed edge).
    let lower_bound = report.lower_bound.map(|b| b + (cost - report.solution.cost));
    if args.json {
        let mut json = serde_json::json!({
            "file": args.file.display().to_string(),
            "name": instance.name,
            "type": instance.kind.as_str(),
            "solver": args.solver.solver.as_str(),
            "dimension": instance.dimension,
            "tasks": instance.num_tasks(),
            "cost": cost,
            "route": if closed { "tour" } else { "path" },
            "tour": tour,
            "time_seconds": report.elapsed.as_secs_f64(),
            "iterations": report.iterations,
            "search_seconds": report.search_elapsed.as_secs_f64(),
            "exact": report.exact,
            "lower_bound": lower_bound,
            "seed": args.seed,
            "threads": threads,
        });
        if let (Some(f), Some(obj)) = (instance.fixed_edge, json.as_object_mut()) {
            obj.insert(
                "fixed_edge".into(),
                serde_json::json!({
                    "a": f.a,
                    "b": f.b,
                    "path_from": f.path_from(),
                    "path_to": f.path_to(),
                    "counted": false,
                }),
            );
        }
        outln!("{json}");
        return;
    }
    outln!(
        "{} ({}, dimension {}, {} tasks): cost {} in {:.2} s, {} iterations{} (solver {}, seed {}, {} threads); checked",
        instance.name,
        instance.kind,
        instance.dimension,
        instance.num_tasks(),
        cost,
        report.elapsed.as_secs_f64(),
        report.iterations,
        match (report.exact, lower_bound) {
            (true, _) => ", proven optimal".to_string(),
            // (a bound far below says nothing: the assignment relaxation ignores precedence)
            (false, Some(b)) if b > 0.0 && cost - b <= 0.5 * b => {
                let shown = if b.fract() == 0.0 { format!("{b}") } else { format!("{b:.2}") };
                format!(", {:.2} % above a lower bound of {shown}", 100.0 * (cost - b) / b)
            }
            _ => String::new(),
        },
        args.solver.solver,
        args.seed,
        threads
    );
    if let Some(f) = instance.fixed_edge {
        let (link, arc) = if instance.kind == Kind::Atsp { ("→", "arc") } else { ("–", "edge") };
        outln!(
            "route: a path from node {} to node {}, as TSPLIB's linhp318: the fixed {arc} {} {link} {} \
             (FIXED_EDGES_SECTION) closes it into the tour and is not counted in the cost",
            f.path_from(),
            f.path_to(),
            f.a,
            f.b
        );
    }
    const SHOWN: usize = 40;
    let text = tour.to_string();
    if tour.len() <= SHOWN {
        outln!("tour: {text}");
    } else {
        let head: Vec<&str> = text.split(' ').take(SHOWN).collect();
        outln!("tour: {} … ({} steps; --json prints all)", head.join(" "), tour.len());
    }
}
