//! The `towpath` command-line tool. Each subcommand lives in its own module under `cmd/`; this
//! file only parses the command line and maps errors to exit codes.

use clap::{Parser, Subcommand};

mod cmd;
mod exit;
mod files;
mod out;

/// towpath plans and sequences the tool paths of robotic and CNC manufacturing: automated fiber
/// placement first, then spray forming and machining.
#[derive(Parser, Debug)]
#[command(name = "towpath", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run the built-in demo: Doherty et al.'s (2022) AFP test parts written, optimized, verified and reported.
    Demo(cmd::demo::Args),
    /// Solve a TSPLIB (TSP, ATSP, SOP), GTSP-LIB, PCGLNS or towpath JSON problem file.
    Solve(cmd::solve::Args),
    /// Write a problem file (TSPLIB, GTSP-LIB, PCGLNS, JSON) as towpath JSON, optionally with an explicit matrix.
    Convert(cmd::convert::Args),
    /// Generate the fiber courses of a ply on a mold surface (mesh or analytic), trimmed per tow,
    /// with quality figures; write JSON, CSV and G-code.
    Layup(Box<cmd::layup::Args>),
    /// Re-sequence an AFP program: same part, laid identically, in less cycle time, verified.
    Optimize(cmd::optimize::Args),
    /// Check an optimized AFP program against its original and print the savings.
    Verify(cmd::verify::Args),
    /// Integrate separate tool paths into one open route over a travel graph (Tewolde & Sheng's (2008) open rural postman).
    Route(cmd::route::Args),
    /// Order cut contours and plotter strokes (SVG, DXF, G-code, JSON): least rapid travel, holes first.
    Order(Box<cmd::order::Args>),
    /// Plan 2.5D pocket machining: toolpath cells per tool linked with the least airtime (Castelino et al. 2003).
    Machine(cmd::machine::Args),
    /// Start the web application: machine set-up, programs in 3D, solves with live progress, layup.
    Serve(cmd::serve::Args),
    /// Plan spray forming or painting: flat patches, passes, one robot path and the predicted
    /// thickness (Tewolde & Sheng 2008).
    Spray(Box<cmd::spray::Args>),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(args) => cmd::demo::run(args),
        Command::Solve(args) => cmd::solve::run(args),
        Command::Convert(args) => cmd::convert::run(args),
        Command::Layup(args) => cmd::layup::run(*args),
        Command::Optimize(args) => cmd::optimize::run(args),
        Command::Verify(args) => cmd::verify::run(args),
        Command::Route(args) => cmd::route::run(args),
        Command::Order(args) => cmd::order::run(*args),
        Command::Machine(args) => cmd::machine::run(args),
        Command::Serve(args) => cmd::serve::run(args),
        Command::Spray(args) => cmd::spray::run(*args),
    };
    std::process::exit(exit::report(result));
}
