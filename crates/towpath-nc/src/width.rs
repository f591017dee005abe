//! Which course width a run uses, where it came from, and whether it is plausible beside the
//! dialect's.
//!
//! A width given with the run (on the command line, say) overrides the dialect's; the dialect's
//! is used otherwise; with neither there is none (enough for one ply, or ply by ply). A given
//! width that differs from the dialect's by more than [`PLAUSIBLE_FACTOR`] is used all the same,
//! with a warning: it is most often a width in other units (an inch user's `0.25` beside the
//! dialect's 6.35 mm), and a too narrow width silently loses precedence between plies.

use serde::Serialize;

use crate::dialect::Dialect;
use crate::footprint::Width;
use crate::program::Program;

/// A width given with the run may differ from the dialect's by at most this factor (either
/// way) without a warning.
pub const PLAUSIBLE_FACTOR: f64 = 2.0;

/// Where the width came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WidthSource {
    /// Given with the run (the command line's `--tow-width` or `--course-width`).
    Given,
    /// The dialect's `course_width` or `tow_width`.
    Dialect,
    /// None anywhere: the run needs no footprints.
    Default,
}

/// The width a run used.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthUsed {
    /// The width, if any.
    pub width: Option<Width>,
    /// Where it came from.
    pub source: WidthSource,
    /// The dialect's width, if it has one.
    pub dialect: Option<Width>,
    /// A warning when the width given disagrees with the dialect's by more than
    /// [`PLAUSIBLE_FACTOR`].
    pub warning: Option<String>,
}

impl WidthUsed {
    /// The width for `given` (if any) and the dialect, checked against the dialect's on this
    /// program (a tow width compares with a course width through the most tows the program lays
    /// at once).
    pub fn choose(given: Option<Width>, dialect: &Dialect, program: &Program) -> Self {
        let of_dialect = dialect.course_width.map(Width::Course).or(dialect.tow_width.map(Width::Tow));
        let (width, source) = match (given, of_dialect) {
            (Some(w), _) => (Some(w), WidthSource::Given),
            (None, Some(w)) => (Some(w), WidthSource::Dialect),
            (None, None) => (None, WidthSource::Default),
        };
        let warning = match (given, of_dialect) {
            (Some(g), Some(d)) => disagreement(g, d, max_tows(program)),
            _ => None,
        };
        WidthUsed { width, source, dialect: of_dialect, warning }
    }

    /// The width in words: `tow width 6.35 mm` or `course width 50.8 mm`, or `none`.
    pub fn describe(&self) -> String {
        match self.width {
            Some(w) => describe(w),
            None => "none".into(),
        }
    }
}

fn describe(w: Width) -> String {
    match w {
        Width::Tow(t) => format!("tow width {t} mm"),
        Width::Course(c) => format!("course width {c} mm"),
    }
}

/// The most tows the program has on during one laid move.
fn max_tows(program: &Program) -> u32 {
    program.segments.iter().filter(|s| s.on_part).map(|s| s.mask.count_ones()).max().unwrap_or(0)
}

/// A warning if `given` and the dialect's `dialect` width differ by more than the plausible
/// factor (compared as course widths: a tow width times `tows`).
fn disagreement(given: Width, dialect: Width, tows: u32) -> Option<String> {
    let as_course = |w: Width| match w {
        Width::Course(c) => Some(c),
        Width::Tow(t) if tows > 0 => Some(t * tows as f64),
        Width::Tow(_) => None,
    };
    let (g, d) = match (given, dialect) {
        (Width::Tow(a), Width::Tow(b)) | (Width::Course(a), Width::Course(b)) => (a, b),
        _ => (as_course(given)?, as_course(dialect)?),
    };
    if !(g > 0.0 && d > 0.0) {
        return None;
    }
    let ratio = if g > d { g / d } else { d / g };
    if ratio <= PLAUSIBLE_FACTOR {
        return None;
    }
    let unit_hint = [(25.4, "inches"), (1000.0, "metres"), (10.0, "centimetres")]
        .iter()
        .find(|(f, _)| ((g * f) / d - 1.0).abs() < 0.01)
        .map(|(f, name)| format!("; if it is in {name}, it is {} mm", crate::reverse::fmt_num(g * f, 4)))
        .unwrap_or_default();
    Some(format!(
        "the {} given is {} times {} than the dialect's {}{unit_hint}; the width given is used (widths are in mm)",
        describe(given),
        crate::reverse::fmt_num(ratio, 2),
        if g < d { "narrower" } else { "wider" },
        describe(dialect),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_far_from_the_dialect_s_are_flagged() {
        // An inch user's tow width beside a millimetre dialect.
        let w = disagreement(Width::Tow(0.25), Width::Tow(6.35), 8).unwrap();
        assert!(w.contains("25.4 times narrower") && w.contains("if it is in inches, it is 6.35 mm"), "{w}");
        // A course width is compared through the most tows laid at once: 8 × 6.35 = 50.8.
        assert!(disagreement(Width::Course(50.8), Width::Tow(6.35), 8).is_none());
        assert!(disagreement(Width::Course(50.8), Width::Tow(6.35), 1).unwrap().contains("8 times wider"));
        // Within the plausible factor: quiet, either way.
        assert!(disagreement(Width::Tow(3.175), Width::Tow(6.35), 8).is_none());
        assert!(disagreement(Width::Tow(12.7), Width::Tow(6.35), 8).is_none());
        assert!(disagreement(Width::Tow(12.8), Width::Tow(6.35), 8).is_some());
        // A tow width cannot be compared without tows.
        assert!(disagreement(Width::Course(50.8), Width::Tow(6.35), 0).is_none());
    }
}
