//! The savings report: totals per cost model, per ply and per precedence set, the new course
//! order, as JSON (serde) or a self-contained HTML page with a before/after plan view.

use std::fmt::Write as _;

use serde::Serialize;
use towpath_machine::{CostKind, Machine};

use crate::footprint::{frame_for, Frame};
use crate::optimize::{Optimized, SolverSummary, Timings};
use crate::problem::PrecedenceRule;
use crate::program::{ply_name, Program};
use crate::reverse::Irreversible;
use crate::verify::{Motion, Verification};

/// Before/after figures under one cost model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Totals {
    /// The cost model.
    pub kind: CostKind,
    /// Its unit.
    pub unit: &'static str,
    /// Off-part motion of the input.
    pub off_before: f64,
    /// Off-part motion of the output.
    pub off_after: f64,
    /// Off-part saving, percent.
    pub off_saved_percent: f64,
    /// All motion of the input.
    pub total_before: f64,
    /// All motion of the output.
    pub total_after: f64,
    /// Total saving, percent.
    pub total_saved_percent: f64,
}

/// Off-part figures of a group of courses under one cost model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupCost {
    /// The cost model.
    pub kind: CostKind,
    /// Before.
    pub before: f64,
    /// After.
    pub after: f64,
    /// Saving, percent.
    pub saved_percent: f64,
}

/// A ply or precedence set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupRow {
    /// Its label.
    pub label: String,
    /// Courses in it.
    pub courses: usize,
    /// Off-part motion attributed to its courses (transit in, approach, retract).
    pub off_part: Vec<GroupCost>,
}

/// One course of the new order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OrderRow {
    /// Position in the new program, from 1.
    pub position: usize,
    /// Position in the original program, from 1.
    pub original: usize,
    /// The ply's number or label.
    pub ply: String,
    /// The course number from its marker, if any.
    pub number: Option<i64>,
    /// The original line of its roller contact.
    pub line: usize,
    /// Laid in reverse.
    pub reversed: bool,
    /// Its Doherty et al.'s precedence set, from 1.
    pub set: usize,
}

/// The savings report. Cycle time leads: [`Report::cycle_time`] (when the machine has
/// velocities), then the distances.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The program's name.
    pub program: String,
    /// Cycle time before and after (the machine's time model, seconds), when every axis of the
    /// machine has a velocity limit.
    pub cycle_time: Option<Totals>,
    /// The machine's name.
    pub machine: String,
    /// The cost model optimized.
    pub cost: CostKind,
    /// Reversal allowed.
    pub bidirectional: bool,
    /// Precedence rule.
    pub precedence: PrecedenceRule,
    /// Courses.
    pub courses: usize,
    /// Plies.
    pub plies: usize,
    /// Doherty et al.'s precedence sets.
    pub precedence_sets: usize,
    /// Precedence edges given to the solver.
    pub precedence_edges: usize,
    /// Courses laid in reverse.
    pub reversed: usize,
    /// Courses that could not be reversed, and why.
    pub not_reversible: Vec<String>,
    /// Totals per cost model.
    pub totals: Vec<Totals>,
    /// Per ply.
    pub per_ply: Vec<GroupRow>,
    /// Per Doherty et al.'s precedence set.
    pub per_set: Vec<GroupRow>,
    /// Off-part motion of the header and footer (per cost model: before, after).
    pub header_footer: Vec<GroupCost>,
    /// The new order.
    pub order: Vec<OrderRow>,
    /// Solver figures.
    pub solver: SolverSummary,
    /// Stage times.
    pub timings: Timings,
    /// The output verified against the input.
    pub verified: bool,
    /// The input was returned unchanged because nothing cheaper was found.
    pub fell_back: bool,
    /// Why the input was returned unchanged, if it was.
    pub fallback: Option<crate::optimize::Fallback>,
    /// The course width used and where it came from.
    pub width: crate::width::WidthUsed,
    /// Where the width came from, in words for the user (`the dialect`; a caller that knows how
    /// the width was given may say so, e.g. `the command line`).
    pub width_from: String,
    /// Things the user should know: a width that disagrees with the dialect's, courses kept
    /// forward because of lines the dialect does not describe.
    pub warnings: Vec<String>,
    /// Motion safety of the input and the output against the cell, when one was given.
    pub safety: Option<crate::optimize::SafetyPair>,
}

fn pct(before: f64, after: f64) -> f64 {
    if before > 0.0 {
        100.0 * (before - after) / before
    } else {
        0.0
    }
}

fn group(label: String, courses: &[usize], v: &Verification) -> GroupRow {
    let off_part = v
        .before
        .iter()
        .zip(&v.after)
        .map(|(b, a)| {
            let (x, y): (f64, f64) =
                (courses.iter().map(|&c| b.off_course[c]).sum(), courses.iter().map(|&c| a.off_course[c]).sum());
            GroupCost { kind: b.kind, before: x, after: y, saved_percent: pct(x, y) }
        })
        .collect();
    GroupRow { label, courses: courses.len(), off_part }
}

/// Totals of a verification, cycle time first (when the machine has velocities), then the
/// weighted axis distance and the tool-point distance.
pub fn totals(v: &Verification) -> Vec<Totals> {
    let mut pairs: Vec<(&Motion, &Motion)> = v.before.iter().zip(&v.after).collect();
    pairs.sort_by_key(|(b, _)| b.kind != CostKind::Time);
    pairs
        .into_iter()
        .map(|(b, a): (&Motion, &Motion)| Totals {
            kind: b.kind,
            unit: b.kind.unit(),
            off_before: b.off_part(),
            off_after: a.off_part(),
            off_saved_percent: pct(b.off_part(), a.off_part()),
            total_before: b.total(),
            total_after: a.total(),
            total_saved_percent: pct(b.total(), a.total()),
        })
        .collect()
}

impl Report {
    /// Builds the report of an optimization.
    pub fn new(name: &str, machine: &Machine, o: &Optimized, opts: &crate::problem::AfpOptions) -> Report {
        let p = &o.program;
        let v = &o.verification;
        let mut set_of = vec![0usize; p.courses.len()];
        for (s, cs) in o.afp.sets.iter().enumerate() {
            for &c in cs {
                set_of[c] = s;
            }
        }
        let per_ply = p.plies.iter().map(|ply| group(ply.label.clone(), &ply.courses, v)).collect();
        let per_set = o
            .afp
            .set_plies
            .iter()
            .zip(&o.afp.sets)
            .enumerate()
            .map(|(i, (ps, cs))| {
                let names: Vec<String> = ps.iter().map(|&x| ply_name(&p.plies[x])).collect();
                group(format!("set {} (plies {})", i + 1, names.join(", ")), cs, v)
            })
            .collect();
        let order = o
            .order
            .iter()
            .enumerate()
            .map(|(i, pl)| {
                let c = &p.courses[pl.course];
                OrderRow {
                    position: i + 1,
                    original: pl.course + 1,
                    ply: ply_name(&p.plies[c.ply]),
                    number: c.number,
                    line: c.on_part.start + 1,
                    reversed: pl.reversed,
                    set: set_of[pl.course] + 1,
                }
            })
            .collect();
        let totals = totals(v);
        Report {
            program: name.to_string(),
            cycle_time: totals.iter().find(|t| t.kind == CostKind::Time).cloned(),
            machine: machine.name.clone(),
            cost: opts.cost,
            bidirectional: opts.bidirectional,
            precedence: opts.precedence,
            courses: p.courses.len(),
            plies: p.plies.len(),
            precedence_sets: o.afp.sets.len(),
            precedence_edges: o.afp.edges,
            reversed: v.reversed,
            not_reversible: o
                .afp
                .not_reversible
                .iter()
                .map(|(c, why)| format!("{}: {why}", p.course_name(*c)))
                .collect(),
            totals,
            per_ply,
            per_set,
            header_footer: v
                .before
                .iter()
                .zip(&v.after)
                .map(|(b, a)| GroupCost {
                    kind: b.kind,
                    before: b.off_other,
                    after: a.off_other,
                    saved_percent: pct(b.off_other, a.off_other),
                })
                .collect(),
            order,
            solver: o.solver.clone(),
            timings: o.timings.clone(),
            verified: true,
            fell_back: o.fell_back,
            fallback: o.fallback,
            width: o.width.clone(),
            width_from: match o.width.source {
                crate::width::WidthSource::Given => "the options given".into(),
                crate::width::WidthSource::Dialect => "the dialect".into(),
                crate::width::WidthSource::Default => "nowhere".into(),
            },
            warnings: o
                .width
                .warning
                .iter()
                .cloned()
                .chain(forward_only(p, &o.afp.not_reversible))
                .chain(o.safety.iter().filter(|s| !s.before.is_safe()).map(|s| {
                    format!(
                        "the input program is not safe in this cell: {}; towpath wrote its transits anew, {}",
                        s.before.summary(),
                        s.before.details(3).join("; ")
                    )
                }))
                .collect(),
            safety: o.safety.clone(),
        }
    }

    /// The width line of the summary: which width, and where it came from.
    pub fn width_line(&self) -> String {
        match self.width.width {
            Some(w) => format!(
                "{}{} (from {})",
                crate::width::WidthUsed { width: Some(w), ..self.width.clone() }.describe(),
                if matches!(w, crate::footprint::Width::Tow(_)) { " × tows on" } else { "" },
                self.width_from
            ),
            None if self.plies <= 1 => "none (one ply: no footprints needed)".into(),
            None => "none (ply by ply: no footprints needed)".into(),
        }
    }

    /// The totals under one cost model.
    pub fn total(&self, kind: CostKind) -> Option<&Totals> {
        self.totals.iter().find(|t| t.kind == kind)
    }

    /// A plain-text summary for a terminal: cycle time first, then distances.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{}: {} courses in {} {} ({} precedence {}), machine {}, optimized for {}, {}",
            self.program,
            self.courses,
            self.plies,
            plural(self.plies, "ply", "plies"),
            self.precedence_sets,
            plural(self.precedence_sets, "set", "sets"),
            self.machine,
            cost_words(self.cost),
            if self.bidirectional { "bidirectional" } else { "unidirectional" }
        );
        for line in headline(&self.totals) {
            let _ = writeln!(s, "  {line}");
        }
        s.push_str(&totals_table(&self.totals));
        let _ = writeln!(
            s,
            "  {} courses reversed{}; verified; {:.2} s (solver {}: {:.2} s){}",
            self.reversed,
            if self.bidirectional && !self.not_reversible.is_empty() {
                format!(" ({} kept forward: see the report)", self.not_reversible.len())
            } else {
                String::new()
            },
            self.timings.total,
            self.solver.solver,
            self.timings.solve,
            match &self.fallback {
                Some(f) => format!("; {f}: the input is returned unchanged"),
                None => String::new(),
            }
        );
        let _ = writeln!(s, "  width: {}", self.width_line());
        if let Some(sf) = &self.safety {
            let _ = writeln!(s, "  motion safety, input:  {}", sf.before.summary());
            let _ = writeln!(s, "  motion safety, output: {}", sf.after.summary());
        }
        s
    }

    /// A self-contained HTML page: tables and a before/after plan view.
    pub fn to_html(&self, o: &Optimized, optimized: &Program, machine: &Machine) -> String {
        let mut h = String::new();
        let _ = write!(
            h,
            "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>towpath: {}</title><style>\
             body{{font-family:system-ui,sans-serif;margin:2em;color:#222}}table{{border-collapse:collapse;margin:1em 0}}\
             td,th{{border:1px solid #ccc;padding:.25em .6em;text-align:right}}th{{background:#f3f3f3}}\
             td:first-child,th:first-child{{text-align:left}}.views{{display:flex;gap:1em;flex-wrap:wrap}}\
             .views figure{{margin:0;border:1px solid #ccc}}.headline p{{margin:.2em 0;font-size:1.1em}}.legend span{{margin-right:1em;white-space:nowrap}}.legend i{{display:inline-block;width:1.4em;height:.5em;margin-right:.3em;vertical-align:middle}}figcaption{{padding:.3em;background:#f3f3f3}}</style></head><body>\n",
            esc(&self.program)
        );
        let _ = writeln!(h, "<h1>towpath: {}</h1>", esc(&self.program));
        // Cycle time leads, then distance.
        h.push_str("<div class=\"headline\">");
        for (i, line) in headline(&self.totals).iter().enumerate() {
            let _ = write!(
                h,
                "<p>{}{}{}</p>",
                if i == 0 { "<b>" } else { "" },
                esc(line),
                if i == 0 { "</b>" } else { "" }
            );
        }
        h.push_str("</div>\n");
        let _ = writeln!(
            h,
            "<p>{} courses in {} {}, {} of Doherty et al.'s precedence sets; machine <b>{}</b>; optimized for <b>{}</b>, {}, precedence by {}; {} courses reversed. Verified against the input.{}</p>",
            self.courses,
            self.plies,
            plural(self.plies, "ply", "plies"),
            self.precedence_sets,
            esc(&self.machine),
            cost_words(self.cost),
            if self.bidirectional { "bidirectional" } else { "unidirectional" },
            self.precedence,
            self.reversed,
            match &self.fallback {
                Some(f) => format!(" {}: the input is returned unchanged.", esc(&f.to_string())),
                None => String::new(),
            }
        );
        let _ = writeln!(h, "<p>Course width: {}.</p>", esc(&self.width_line()));
        if let Some(sf) = &self.safety {
            let _ = writeln!(
                h,
                "<p class=\"safety-summary\"><b>Motion safety</b> against the cell: input: {}; output: {}.</p>",
                esc(&sf.before.summary()),
                esc(&sf.after.summary())
            );
        }
        for w in &self.warnings {
            let _ = writeln!(h, "<p><b>Warning:</b> {}</p>", esc(w));
        }
        h.push_str("<h2>Totals</h2><table><tr><th>cost model</th><th>off-part before</th><th>off-part after</th><th>saved</th><th>total before</th><th>total after</th><th>saved</th><th>unit</th></tr>\n");
        for t in &self.totals {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1} %</td><td>{:.1}</td><td>{:.1}</td><td>{:.1} %</td><td>{}</td></tr>",
                t.kind, t.off_before, t.off_after, t.off_saved_percent, t.total_before, t.total_after, t.total_saved_percent, t.unit
            );
        }
        h.push_str("</table>\n");
        h.push_str("<h2>Plan view</h2>\n");
        match plan_views(o, optimized, machine) {
            Some(svg) => h.push_str(&svg),
            None => h.push_str("<p>(no drawing: the machine has no kinematics)</p>"),
        }
        for (title, rows) in [("Per ply", &self.per_ply), ("Per precedence set", &self.per_set)] {
            let _ = write!(h, "<h2>{title}</h2><table><tr><th>group</th><th>courses</th>");
            for t in &self.totals {
                let _ = write!(h, "<th>{0} before</th><th>{0} after</th><th>saved</th>", t.kind);
            }
            h.push_str("</tr>\n");
            for r in rows {
                let _ = write!(h, "<tr><td>{}</td><td>{}</td>", esc(&r.label), r.courses);
                for g in &r.off_part {
                    let _ =
                        write!(h, "<td>{:.1}</td><td>{:.1}</td><td>{:.1} %</td>", g.before, g.after, g.saved_percent);
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</table>\n");
        }
        h.push_str("<h2>New course order</h2><table><tr><th>position</th><th>original position</th><th>ply</th><th>course</th><th>line</th><th>direction</th><th>set</th></tr>\n");
        for r in &self.order {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                r.position,
                r.original,
                esc(&r.ply),
                r.number.map_or(String::new(), |n| n.to_string()),
                r.line,
                if r.reversed { "reversed" } else { "forward" },
                r.set
            );
        }
        h.push_str("</table>\n");
        if !self.not_reversible.is_empty() {
            h.push_str("<h2>Courses kept forward</h2><ul>");
            for n in &self.not_reversible {
                let _ = write!(h, "<li>{}</li>", esc(n));
            }
            h.push_str("</ul>\n");
        }
        h.push_str("</body></html>\n");
        h
    }
}

/// `one` or `many` by count.
fn plural(n: usize, one: &'static str, many: &'static str) -> &'static str {
    if n == 1 {
        one
    } else {
        many
    }
}

/// What a cost model optimizes, in words for the user.
pub fn cost_words(kind: CostKind) -> &'static str {
    match kind {
        CostKind::Time => "cycle time",
        CostKind::Axis => "Doherty et al.'s weighted axis distance",
        CostKind::Tool => "tool-point distance",
    }
}

/// The lines that lead every AFP summary: cycle time (off-part before -> after, % saved, total
/// before -> after), then distance (Doherty et al.'s weighted axis distance and the tool
/// point's path, when known). Without a time model, says so first.
pub fn headline(totals: &[Totals]) -> Vec<String> {
    let mut lines = Vec::new();
    match totals.iter().find(|t| t.kind == CostKind::Time) {
        Some(t) => lines.push(format!(
            "cycle time: off-part {:.1} s -> {:.1} s ({} saved), total {:.1} s -> {:.1} s ({} saved)",
            t.off_before,
            t.off_after,
            percent(t.off_saved_percent),
            t.total_before,
            t.total_after,
            percent(t.total_saved_percent)
        )),
        None => lines.push(
            "cycle time: unknown (the machine file gives no max_velocity for some axes); distances only".to_string(),
        ),
    }
    let mut distance = Vec::new();
    for t in totals.iter().filter(|t| t.kind != CostKind::Time) {
        distance.push(format!(
            "{} {:.0} -> {:.0} {} ({} saved)",
            match t.kind {
                CostKind::Axis => "weighted axis",
                _ => "tool point",
            },
            t.off_before,
            t.off_after,
            t.unit,
            percent(t.off_saved_percent)
        ));
    }
    if !distance.is_empty() {
        lines.push(format!("off-part distance: {}", distance.join("; ")));
    }
    lines
}

/// A saving in percent, one decimal.
fn percent(p: f64) -> String {
    format!("{p:.1} %")
}

/// The per-cost table of a summary (time first, as [`totals`] orders them).
pub fn totals_table(totals: &[Totals]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<6} {:>14} {:>14} {:>8} {:>14} {:>14} {:>8}",
        "cost", "off-part in", "off-part out", "saved", "total in", "total out", "saved"
    );
    for t in totals {
        let _ = writeln!(
            s,
            "  {:<6} {:>14.1} {:>14.1} {:>7.1}% {:>14.1} {:>14.1} {:>7.1}%   ({})",
            t.kind.name(),
            t.off_before,
            t.off_after,
            t.off_saved_percent,
            t.total_before,
            t.total_after,
            t.total_saved_percent,
            t.unit
        );
    }
    s
}

/// One warning for the courses kept forward because of codes the dialect does not describe (or
/// switches that do not pair up): how many, and the first.
fn forward_only(p: &Program, not_reversible: &[(usize, Irreversible)]) -> Option<String> {
    let list: Vec<&(usize, Irreversible)> =
        not_reversible.iter().filter(|(_, why)| !matches!(why, Irreversible::Other(_))).collect();
    let (c, why) = list.first()?;
    Some(if list.len() == 1 {
        format!("{} is laid forward only: {why}", p.course_name(*c))
    } else {
        format!(
            "{} courses are laid forward only because of codes the dialect does not describe or switches that do \
             not pair up; the first, {}: {why}",
            list.len(),
            p.course_name(*c)
        )
    })
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Colours of the plies in the plan view, in turn.
const PLY_COLOURS: [&str; 8] = ["#1b9e77", "#7570b3", "#e6ab02", "#66a61e", "#e7298a", "#a6761d", "#1f78b4", "#666"];

/// Polylines of a program in the frame: (the ply of an on-part run, or `None` off-part;
/// points).
fn polylines(p: &Program, machine: &Machine, frame: &Frame) -> Vec<(Option<usize>, Vec<[f64; 2]>)> {
    let Some(kin) = machine.kinematics() else { return Vec::new() };
    let regions = p.regions();
    let mut out: Vec<(Option<usize>, Vec<[f64; 2]>)> = Vec::new();
    for s in &p.segments {
        let a = frame.map(kin.part_point(p.point(s.from)));
        let mut b = frame.map(kin.part_point(p.point(s.to)));
        b[1] = frame.unwrap_near(b[1], a[1]);
        if (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-9 {
            continue;
        }
        let ply = match regions.get(s.line as usize) {
            Some(crate::program::Region::OnPart(k)) if s.on_part => p.courses.get(*k).map(|c| c.ply).or(Some(0)),
            _ if s.on_part => Some(0),
            _ => None,
        };
        match out.last_mut() {
            Some((q, pts))
                if *q == ply && pts.last().is_some_and(|l| (l[0] - a[0]).abs() + (l[1] - a[1]).abs() < 1e-9) =>
            {
                pts.push(b)
            }
            _ => out.push((ply, vec![a, b])),
        }
    }
    out
}

/// A round length for a scale bar about a fifth of `span`: 1, 2 or 5 times a power of ten.
fn scale_length(span: f64) -> f64 {
    let target = (span / 5.0).max(1e-9);
    let base = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|k| k * base).find(|&l| l <= target).unwrap_or(base)
}

fn plan_views(o: &Optimized, optimized: &Program, machine: &Machine) -> Option<String> {
    let kin = machine.kinematics()?;
    let frame = match &o.afp.footprints {
        Some(f) => f.frame,
        None => frame_for(&o.program, machine, &kin, None).unwrap_or(Frame::Plan),
    };
    let before = polylines(&o.program, machine, &frame);
    let after = polylines(optimized, machine, &frame);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (_, pts) in before.iter().chain(&after) {
        for p in pts {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    if !(lo[0].is_finite() && hi[0] > lo[0] - 1.0) {
        return None;
    }
    let (w, hgt) = ((hi[0] - lo[0]).max(1.0), (hi[1] - lo[1]).max(1.0));
    let pad = 0.08 * w.max(hgt);
    let stroke = 0.002 * w.max(hgt);
    let bar = scale_length(w);
    // Collisions (red) and near misses (orange) of each program, where a cell was given.
    let marks = |report: Option<&crate::safety::SafetyReport>| -> Vec<([f64; 2], &'static str, String)> {
        let Some(r) = report else { return Vec::new() };
        let mark = |i: &crate::safety::MoveIssue, colour: &'static str, what: &str| {
            (frame.map(i.at), colour, format!("line {}: {what}, {:.2} mm", i.line, i.clearance))
        };
        r.collisions
            .iter()
            .map(|i| mark(i, "#e00", "collision"))
            .chain(r.near_misses.iter().map(|i| mark(i, "#f90", "near miss")))
            .collect()
    };
    let marks_before = marks(o.safety.as_ref().map(|s| &s.before));
    let marks_after = marks(o.safety.as_ref().map(|s| &s.after));
    let view = |id: &str,
                lines: &[(Option<usize>, Vec<[f64; 2]>)],
                marks: &[([f64; 2], &'static str, String)],
                off_color: &str,
                caption: &str,
                value: String| {
        let mut s = String::new();
        let _ = write!(
            s,
            "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"560\" viewBox=\"{} {} {} {}\" style=\"background:#fff\">\
             <defs><marker id=\"arrow-{id}\" viewBox=\"0 0 10 10\" refX=\"5\" refY=\"5\" markerWidth=\"3\" markerHeight=\"3\" \
             orient=\"auto\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#222\"/></marker></defs><g transform=\"scale(1,-1)\">",
            lo[0] - pad,
            -hi[1] - pad,
            w + 2.0 * pad,
            hgt + 2.0 * pad
        );
        for (ply, pts) in lines {
            let d: Vec<String> = pts.iter().map(|p| format!("{:.1},{:.1}", p[0], p[1])).collect();
            let (color, width, arrow) = match ply {
                Some(k) => {
                    (PLY_COLOURS[k % PLY_COLOURS.len()], 4.0 * stroke, format!(" marker-end=\"url(#arrow-{id})\""))
                }
                None => (off_color, stroke, String::new()),
            };
            let _ = write!(
                s,
                "<polyline fill=\"none\" stroke=\"{color}\" stroke-width=\"{width:.2}\" stroke-linejoin=\"round\"{arrow} points=\"{}\"/>",
                d.join(" ")
            );
        }
        // Where the program starts: its first move's start.
        if let Some(p) = lines.first().and_then(|(_, pts)| pts.first()) {
            let _ = write!(
                s,
                "<circle class=\"start\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"{:.2}\" fill=\"#0a0\" stroke=\"#fff\" stroke-width=\"{:.2}\"/>",
                p[0],
                p[1],
                6.0 * stroke,
                stroke
            );
        }
        for (p, colour, title) in marks {
            let _ = write!(
                s,
                "<circle class=\"safety\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"{:.2}\" fill=\"none\" stroke=\"{colour}\" \
                 stroke-width=\"{:.2}\"><title>{}</title></circle>",
                p[0],
                p[1],
                9.0 * stroke,
                2.5 * stroke,
                esc(title)
            );
        }
        s.push_str("</g>");
        // Scale bar, below the drawing (unflipped coordinates).
        let (x0, y0) = (lo[0], -lo[1] + 0.55 * pad);
        let _ = write!(
            s,
            "<g class=\"scale\"><line x1=\"{x0:.1}\" y1=\"{y0:.1}\" x2=\"{:.1}\" y2=\"{y0:.1}\" stroke=\"#000\" stroke-width=\"{:.2}\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"{:.1}\" font-family=\"sans-serif\">{} mm</text></g>",
            x0 + bar,
            2.0 * stroke,
            x0 + bar + 0.1 * pad,
            y0 + 0.15 * pad,
            0.4 * pad,
            bar
        );
        let _ = write!(s, "</svg><figcaption>{caption}: {value}</figcaption></figure>");
        s
    };
    let off = |m: &[Motion]| {
        m.iter()
            .find(|x| x.kind == CostKind::Tool)
            .map_or(String::new(), |x| format!("off-part tool path {:.0} mm", x.off_part()))
    };
    let label = if matches!(frame, Frame::Cylinder { .. }) { " (cylinder unrolled)" } else { "" };
    let mut legend = String::from("<p class=\"legend\">");
    for (k, ply) in o.program.plies.iter().enumerate() {
        let _ = write!(
            legend,
            "<span><i style=\"background:{}\"></i>ply {}</span> ",
            PLY_COLOURS[k % PLY_COLOURS.len()],
            esc(&ply_name(ply))
        );
    }
    let _ = write!(
        legend,
        "<span><i style=\"background:#d22;height:2px\"></i>off-part before</span> \
         <span><i style=\"background:#14c;height:2px\"></i>off-part after</span> \
         <span><b style=\"color:#0a0\">●</b> start</span> <span>▶ course direction</span>"
    );
    if o.safety.is_some() {
        legend.push_str(
            " <span><b style=\"color:#e00\">○</b> collision</span> <span><b style=\"color:#f90\">○</b> near miss</span>",
        );
    }
    legend.push_str("</p>");
    Some(format!(
        "<div class=\"views\">{}{}</div>{legend}<p>Laid courses coloured by ply, an arrow at each course's end; \
         thin lines: off-part motion{label}; the bar gives the scale in mm.</p>",
        view("before", &before, &marks_before, "#d22", "before", off(&o.verification.before)),
        view("after", &after, &marks_after, "#14c", "after", off(&o.verification.after))
    ))
}

#[cfg(test)]
mod tests {
    use super::scale_length;

    /// The scale bar is 1, 2 or 5 times a power of ten, at most a fifth of the span and more
    /// than half of that fifth's largest such length.
    #[test]
    fn scale_bars_are_round_and_about_a_fifth() {
        for (span, want) in [(1000.0, 200.0), (1200.0, 200.0), (2600.0, 500.0), (49.0, 5.0), (5.0, 1.0), (0.9, 0.1)] {
            assert!((scale_length(span) - want).abs() < 1e-9 * want, "{span}: {}", scale_length(span));
        }
        for span in [3.0, 17.0, 480.0, 7777.0] {
            let l = scale_length(span);
            assert!(l <= span / 5.0 + 1e-9 && l > span / 5.0 / 2.5, "{span}: {l}");
        }
    }
}
