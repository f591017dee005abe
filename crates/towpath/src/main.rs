//! The `towpath` command-line tool. Each subcommand lives in its own module under `cmd/`; this
//! file only parses the command line and maps errors to exit codes.

use clap::{Parser, Subcommand};

mod cmd;
mod exit;

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
    /// Run the built-in demo: a generated part, sequenced and checked, with no files of your own.
    Demo(cmd::demo::Args),
    /// Solve a TSPLIB (TSP, ATSP, SOP), GTSP-LIB, PCGLNS or towpath JSON problem file.
    Solve(cmd::solve::Args),
    /// Write a problem file (TSPLIB, GTSP-LIB, PCGLNS, JSON) as towpath JSON, optionally with an explicit matrix.
    Convert(cmd::convert::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(args) => cmd::demo::run(args),
        Command::Solve(args) => cmd::solve::run(args),
        Command::Convert(args) => cmd::convert::run(args),
    };
    std::process::exit(exit::report(result));
}
