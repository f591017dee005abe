//! `towpath convert FILE --to json`: writes any problem towpath reads (TSPLIB TSP/ATSP/SOP,
//! GTSP-LIB, PCGLNS, towpath JSON) as towpath's JSON problem format, so that other programs
//! (the peers of the benchmarks, a user's scripts) read exactly the problem towpath solves.

use std::path::PathBuf;

use towpath_formats::{read_instance, write_json, CostsAs};

use crate::files::Files;
use crate::{exit, outln};

/// Output formats of `towpath convert`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// towpath's JSON problem format (docs/json-format.md).
    Json,
}

/// Arguments of `towpath convert`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  towpath convert kroA100.tsp --to json -o kroA100.json           # points with their metric
  towpath convert kroA100.tsp --to json --matrix -o kroA100.json  # every distance, as a matrix
  towpath convert ESC47.sop > ESC47.json

Task ids are the file's node numbers (\"1\", \"2\", ...) for TSP/ATSP/SOP and \"set1\", \"set2\", ...
for GTSP/PCGLNS, whose modes are the set's nodes (a mode's entry state is its node number
minus one). Forbidden moves (SOP's -1 entries) are null in the matrix; precedence, pinned
first/last tasks and the route's end are written out, so every route has the same cost and
feasibility in the JSON file as in the original.")]
pub struct Args {
    /// The problem file.
    pub file: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Target::Json)]
    pub to: Target,
    /// Write every transition cost as an explicit matrix, even for a coordinate file (n² numbers:
    /// large for big instances).
    #[arg(long)]
    pub matrix: bool,
    /// Output file (default: standard output). It may not be the input file.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Runs `towpath convert`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut files = Files::new();
    files.input("input", &args.file)?;
    if let Some(out) = &args.output {
        files.output("output", out)?;
    }
    let instance = read_instance(&args.file).map_err(exit::bad_input)?;
    let costs = if args.matrix { CostsAs::Matrix } else { CostsAs::Native };
    let text = match args.to {
        Target::Json => write_json(
            &instance
                .to_json(costs)
                .map_err(|e| exit::bad_input(anyhow::anyhow!("{}: --matrix: {e}", args.file.display())))?,
        ),
    };
    match &args.output {
        Some(out) => {
            files.write(out, text + "\n")?;
            files.commit()
        }
        None => {
            outln!("{text}");
            Ok(())
        }
    }
}
