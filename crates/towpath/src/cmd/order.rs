//! `towpath order`: cut contours and plotter strokes in the order with the least rapid (pen-up)
//! travel, holes and inner parts first; SVG, DXF, G-code or towpath-cut JSON in and the same
//! format out.

use std::path::PathBuf;

use anyhow::Context;
use towpath_cut::io::{self, Format};
use towpath_cut::lead::{LeadIn, LeadKind};
use towpath_cut::order::order_merged;
use towpath_cut::verify::Rules;
use towpath_cut::{order, verify, EntryMode, OrderOptions};
use towpath_seq::SolveOptions;

use crate::cmd::solver_args::SolverArgs;
use crate::files::Files;
use crate::{exit, outln};

/// Where closed contours may be entered.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Entry {
    /// Only at vertices.
    Vertex,
    /// Anywhere along the contour (candidates, then each entry refined).
    Any,
}

/// Lead-in shape.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Lead {
    /// A straight line square to the contour.
    Line,
    /// A quarter circle ending tangent to the contour.
    Arc,
}

/// Input format (by default from the file name's extension, else from the content).
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum InputFormat {
    /// SVG.
    Svg,
    /// DXF.
    Dxf,
    /// G-code.
    Gcode,
    /// towpath-cut/1 JSON.
    Json,
}

/// Arguments of `towpath order`.
#[derive(clap::Args, Debug)]
#[command(after_long_help = "Orders the pieces of a cutting or plotting job (laser, waterjet, plasma, drag \
knife, pen plotter) so that the rapid (pen-up) travel between them is least, without letting a part drop out \
before its holes are cut: a piece inside a closed contour is done before it. Each closed contour is entered \
where it is best (at a vertex or anywhere along it) and keeps its drawn direction; open strokes may be drawn \
backwards. Every piece's geometry is kept exactly: the output is the input with the pieces reordered, \
reversed or started elsewhere, checked by an independent verifier before it is written.

Inputs: SVG (layers = top-level groups as operations, in document order), DXF (layers as operations; LINE, \
LWPOLYLINE, POLYLINE, ARC, CIRCLE, SPLINE), G-code (pieces between rapids or torch/pen on/off; rapids \
regenerated), towpath-cut/1 JSON (docs/cut.md). Operations are done in their order unless --mix-operations.

Examples:
  towpath order drawing.svg -o sorted.svg
  towpath order parts.dxf -o parts-sorted.dxf --lead-in 2 --lead-kind arc
  towpath order job.nc -o job-sorted.nc --no-reverse --json")]
pub struct Args {
    /// The drawing (.svg, .dxf, .nc/.gcode/.ngc/.tap, .json).
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Write the ordered drawing here (same format as the input).
    #[arg(short, long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
    /// The input's format, if its extension does not tell.
    #[arg(long, value_enum)]
    pub format: Option<InputFormat>,
    /// Never draw an open stroke backwards.
    #[arg(long)]
    pub no_reverse: bool,
    /// Do not require pieces inside a closed contour to come before it.
    #[arg(long)]
    pub no_inner_first: bool,
    /// Let operations (layers) interleave instead of doing them in their listed order.
    #[arg(long)]
    pub mix_operations: bool,
    /// Where closed contours may be entered.
    #[arg(long, value_enum, default_value_t = Entry::Any)]
    pub entry: Entry,
    /// Spacing of entry candidates along closed contours (drawing units; default: contour
    /// length / --max-entries).
    #[arg(long, value_name = "D")]
    pub entry_spacing: Option<f64>,
    /// Most entry candidates per closed contour.
    #[arg(long, default_value_t = 12, value_name = "N")]
    pub max_entries: usize,
    /// Lead-in length (drawing units) at each closed contour's entry, on the scrap side.
    #[arg(long, value_name = "MM")]
    pub lead_in: Option<f64>,
    /// Lead-in shape.
    #[arg(long, value_enum, default_value_t = Lead::Line)]
    pub lead_kind: Lead,
    /// Join open strokes whose ends meet within this distance into one (drawn without lifting).
    #[arg(long, value_name = "TOL")]
    pub merge: Option<f64>,
    /// Where the tool starts: X,Y, or "none" to start at the first piece (default 0,0).
    #[arg(long, value_name = "X,Y", default_value = "0,0")]
    pub start: String,
    /// Flattening and "touching" tolerance in drawing units.
    #[arg(long, default_value_t = 1e-3)]
    pub tolerance: f64,
    /// Solver time limit in seconds (default 0.2 ms per piece, at least 0.1 s and at most 5 s;
    /// the search stops sooner when it stagnates).
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Work budget (improvement kicks); without --time-limit the answer then depends only on
    /// the input, --seed and --threads.
    #[arg(long)]
    pub iterations: Option<u64>,
    /// Seed of the solver's random choices.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Solver threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print one JSON object with the totals instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Prove how far from the least possible rapid travel the order can be: a Held–Karp lower
    /// bound on every order, for drawings of open strokes drawn either way (solved through
    /// their ends; up to 25,000 strokes per operation). Takes O(n²) time after the search: about
    /// 0.6 s for 1,000 strokes, 12 s for 10,000.
    #[arg(long)]
    pub bound: bool,
    #[command(flatten)]
    pub solver: SolverArgs,
}

fn parse_start(s: &str) -> anyhow::Result<Option<[f64; 2]>> {
    if s.eq_ignore_ascii_case("none") {
        return Ok(None);
    }
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| exit::bad_input(anyhow::anyhow!("--start {s:?}: give X,Y (two numbers) or none")))?;
    match v.as_slice() {
        [x, y] if x.is_finite() && y.is_finite() => Ok(Some([*x, *y])),
        _ => Err(exit::bad_input(anyhow::anyhow!("--start {s:?}: give X,Y (two numbers) or none"))),
    }
}

fn positive(name: &str, v: Option<f64>) -> anyhow::Result<()> {
    match v {
        Some(x) if !(x > 0.0 && x.is_finite()) => {
            Err(exit::bad_input(anyhow::anyhow!("{name} {x}: give a positive number")))
        }
        _ => Ok(()),
    }
}

/// Runs `towpath order`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut files = Files::new();
    files.input("drawing", &args.input)?;
    if let Some(o) = &args.output {
        files.output("ordered drawing", o)?;
    }
    positive("--lead-in", args.lead_in)?;
    positive("--merge", args.merge)?;
    positive("--entry-spacing", args.entry_spacing)?;
    positive("--tolerance", Some(args.tolerance))?;
    if args.max_entries == 0 {
        return Err(exit::bad_input(anyhow::anyhow!("--max-entries 0: give at least 1")));
    }
    let start = parse_start(&args.start)?;
    let name = args.input.display().to_string();
    let bytes = std::fs::read(&args.input).with_context(|| format!("reading {name}")).map_err(exit::bad_input)?;
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let format = match args.format {
        Some(InputFormat::Svg) => Format::Svg,
        Some(InputFormat::Dxf) => Format::Dxf,
        Some(InputFormat::Gcode) => Format::Gcode,
        Some(InputFormat::Json) => Format::Json,
        None => Format::from_extension(&name).unwrap_or_else(|| sniff(&text)),
    };
    let (drawing, source) = io::read(format, &text, &name, args.tolerance).map_err(exit::bad_input)?;
    let n = drawing.pieces.len();
    let time_limit = match (args.time_limit, args.iterations) {
        (Some(t), _) => Some(crate::cmd::solver_args::time_limit(t)?),
        (None, Some(_)) => None,
        (None, None) => Some(std::time::Duration::from_secs_f64((0.0002 * n as f64).clamp(0.1, 5.0))),
    };
    let mut solve = SolveOptions {
        time_limit,
        iterations: args.iterations,
        seed: args.seed,
        held_karp_bound: args.bound,
        ..SolveOptions::default()
    };
    if let Some(t) = args.threads {
        solve.threads = t.max(1);
    }
    let opts = OrderOptions {
        reverse: !args.no_reverse,
        inner_first: !args.no_inner_first,
        mix_operations: args.mix_operations,
        entry: match args.entry {
            Entry::Vertex => EntryMode::Vertex,
            Entry::Any => EntryMode::Any,
        },
        entry_spacing: args.entry_spacing,
        max_entries: args.max_entries,
        lead_in: args.lead_in.map(|length| LeadIn {
            length,
            kind: match args.lead_kind {
                Lead::Line => LeadKind::Line,
                Lead::Arc => LeadKind::Arc,
            },
        }),
        start,
        tolerance: args.tolerance,
        solve,
        solver: args.solver.solver,
        params: args.solver.params(),
    };
    let t0 = std::time::Instant::now();
    let report = match args.merge {
        Some(tol) => order_merged(&drawing, &opts, tol),
        None => order(&drawing, &opts),
    }
    .map_err(exit::bad_input)?;
    let rules = Rules {
        inner_first: opts.inner_first,
        mix_operations: opts.mix_operations,
        reverse: opts.reverse,
        tolerance: opts.tolerance,
        start: opts.start,
    };
    let check = verify(&drawing, &report.placements, &rules);
    if !check.ok() {
        return Err(exit::check_failed(anyhow::anyhow!("the ordering did not verify: {}", check.problems())));
    }
    if let Some(o) = &args.output {
        let text = io::write(&source, &drawing, &report.placements).map_err(exit::bad_input)?;
        files.write(o, text)?;
    }
    files.commit()?;
    let seconds = t0.elapsed().as_secs_f64();
    let closed = drawing.pieces.iter().filter(|p| p.path.closed).count();
    let reversed = report.placements.iter().filter(|p| p.reversed).count();
    if args.json {
        let v = serde_json::json!({
            "input": name,
            "format": format!("{format:?}").to_lowercase(),
            "pieces": n,
            "closed": closed,
            "operations": drawing.operations,
            "rapid_before": report.travel_before,
            "rapid_after": report.travel_after,
            "rapid_solved": report.travel_solved,
            "reversed": reversed,
            "precedence_pairs": report.precedence_pairs,
            "precedence_violations": check.precedence.len(),
            "solver": opts.solver.as_str(),
            "solve_seconds": report.solve_seconds,
            "seconds": seconds,
            "iterations": report.iterations,
            "rapid_lower_bound": report.travel_lower_bound,
            "output": args.output.as_ref().map(|p| p.display().to_string()),
        });
        outln!("{v}");
    } else {
        let saved =
            if report.travel_before > 0.0 { 100.0 * (1.0 - report.travel_after / report.travel_before) } else { 0.0 };
        outln!("towpath order: {name}");
        outln!("  pieces              : {n} ({closed} closed, {} operations)", drawing.operations.len());
        outln!("  rapid travel before : {:>14.3}", report.travel_before);
        outln!("  rapid travel after  : {:>14.3}  ({saved:.1} % less)", report.travel_after);
        match report.travel_lower_bound {
            Some(b) if b > 0.0 => outln!(
                "  lower bound         : {b:>14.3}  (Held–Karp: no order travels less; this one is {:.2} % above)",
                100.0 * (report.travel_after - b) / b
            ),
            Some(b) => outln!("  lower bound         : {b:>14.3}  (Held–Karp)"),
            None if args.bound => {
                outln!(
                    "  lower bound         : none (only for open strokes drawn either way, solved through their ends)"
                )
            }
            None => {}
        }
        outln!("  reversed strokes    : {reversed}");
        outln!("  precedence          : {} pairs kept, 0 violations (verified)", report.precedence_pairs);
        outln!("  solver              : {} {:.2} s, total {seconds:.2} s", opts.solver, report.solve_seconds);
        if let Some(o) = &args.output {
            outln!("  written to          : {}", o.display());
        }
    }
    Ok(())
}

/// The format of a file whose extension does not tell, from its first characters.
fn sniff(text: &str) -> Format {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with('{') {
        Format::Json
    } else if t.starts_with('<') {
        Format::Svg
    } else if t.starts_with("0\n") || t.starts_with("0\r\n") || t.starts_with("999") {
        Format::Dxf
    } else {
        Format::Gcode
    }
}
