//! `towpath verify`: checks an optimized AFP program against its original, independently of the
//! optimizer, and prints the cycle time and the off-part motion before and after.

use std::path::PathBuf;

use towpath_nc::{totals, verify, PrecedenceRule, VerifyError, VerifyOptions};

use super::afp_common::{machine_hint, read, warn, width_from, MachineArgs};
use crate::{exit, outln};

/// Arguments of `towpath verify`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The original program.
    #[arg(value_name = "ORIGINAL")]
    pub original: PathBuf,
    /// The optimized program.
    #[arg(value_name = "OPTIMIZED")]
    pub optimized: PathBuf,
    #[command(flatten)]
    pub machine: MachineArgs,
    /// The precedence the optimized program must keep: a course after the courses of earlier
    /// plies it overlaps (courses, always checked), and also Doherty et al.'s precedence sets in order
    /// (sets) or every ply finished before the next starts (plies), as `optimize --precedence`.
    #[arg(long, default_value = "courses", value_name = "courses|sets|plies")]
    pub precedence: PrecedenceRule,
    /// Also require every ply to be finished before the next one starts (`--precedence plies`).
    #[arg(long)]
    pub strict_plies: bool,
    /// Also require the courses of each ply in their original order.
    #[arg(long)]
    pub keep_ply_order: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `towpath verify`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let (machine, dialect, width) = args.machine.load()?;
    let original = read(&args.original)?;
    let optimized = read(&args.optimized)?;
    let opts = VerifyOptions {
        width,
        strict_plies: args.strict_plies || args.precedence == PrecedenceRule::Plies,
        keep_ply_order: args.keep_ply_order,
        seed000_sets: args.precedence == PrecedenceRule::Sets,
    };
    let m = &args.machine.machine;
    let v = verify(&original, &optimized, &machine, &dialect, &opts).map_err(|e| match e {
        VerifyError::Original(e) => {
            exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.original.display(), machine_hint(&e, m)))
        }
        VerifyError::Optimized(e) => {
            exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.optimized.display(), machine_hint(&e, m)))
        }
        VerifyError::Setup(e) => {
            exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.original.display(), machine_hint(&e, m)))
        }
        e => {
            exit::check_failed(anyhow::anyhow!("{} against {}: {e}", args.optimized.display(), args.original.display()))
        }
    })?;
    let t = totals(&v);
    let from = width_from(&args.machine, &v.width, &args.machine.dialect_name());
    if let Some(w) = &v.width.warning {
        warn(w);
    }
    let per_tow = if matches!(v.width.width, Some(towpath_nc::Width::Tow(_))) { " × tows on" } else { "" };
    let width = match (&v.width.width, v.precedence_checked) {
        (Some(_), true) => format!("{}{per_tow} (from {from})", v.width.describe()),
        (Some(_), false) => format!("{}{per_tow} (from {from}; no footprints needed)", v.width.describe()),
        (None, _) if v.ply_order_checked => "none (ply by ply: no footprints needed)".to_string(),
        (None, _) => "none (one ply: no footprints needed)".to_string(),
    };
    if args.json {
        outln!(
            "{}",
            serde_json::json!({
                "verified": true,
                "courses": v.courses,
                "reversed": v.reversed,
                "precedence_checked": v.precedence_checked,
                "ply_order_checked": v.ply_order_checked,
                "width": v.width,
                "width_from": from,
                "warnings": v.width.warning.iter().collect::<Vec<_>>(),
                "cycle_time": t.iter().find(|x| x.kind == towpath_machine::CostKind::Time),
                "totals": t,
            })
        );
        return Ok(());
    }
    outln!(
        "verified: {} courses, same motion on-part ({} laid in reverse), precedence {}",
        v.courses,
        v.reversed,
        match (v.precedence_checked, opts.seed000_sets, opts.strict_plies) {
            (false, _, true) => "kept (ply by ply)",
            (false, ..) => "not needed (one ply)",
            (true, true, _) => "kept (and Doherty et al.'s precedence sets in order)",
            (true, _, true) => "kept (and ply by ply)",
            (true, ..) => "kept",
        }
    );
    // Cycle time first, then distance.
    for line in towpath_nc::headline(&t) {
        outln!("  {line}");
    }
    outln!("  width: {width}");
    crate::out!("{}", towpath_nc::totals_table(&t));
    Ok(())
}
