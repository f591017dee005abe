//! `towpath machine`: 2.5D pocket machining after Castelino, D'Souza & Wright (2003): features
//! offset per tool into toolpath cells, the cells linked from the origin and back with the
//! least airtime under the feature hierarchy, written as G-code with a drawing.

use std::path::PathBuf;

use anyhow::Context;
use towpath_cut::mill::{check_plan, output, plan, read_part, MillOptions};
use towpath_seq::SolveOptions;

use crate::cmd::solver_args::{refusal, SolverArgs};
use crate::files::Files;
use crate::{exit, outln};

/// Arguments of `towpath machine`.
#[derive(clap::Args, Debug)]
#[command(after_long_help = "Plans the pocket machining of a 2.5D part with several tools (Castelino, \
D'Souza & Wright 2003). For each tool, each feature it machines is offset inward by the tool radius and then \
again at the step-over (contour-parallel toolpaths); a region that splits gives several toolpath cells. Each \
cell is entered at a point on its outermost loop, which fixes where it ends; the cells of each tool are \
linked from the origin and back with the least rapid travel, parents before children in the feature \
hierarchy and a split cell before the cells it splits into. Writes G-code (tool change, spindle, a plunge per \
cell, feed moves, retract to the clearance plane) and, with --report, an SVG or HTML drawing.

Part file (towpath-part/1, docs/machining.md):
  {\"format\": \"towpath-part/1\", \"origin\": [0, 0], \"clearance\": 5,
   \"features\": [{\"id\": \"pocket\", \"boundary\": [[0,0],[80,0],[80,40],[0,40]], \"islands\": [], \"depth\": 6,
                 \"parent\": null}],
   \"tools\": [{\"number\": 1, \"radius\": 4, \"step_over\": 3, \"features\": [\"pocket\"]}]}")]
pub struct Args {
    /// The part description (JSON).
    #[arg(value_name = "PART.json")]
    pub part: PathBuf,
    /// Write the G-code here.
    #[arg(short, long, value_name = "OUT.nc")]
    pub output: Option<PathBuf>,
    /// Plan only this tool number (repeat for several).
    #[arg(long, value_name = "N")]
    pub tool: Vec<u32>,
    /// Override every tool's step-over.
    #[arg(long, value_name = "MM")]
    pub step_over: Option<f64>,
    /// Spacing of entry candidates along each cell's outermost loop.
    #[arg(long, value_name = "MM")]
    pub entry_spacing: Option<f64>,
    /// Most entry candidates per cell.
    #[arg(long, default_value_t = 16, value_name = "N")]
    pub max_entries: usize,
    /// Machine each cell from the inside out (default: outside-in).
    #[arg(long)]
    pub inside_out: bool,
    /// Write a drawing of the linked paths (.svg) or a report with it (.html).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Solver time limit per tool in seconds. A tool of up to ten cells (of up to 16 entries
    /// each) is linked exactly at once; a larger one stops sooner when 40 % of the budget
    /// (eight of its twenty epochs in a row) brings no better plan.
    #[arg(long, default_value_t = 2.0)]
    pub time_limit: f64,
    /// Work budget per tool; without --time-limit the answer depends only on the input, seed
    /// and threads.
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
    #[command(flatten)]
    pub solver: SolverArgs,
}

/// Epochs (each a twentieth of the budget) in a row without a better plan after which a tool's
/// search stops: cell linking converges well inside the default 2 s on the benchmark parts, and
/// running to the limit made every tool cost the whole limit (BENCHMARKS.md, "Machining").
const STALL_EPOCHS: u32 = 8;

/// Runs `towpath machine`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut files = Files::new();
    files.input("part", &args.part)?;
    if let Some(o) = &args.output {
        files.output("G-code", o)?;
    }
    if let Some(r) = &args.report {
        files.output("report", r)?;
    }
    let name = args.part.display().to_string();
    let text =
        std::fs::read_to_string(&args.part).with_context(|| format!("reading {name}")).map_err(exit::bad_input)?;
    let mut part = read_part(&text, &name).map_err(exit::bad_input)?;
    if let Some(s) = args.step_over {
        for t in &mut part.tools {
            if !(s > 0.0 && s <= 2.0 * t.radius) {
                return Err(exit::bad_input(anyhow::anyhow!(
                    "--step-over {s}: must be positive and at most the diameter of T{} ({})",
                    t.number,
                    2.0 * t.radius
                )));
            }
            t.step_over = s;
        }
    }
    for n in &args.tool {
        if !part.tools.iter().any(|t| t.number == *n) {
            return Err(exit::bad_input(anyhow::anyhow!("--tool {n}: the part has no tool T{n}")));
        }
    }
    if let Some(s) = args.entry_spacing {
        if !(s > 0.0 && s.is_finite()) {
            return Err(exit::bad_input(anyhow::anyhow!("--entry-spacing {s}: give a positive number")));
        }
    }
    let time_limit = match args.iterations {
        Some(_) if args.time_limit == 2.0 => None,
        _ => Some(crate::cmd::solver_args::time_limit(args.time_limit)?),
    };
    let mut solve = SolveOptions {
        time_limit,
        iterations: args.iterations,
        seed: args.seed,
        stall_epochs: Some(STALL_EPOCHS),
        ..SolveOptions::default()
    };
    if let Some(t) = args.threads {
        solve.threads = t.max(1);
    }
    let opts = MillOptions {
        entry_spacing: args.entry_spacing,
        max_entries: args.max_entries.max(1),
        inside_out: args.inside_out,
        tools: args.tool.clone(),
        solve,
        solver: args.solver.solver,
        params: args.solver.params(),
    };
    let p = plan(&part, &opts).map_err(|e| match e {
        towpath_cut::CutError::Solver(s) => exit::bad_input(anyhow::anyhow!(
            "solver {}: {s}{}",
            opts.solver,
            if opts.solver == towpath_baselines::SolverName::Towpath {
                ""
            } else {
                " (--solver towpath takes every valid problem)"
            }
        )),
        e => exit::bad_input(e),
    })?;
    let _ = refusal;
    let problems = check_plan(&part, &p, opts.inside_out);
    if !problems.is_empty() {
        return Err(exit::check_failed(anyhow::anyhow!("the plan did not verify: {}", problems.join("; "))));
    }
    if let Some(o) = &args.output {
        files.write(o, output::gcode(&part, &p))?;
    }
    if let Some(r) = &args.report {
        let html = r.extension().is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
        let text = if html { output::html(&part, &p, opts.solver.as_str()) } else { output::svg(&part, &p) };
        files.write(r, text)?;
    }
    files.commit()?;
    let tools: Vec<serde_json::Value> = p
        .tools
        .iter()
        .map(|tp| {
            let t = &part.tools[tp.tool];
            serde_json::json!({
                "tool": t.number,
                "radius": t.radius,
                "step_over": t.step_over,
                "cells": tp.cells.len(),
                "precedence_pairs": tp.precedence.len(),
                "rapid_before": tp.rapid_before,
                "rapid_after": tp.rapid_after,
                "order": tp.order.iter().map(|(c, _)| tp.cells[*c].id.clone()).collect::<Vec<_>>(),
                "solve_seconds": tp.solve_seconds,
            })
        })
        .collect();
    let before: f64 = p.tools.iter().map(|t| t.rapid_before).sum();
    let after: f64 = p.tools.iter().map(|t| t.rapid_after).sum();
    if args.json {
        let v = serde_json::json!({
            "part": part.name,
            "solver": opts.solver.as_str(),
            "tools": tools,
            "rapid_before": before,
            "rapid_after": after,
            "precedence_violations": 0,
        });
        outln!("{v}");
    } else {
        outln!("towpath machine: {} ({name})", part.name);
        for tp in &p.tools {
            let t = &part.tools[tp.tool];
            outln!(
                "  T{:<3} r {:<6} {:>4} cells  rapid {:>10.3} → {:>10.3}  ({:.2} s)",
                t.number,
                t.radius,
                tp.cells.len(),
                tp.rapid_before,
                tp.rapid_after,
                tp.solve_seconds
            );
        }
        let saved = if before > 0.0 { 100.0 * (1.0 - after / before) } else { 0.0 };
        outln!("  rapid travel (X/Y)  : {before:.3} → {after:.3} ({saved:.1} % less; before = cells in feature order, first vertex)");
        outln!("  solver              : {}, precedence kept (verified)", opts.solver);
        if let Some(o) = &args.output {
            outln!("  G-code written to   : {}", o.display());
        }
        if let Some(r) = &args.report {
            outln!("  drawing written to  : {}", r.display());
        }
    }
    Ok(())
}
