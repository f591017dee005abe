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
    /// Integrate separate tool paths into one open route over a travel graph (seed 004's open rural postman).
    Route(cmd::route::Args),
    /// Run a benchmark and print (or write into BENCHMARKS.md) its tables.
    Bench(cmd::bench::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(args) => cmd::demo::run(args),
        Command::Route(args) => cmd::route::run(args),
        Command::Bench(args) => cmd::bench::run(args),
    };
    std::process::exit(exit::report(result));
}
