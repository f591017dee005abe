//! `towpath optimize`: an AFP program in, the same part in less cycle time (or less off-part
//! motion) out, verified.

use std::path::PathBuf;
use std::time::Duration;

use towpath_machine::CostKind;
use towpath_nc::{optimize, AfpOptions, NcError, OptimizeOptions, PrecedenceRule, Report};

use super::afp_common::{hint, lines_with, read, warn, width_from, CellArgs, MachineArgs};
use super::solver_args::SolverArgs;
use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath optimize`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The qualified AFP program (CNC program with plies of courses).
    #[arg(value_name = "PROGRAM")]
    pub program: PathBuf,
    #[command(flatten)]
    pub machine: MachineArgs,
    #[command(flatten)]
    pub cell: CellArgs,
    /// Allow courses to be laid in reverse (heading turned 180°, tow restarts and cuts swapped).
    #[arg(long)]
    pub bidirectional: bool,
    /// What to minimize: cycle time (time; the default when every axis of the machine file has
    /// a max_velocity), Doherty et al.'s weighted axis distance (axis; the default otherwise),
    /// or the tool point's distance (tool). Whatever is chosen, a program with a longer cycle
    /// time than the input is never returned: the input order is kept instead.
    #[arg(long, value_name = "time|axis|tool")]
    pub cost: Option<CostKind>,
    /// Precedence: a course after the courses of earlier plies it overlaps (courses), Doherty et
    /// al.'s precedence sets (sets), or ply by ply (plies, needs no widths).
    #[arg(long, default_value = "courses", value_name = "courses|sets|plies")]
    pub precedence: PrecedenceRule,
    /// Keep the order of the courses within each ply.
    #[arg(long)]
    pub keep_ply_order: bool,
    /// Solver time limit in seconds (default: 1 s plus 0.2 ms per course, at most 10 s).
    #[arg(long, value_name = "S")]
    pub time_limit: Option<f64>,
    /// Work budget: improvement kicks summed over threads. Without --time-limit there is then no
    /// time limit, and the output depends only on the inputs, --seed and --threads.
    #[arg(long, value_name = "N")]
    pub iterations: Option<u64>,
    /// Solver seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Solver threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Where to write the optimized program.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Write a report: `.json` for data, `.html` for a page with a before/after plan view.
    #[arg(long, value_name = "REPORT.json|html")]
    pub report: Option<PathBuf>,
    /// Print the report as one JSON object on stdout instead of a summary.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub solver: SolverArgs,
}

/// Maps an optimization error to an exit code, naming the program file (and the machine file
/// where the error lies in it).
pub fn classify(file: &std::path::Path, machine: &std::path::Path, e: NcError) -> anyhow::Error {
    let hint = hint(&e, machine);
    match e {
        NcError::SelfCheck(_) | NcError::Unsafe(_) => exit::check_failed(anyhow::anyhow!("{}: {e}", file.display())),
        // Everything else, a solver that cannot take this program (`NcError::Solver`) included,
        // refuses the input.
        _ => exit::bad_input(anyhow::anyhow!("{}: {e}{hint}", file.display())),
    }
}

/// Runs `towpath optimize`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let given_limit = args.time_limit.map(super::solver_args::time_limit).transpose()?;
    let mut files = Files::new();
    args.machine.declare(&mut files)?;
    args.cell.declare(&mut files)?;
    files.input("program", &args.program)?;
    files.output("output", &args.output)?;
    if let Some(r) = &args.report {
        files.output("report", r)?;
    }
    let (machine, dialect, width) = args.machine.load()?;
    let safety = args.cell.load(&machine, &dialect)?;
    let text = read(&args.program)?;
    let afp = AfpOptions {
        cost: args.cost.unwrap_or_else(|| towpath_nc::default_cost(&machine)),
        bidirectional: args.bidirectional,
        precedence: args.precedence,
        keep_ply_order: args.keep_ply_order,
        width,
    };
    // The course count decides the default time limit; count roller contacts cheaply.
    let time_limit = match (given_limit, args.iterations) {
        (Some(t), _) => Some(t),
        (None, Some(_)) => None,
        (None, None) => Some({
            let courses = lines_with(&text, dialect.contact_on.as_str()).max(1);
            towpath_nc::auto_time_limit(if dialect.contact_on.is_empty() { 1000 } else { courses })
        }),
    };
    let bar = progress_bar(time_limit);
    let opts = OptimizeOptions {
        afp: afp.clone(),
        time_limit,
        iterations: args.iterations,
        seed: args.seed,
        threads: args.threads.unwrap_or_else(|| OptimizeOptions::default().threads),
        progress: bar.clone().map(|b| {
            let f: towpath_seq::ProgressFn = std::sync::Arc::new(move |p: &towpath_seq::Progress| {
                b.set_position((p.fraction * 1000.0) as u64);
                b.set_message(format!("best {:.1}", p.best_cost));
            });
            f
        }),
        solver: args.solver.solver,
        baselines: args.solver.params(),
        safety,
        cancel: None,
        stage: None,
    };
    let o = optimize(&text, &machine, &dialect, &opts).map_err(|e| classify(&args.program, &args.machine.machine, e));
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let o = o?;
    files.write(&args.output, &o.text)?;
    let name =
        args.program.file_name().map_or_else(|| args.program.display().to_string(), |n| n.to_string_lossy().into());
    let mut report = Report::new(&name, &machine, &o, &afp);
    report.width_from = width_from(&args.machine, &o.width, &args.machine.dialect_name());
    for w in &report.warnings {
        warn(w);
    }
    if let Some(path) = &args.report {
        let body = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"))
        {
            report.to_html(&o, &o.output, &machine)
        } else {
            serde_json::to_string_pretty(&report)?
        };
        files.write(path, &body)?;
    }
    files.commit()?;
    if args.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        crate::out!("{}", report.summary());
        outln!("  written to {}", args.output.display());
    }
    Ok(())
}

/// A progress bar on stderr, only when it is a terminal.
fn progress_bar(limit: Option<Duration>) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    let limit = limit?;
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let b = indicatif::ProgressBar::new(1000);
    let style = indicatif::ProgressStyle::with_template("sequencing {bar:30} {msg} ({elapsed} of ~{prefix})")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    b.set_style(style);
    b.set_prefix(format!("{:.0}s", limit.as_secs_f64()));
    Some(b)
}
