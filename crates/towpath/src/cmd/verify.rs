//! `towpath verify`: checks an optimized AFP program against its original, independently of the
//! optimizer, and prints the cycle time and the off-part motion before and after.

use std::path::PathBuf;

use towpath_nc::{totals, verify_parsed, PrecedenceRule, VerifyError, VerifyOptions};

use super::afp_common::{hint, read, warn, width_from, CellArgs, MachineArgs};
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
    #[command(flatten)]
    pub cell: CellArgs,
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
    let safety = args.cell.load(&machine, &dialect)?;
    let original = read(&args.original)?;
    let optimized = read(&args.optimized)?;
    let opts = VerifyOptions {
        width,
        strict_plies: args.strict_plies || args.precedence == PrecedenceRule::Plies,
        keep_ply_order: args.keep_ply_order,
        doherty_sets: args.precedence == PrecedenceRule::Sets,
    };
    let m = &args.machine.machine;
    // Each program is parsed once, for the verifier and the safety checks.
    let parsed = towpath_nc::parse(&original, &machine, &dialect)
        .map_err(VerifyError::Original)
        .and_then(|a| Ok((a, towpath_nc::parse(&optimized, &machine, &dialect).map_err(VerifyError::Optimized)?)));
    let v = parsed
        .as_ref()
        .map_err(Clone::clone)
        .and_then(|(a, b)| verify_parsed(a, b, &machine, &dialect, &opts, None))
        .map_err(|e| match e {
            VerifyError::Original(e) => {
                exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.original.display(), hint(&e, m)))
            }
            VerifyError::Optimized(e) => {
                exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.optimized.display(), hint(&e, m)))
            }
            VerifyError::Setup(e) => {
                exit::bad_input(anyhow::anyhow!("{}: {e}{}", args.original.display(), hint(&e, m)))
            }
            e => exit::check_failed(anyhow::anyhow!(
                "{} against {}: {e}",
                args.optimized.display(),
                args.original.display()
            )),
        })?;
    let t = totals(&v);
    let (a, b) = parsed.map_err(|e| anyhow::anyhow!("internal: {e}"))?;
    let safety = check_safety(&args, &a, &b, &machine, safety.as_ref())?;
    let unsafe_after = !safety.after.is_safe();
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
                "safety": safety_json(&safety),
            })
        );
        return safety_verdict(&args, &safety);
    }
    outln!(
        "verified: {} courses, same motion on-part ({} laid in reverse), precedence {}",
        v.courses,
        v.reversed,
        match (v.precedence_checked, opts.doherty_sets, opts.strict_plies) {
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
    if safety.checked_cell {
        outln!("  motion safety, original:  {}", safety.before.summary());
        outln!("  motion safety, optimized: {}", safety.after.summary());
    }
    if unsafe_after || safety.before.near_misses.len() < safety.after.near_misses.len() {
        for line in safety.after.details(10) {
            outln!("    {line}");
        }
    }
    safety_verdict(&args, &safety)
}

/// The motion safety of both programs: against the cell with `--mold`, else the travel
/// limits only.
struct SafetyBoth {
    before: towpath_nc::SafetyReport,
    after: towpath_nc::SafetyReport,
    checked_cell: bool,
}

fn check_safety(
    args: &Args,
    a: &towpath_nc::Program,
    b: &towpath_nc::Program,
    machine: &towpath_machine::Machine,
    safety: Option<&towpath_nc::Safety>,
) -> anyhow::Result<SafetyBoth> {
    Ok(match safety {
        Some(s) => {
            towpath_nc::check_cell_under_path(a, machine, s, towpath_nc::MOLD_GAP)
                .map_err(|e| exit::bad_input(anyhow::anyhow!("{}: {e}", args.original.display())))?;
            SafetyBoth {
                before: towpath_nc::check_program(a, s),
                after: towpath_nc::check_program(b, s),
                checked_cell: true,
            }
        }
        None => {
            let limits = |p: &towpath_nc::Program| towpath_nc::SafetyReport {
                limit_violations: towpath_nc::limit_violations(p, machine),
                ..towpath_nc::SafetyReport::default()
            };
            SafetyBoth { before: limits(a), after: limits(b), checked_cell: false }
        }
    })
}

fn safety_json(s: &SafetyBoth) -> serde_json::Value {
    let one = |r: &towpath_nc::SafetyReport| {
        serde_json::json!({
            "collisions": r.collisions.len(),
            "near_misses": r.near_misses.len(),
            "limit_violations": r.limit_violations.len(),
            "min_clearance": r.min_clearance.map(|(c, _)| c),
            "min_clearance_line": r.min_clearance.map(|(_, l)| l),
            "moves_checked": r.moves_checked,
            "details": r,
        })
    };
    serde_json::json!({
        "cell_checked": s.checked_cell,
        "clearance": s.checked_cell.then_some(s.after.clearance),
        "original": one(&s.before),
        "optimized": one(&s.after),
    })
}

/// Exit 3 when the optimized program collides or leaves the travel limits.
fn safety_verdict(args: &Args, s: &SafetyBoth) -> anyhow::Result<()> {
    if s.after.is_safe() {
        return Ok(());
    }
    let already =
        if s.before.is_safe() { String::new() } else { format!("; the original already has {}", s.before.summary()) };
    Err(exit::check_failed(anyhow::anyhow!("{}: not safe: {}{already}", args.optimized.display(), s.after.summary())))
}
