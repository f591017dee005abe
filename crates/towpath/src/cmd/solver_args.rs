//! `--solver NAME` and the baselines' parameters, shared by every command that sequences
//! (flatten [`SolverArgs`] into a command's `Args`).

use towpath_baselines::{AcoParams, BaselineError, BaselineParams, DohertyParams, GaParams, SolverName};

use crate::exit;

/// Which solver sequences the tasks, and the parameters of the published solvers (docs/references.md).
#[derive(clap::Args, Debug, Clone)]
pub struct SolverArgs {
    /// The solver: towpath (towpath's own, the best), or one of the published algorithms
    /// towpath is built from, for comparison: doherty (Doherty et al. 2022 §3.2), castelino
    /// (Castelino et al. 2003, GTSP→TSP transformation), ga (Tewolde & Sheng 2008 §IV),
    /// aco1 / aco2 (Tewolde & Sheng 2008 §V, one or two ants per task; aco = aco2).
    #[arg(long, value_enum, default_value_t = SolverName::Towpath, help_heading = "Solver")]
    pub solver: SolverName,
    /// GA: generations (paper: 100 is enough for most sizes; Table I used 1000).
    #[arg(long, default_value_t = 100, help_heading = "Solver")]
    pub ga_generations: usize,
    /// GA: population size P_size (paper: 100; Table I used 200).
    #[arg(long, default_value_t = 100, help_heading = "Solver")]
    pub ga_population: usize,
    /// ACO: cycles (paper: 10).
    #[arg(long, default_value_t = 10, help_heading = "Solver")]
    pub aco_cycles: usize,
    /// Doherty: N, depth-first iterations without improvement before stopping.
    #[arg(long, default_value_t = 3, help_heading = "Solver")]
    pub doherty_n: usize,
    /// Doherty: maximum depth-first iterations per precedence set.
    #[arg(long, default_value_t = 25, help_heading = "Solver")]
    pub doherty_max_iterations: usize,
}

impl SolverArgs {
    /// The parameters of the baselines as set on the command line.
    pub fn params(&self) -> BaselineParams {
        BaselineParams {
            ga: GaParams { generations: self.ga_generations, population: self.ga_population, ..GaParams::default() },
            aco: AcoParams { cycles: self.aco_cycles, ..AcoParams::default() },
            doherty: DohertyParams {
                no_improvement: self.doherty_n,
                max_iterations: self.doherty_max_iterations,
                ..DohertyParams::default()
            },
            ..BaselineParams::default()
        }
    }
}

/// Why a solver could not sequence a valid input, naming the solver once; for the seed papers'
/// solvers the message points to towpath's, which takes every valid problem.
pub fn refusal(name: SolverName, e: &BaselineError) -> String {
    let text = e.to_string();
    let text = if text.starts_with(name.as_str()) { text } else { format!("solver {name}: {text}") };
    if let BaselineError::TooMuch { param, .. } = e {
        let flag = match *param {
            "ga.population" => "--ga-population",
            "ga.generations" => "--ga-generations",
            "aco.cycles" => "--aco-cycles",
            _ => return text,
        };
        return format!("{text} ({flag})");
    }
    if let BaselineError::Solve(towpath_seq::SolveError::TooManyThreads { .. }) = e {
        return format!("{text} (--threads)");
    }
    let hint = if name == SolverName::Towpath { "" } else { " (--solver towpath takes every valid problem)" };
    format!("{text}{hint}")
}

/// A `--threads` value: at least 1, at most what the solver runs (refused with exit code 2).
/// `None` gives the machine's available cores.
pub fn threads(threads: Option<usize>) -> anyhow::Result<usize> {
    let max = towpath_seq::MAX_THREADS;
    match threads {
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get()).min(max)),
        Some(0) => Err(exit::bad_input(anyhow::anyhow!("--threads 0: give at least 1"))),
        Some(t) if t > max => Err(exit::bad_input(anyhow::anyhow!("--threads {t}: the solver runs at most {max}"))),
        Some(t) => Ok(t),
    }
}

/// [`refusal`] as refused input (exit code 2).
pub fn refused(name: SolverName, e: BaselineError) -> anyhow::Error {
    exit::bad_input(anyhow::anyhow!("{}", refusal(name, &e)))
}

/// A `--time-limit` in seconds as a duration: refused (exit code 2) unless it is a number ≥ 0
/// small enough to be a duration (about 584 billion years).
pub fn time_limit(seconds: f64) -> anyhow::Result<std::time::Duration> {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(exit::bad_input(anyhow::anyhow!("--time-limit {seconds:?}: give a number of seconds ≥ 0")));
    }
    std::time::Duration::try_from_secs_f64(seconds)
        .map_err(|_| exit::bad_input(anyhow::anyhow!("--time-limit {seconds:?}: too large a number of seconds")))
}
