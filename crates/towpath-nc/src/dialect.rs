//! Program dialects: which words and markers mean what. `docs/dialect.md` documents every key;
//! [`Dialect::default`] is the reference dialect (ISO G-code, `G0`/`G1`, `M20`/`M21` roller
//! contact, `M60`/`M61 P<mask>` tow restart/cut, `(PLY n)` and `(COURSE n)` comments).

use serde::{Deserialize, Serialize};

use crate::error::NcError;

/// A word code such as `G1` or `M60`: a letter and a number (`G01` equals `G1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Code {
    /// The letter, upper case.
    pub letter: char,
    /// The number.
    pub number: f64,
}

impl Code {
    /// Parses `"G1"`, `"m60"`, `"G64.1"`. Returns `None` for anything else.
    pub fn parse(text: &str) -> Option<Code> {
        let text = text.trim();
        let mut chars = text.chars();
        let letter = chars.next()?.to_ascii_uppercase();
        if !letter.is_ascii_alphabetic() {
            return None;
        }
        let rest = chars.as_str();
        if rest.is_empty() || !rest.chars().all(|c| c.is_ascii_digit() || c == '.') {
            return None;
        }
        let number: f64 = rest.parse().ok()?;
        Some(Code { letter, number })
    }

    /// True if a word (letter, value) is this code.
    #[inline]
    pub fn matches(&self, letter: char, value: f64) -> bool {
        self.letter == letter && self.number == value
    }
}

impl std::fmt::Display for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{}", self.letter, self.number)
    }
}

/// Where tow and contact codes written on a motion line take effect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EventTiming {
    /// At the start of the line's move.
    Before,
    /// At the end of the line's move (default).
    After,
}

/// The unit of programmed feeds: per minute (ISO G-code: mm/min, or deg/min for a move of
/// angular axes alone) or per second.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedUnit {
    /// Units per minute (the default).
    PerMinute,
    /// Units per second.
    PerSecond,
}

/// A clearance for regenerated transits: the axis and the value they go to before moving the
/// other axes (`clearance = { axis = "Z", value = 100.0 }`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clearance {
    /// The axis label, a linear axis of the machine (`"Z"`).
    pub axis: String,
    /// The axis value of the clearance, in program units (physical: set-position offsets
    /// apply as for any move).
    pub value: f64,
}

/// A pair of codes that switch something on and off along a course's path (a heater, a
/// cutter, coolant): `[[switch]]` in the dialect file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Switch {
    /// The code that switches it on (`"M8"`).
    pub on: String,
    /// The code that switches it off (`"M9"`).
    pub off: String,
}

fn s(x: &str) -> String {
    x.to_string()
}

/// A program dialect, read from TOML. Every key has a default: the reference dialect.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Dialect {
    /// Codes of rapid moves.
    pub rapid: Vec<String>,
    /// Codes of feed (linear interpolation) moves.
    pub feed: Vec<String>,
    /// Codes of clockwise arcs (centre by `I`/`J`/`K` offsets from the start, or radius `R`).
    /// Arcs are kept only inside on-part blocks, as they are; empty: arcs are refused.
    pub arc_cw: Vec<String>,
    /// Codes of counter-clockwise arcs.
    pub arc_ccw: Vec<String>,
    /// Plane selection codes for arcs, in the order XY, ZX, YZ (modal; XY at the start).
    pub arc_planes: Vec<String>,
    /// Absolute distance mode.
    pub absolute: String,
    /// Incremental distance mode.
    pub incremental: String,
    /// Set-position code (`G92 A10` declares the current position to be A10). towpath also
    /// writes it to unwind continuous axes after a short-way move.
    pub set_position: String,
    /// The feed-rate word letter.
    pub feed_word: String,
    /// The unit of feed values: per minute (mm/min, deg/min) or per second.
    pub feed_unit: FeedUnit,
    /// The line-number word letter (numbers are kept on the lines that have them).
    pub line_number_word: String,
    /// Roller contact on; empty when the machine has no contact codes (courses then run from
    /// the first tow restart to the cut of the last tow).
    pub contact_on: String,
    /// Roller contact off (lift).
    pub contact_off: String,
    /// Tow restart (add) code; its mask word gives the tows as a bit set.
    pub tow_restart: String,
    /// Tow cut code.
    pub tow_cut: String,
    /// The word carrying the tow mask on restart/cut lines.
    pub tow_mask_word: String,
    /// Comment prefix marking the start of a ply (`(PLY 3 ...)`).
    pub ply_comment: String,
    /// Comment prefix marking the start of a course (`(COURSE 12 ...)`); optional in programs.
    pub course_comment: String,
    /// Comments in parentheses.
    pub comment_parens: bool,
    /// Comments from `;` to the end of the line.
    pub comment_semicolon: bool,
    /// How many motion lines before roller contact form a course's approach block (kept with
    /// the course); earlier off-part motion is transit and is regenerated.
    pub approach_moves: usize,
    /// How many motion lines after the lift form a course's retract block.
    pub retract_moves: usize,
    /// True if the controller itself takes continuous axes the short way round (rotary
    /// roll-over); false if it moves by the literal difference of programmed values.
    pub rollover: bool,
    /// Where tow and contact codes written on a motion line take effect.
    pub event_timing: EventTiming,
    /// Tow width in mm (course width = tow width × tows on), if not given on the command line.
    pub tow_width: Option<f64>,
    /// Course width in mm, if not given on the command line.
    pub course_width: Option<f64>,
    /// Digits after the decimal point in numbers towpath writes.
    pub decimals: usize,
    /// G codes whose axis words are not positions (a dwell `G4 X2`): such lines are kept as
    /// they are and move nothing.
    pub non_motion_codes: Vec<String>,
    /// A clearance for the transits towpath writes: up to this value of this axis, across, and
    /// down (none: one straight rapid move).
    pub clearance: Option<Clearance>,
    /// M codes that act at their point of a course's path and mean the same whichever way the
    /// course is laid (a stop, a message to the operator): kept at their point when a course is
    /// reversed. Other codes towpath does not know keep a course forward.
    pub point_codes: Vec<String>,
    /// On/off pairs of M codes that switch something along a course's path: reversed, each
    /// pair's on and off lines trade places so the same stretch runs with it on.
    #[serde(rename = "switch")]
    pub switches: Vec<Switch>,
}

impl Default for Dialect {
    fn default() -> Self {
        Dialect {
            rapid: vec![s("G0")],
            feed: vec![s("G1")],
            arc_cw: vec![s("G2")],
            arc_ccw: vec![s("G3")],
            arc_planes: vec![s("G17"), s("G18"), s("G19")],
            absolute: s("G90"),
            incremental: s("G91"),
            set_position: s("G92"),
            feed_word: s("F"),
            feed_unit: FeedUnit::PerMinute,
            line_number_word: s("N"),
            contact_on: s("M20"),
            contact_off: s("M21"),
            tow_restart: s("M60"),
            tow_cut: s("M61"),
            tow_mask_word: s("P"),
            ply_comment: s("PLY"),
            course_comment: s("COURSE"),
            comment_parens: true,
            comment_semicolon: true,
            approach_moves: 1,
            retract_moves: 1,
            rollover: false,
            event_timing: EventTiming::After,
            tow_width: None,
            course_width: None,
            decimals: 4,
            non_motion_codes: vec![s("G4")],
            clearance: None,
            point_codes: Vec::new(),
            switches: Vec::new(),
        }
    }
}

/// A dialect with its codes parsed, ready for the parser.
#[derive(Clone, Debug)]
pub(crate) struct Codes {
    pub rapid: Vec<Code>,
    pub feed: Vec<Code>,
    pub arc_cw: Vec<Code>,
    pub arc_ccw: Vec<Code>,
    pub planes: Vec<Code>,
    pub absolute: Code,
    pub incremental: Code,
    pub set_position: Code,
    pub feed_word: char,
    pub line_number_word: char,
    pub contact: Option<(Code, Code)>,
    pub restart: Code,
    pub cut: Code,
    pub mask_word: char,
    /// G codes whose axis words are not positions (a dwell).
    pub non_motion: Vec<Code>,
    /// Codes that act at a point and mean the same either way.
    pub point: Vec<Code>,
    /// Switch pairs (on, off).
    pub switches: Vec<(Code, Code)>,
}

impl Dialect {
    /// Reads a dialect from TOML text (missing keys take the reference values).
    pub fn from_toml_str(text: &str) -> Result<Self, NcError> {
        let d: Dialect = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            NcError::Dialect(format!("line {line}: {}", e.message()))
        })?;
        d.codes()?;
        Ok(d)
    }

    /// Writes the dialect as TOML.
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Parses and checks the codes.
    pub(crate) fn codes(&self) -> Result<Codes, NcError> {
        let code = |key: &str, v: &str| {
            Code::parse(v).ok_or_else(|| NcError::Dialect(format!("{key}: {v:?} is not a code like G1 or M60")))
        };
        let letter = |key: &str, v: &str| {
            let mut c = v.chars();
            match (c.next(), c.next()) {
                (Some(l), None) if l.is_ascii_alphabetic() => Ok(l.to_ascii_uppercase()),
                _ => Err(NcError::Dialect(format!("{key}: {v:?} is not a single letter"))),
            }
        };
        let list = |key: &str, v: &[String]| -> Result<Vec<Code>, NcError> {
            if v.is_empty() {
                return Err(NcError::Dialect(format!("{key}: at least one code is needed")));
            }
            v.iter().map(|x| code(key, x)).collect()
        };
        let contact = match (self.contact_on.trim().is_empty(), self.contact_off.trim().is_empty()) {
            (true, true) => None,
            (false, false) => Some((code("contact_on", &self.contact_on)?, code("contact_off", &self.contact_off)?)),
            _ => return Err(NcError::Dialect("contact_on and contact_off must both be set or both be empty".into())),
        };
        for (k, w) in [("tow_width", self.tow_width), ("course_width", self.course_width)] {
            if let Some(w) = w {
                if !(w.is_finite() && w > 0.0) {
                    return Err(NcError::Dialect(format!("{k}: {w} is not a width > 0")));
                }
            }
        }
        if let Some(c) = &self.clearance {
            if !(c.value.is_finite() && c.value.abs() <= crate::interp::MAX_AXIS_VALUE) {
                return Err(NcError::Dialect(format!("clearance.value: {} is not a number within ±1e7", c.value)));
            }
            if c.axis.trim().is_empty() {
                return Err(NcError::Dialect("clearance.axis: name the axis (a linear axis of the machine)".into()));
            }
        }
        if self.decimals > 9 {
            return Err(NcError::Dialect(format!("decimals: {} is more than 9", self.decimals)));
        }
        if !self.comment_parens && !self.comment_semicolon {
            return Err(NcError::Dialect(
                "comments: enable comment_parens or comment_semicolon (markers are comments)".into(),
            ));
        }
        if self.ply_comment.trim().is_empty() {
            return Err(NcError::Dialect("ply_comment: must not be empty".into()));
        }
        let any = |key: &str, v: &[String]| -> Result<Vec<Code>, NcError> { v.iter().map(|x| code(key, x)).collect() };
        let planes = any("arc_planes", &self.arc_planes)?;
        if planes.len() != 3 {
            return Err(NcError::Dialect(format!(
                "arc_planes: give three codes (planes XY, ZX and YZ), not {}",
                planes.len()
            )));
        }
        let codes = Codes {
            rapid: list("rapid", &self.rapid)?,
            feed: list("feed", &self.feed)?,
            arc_cw: any("arc_cw", &self.arc_cw)?,
            arc_ccw: any("arc_ccw", &self.arc_ccw)?,
            planes,
            absolute: code("absolute", &self.absolute)?,
            incremental: code("incremental", &self.incremental)?,
            set_position: code("set_position", &self.set_position)?,
            feed_word: letter("feed_word", &self.feed_word)?,
            line_number_word: letter("line_number_word", &self.line_number_word)?,
            contact,
            restart: code("tow_restart", &self.tow_restart)?,
            cut: code("tow_cut", &self.tow_cut)?,
            mask_word: letter("tow_mask_word", &self.tow_mask_word)?,
            non_motion: self
                .non_motion_codes
                .iter()
                .map(|x| {
                    Code::parse(x)
                        .ok_or_else(|| NcError::Dialect(format!("non_motion_codes: {x:?} is not a code like G4")))
                })
                .collect::<Result<_, _>>()?,
            point: any("point_codes", &self.point_codes)?,
            switches: self
                .switches
                .iter()
                .enumerate()
                .map(|(i, sw)| {
                    Ok((code(&format!("switch[{i}].on"), &sw.on)?, code(&format!("switch[{i}].off"), &sw.off)?))
                })
                .collect::<Result<_, NcError>>()?,
        };
        self.check_roles(&codes)?;
        Ok(codes)
    }

    /// Every code has one role and the letter the interpreter reads it with (motion and mode
    /// codes are G codes, contact and tow codes M codes); the word letters differ from each
    /// other and from G and M; ply and course comments differ.
    fn check_roles(&self, c: &Codes) -> Result<(), NcError> {
        let non_motion = c.non_motion.clone();
        let mut roles: Vec<(&str, Code, char)> = Vec::new();
        for (key, list) in [
            ("rapid", &c.rapid),
            ("feed", &c.feed),
            ("arc_cw", &c.arc_cw),
            ("arc_ccw", &c.arc_ccw),
            ("arc_planes", &c.planes),
            ("non_motion_codes", &non_motion),
        ] {
            roles.extend(list.iter().map(|&x| (key, x, 'G')));
        }
        roles.push(("absolute", c.absolute, 'G'));
        roles.push(("incremental", c.incremental, 'G'));
        roles.push(("set_position", c.set_position, 'G'));
        if let Some((on, off)) = c.contact {
            roles.push(("contact_on", on, 'M'));
            roles.push(("contact_off", off, 'M'));
        }
        roles.push(("tow_restart", c.restart, 'M'));
        roles.push(("tow_cut", c.cut, 'M'));
        roles.extend(c.point.iter().map(|&x| ("point_codes", x, 'M')));
        let switch_keys: Vec<(String, String)> =
            (0..c.switches.len()).map(|i| (format!("switch[{i}].on"), format!("switch[{i}].off"))).collect();
        for ((on, off), (kon, koff)) in c.switches.iter().zip(&switch_keys) {
            roles.push((kon.as_str(), *on, 'M'));
            roles.push((koff.as_str(), *off, 'M'));
        }
        for (i, &(key, x, letter)) in roles.iter().enumerate() {
            if x.letter != letter {
                let article = if letter == 'M' { "an" } else { "a" };
                return Err(NcError::Dialect(format!(
                    "{key}: {x} is not {article} {letter} code (motion and mode codes are G codes, contact and tow codes M codes)"
                )));
            }
            let same = |&&(k, y, _): &&(&str, Code, char)| k != key && y == x;
            if let Some((other, ..)) = roles[..i].iter().find(same) {
                return Err(NcError::Dialect(format!("{key}: {x} is also the dialect's {other} code")));
            }
        }
        let words =
            [("feed_word", c.feed_word), ("line_number_word", c.line_number_word), ("tow_mask_word", c.mask_word)];
        for (i, &(key, l)) in words.iter().enumerate() {
            if l == 'G' || l == 'M' {
                return Err(NcError::Dialect(format!("{key}: {l} is the letter of G or M codes")));
            }
            if let Some((other, _)) = words[..i].iter().find(|w| w.1 == l) {
                return Err(NcError::Dialect(format!("{key}: {l} is also the {other}")));
            }
        }
        if self.ply_comment.trim().eq_ignore_ascii_case(self.course_comment.trim()) {
            return Err(NcError::Dialect(format!(
                "course_comment: {:?} is also the ply_comment: give courses another word (or \"\")",
                self.course_comment
            )));
        }
        Ok(())
    }

    /// The clearance of regenerated transits as (axis index, value) for this machine, if the
    /// dialect sets one; refused unless the axis is a linear axis of the machine.
    pub fn clearance_axis(&self, machine: &towpath_machine::Machine) -> Result<Option<(usize, f64)>, NcError> {
        let Some(c) = &self.clearance else { return Ok(None) };
        let Some(i) = machine.axis_index(c.axis.trim()) else {
            return Err(NcError::Dialect(format!("clearance.axis: the machine has no axis {:?}", c.axis)));
        };
        if machine.axes[i].kind != towpath_machine::AxisKind::Linear {
            return Err(NcError::Dialect(format!(
                "clearance.axis: {} is not a linear axis (transits go up and down on a linear axis)",
                machine.axes[i].label
            )));
        }
        Ok(Some((i, c.value)))
    }

    /// A programmed feed value in units per second.
    pub fn feed_per_second(&self, feed: f64) -> f64 {
        match self.feed_unit {
            FeedUnit::PerMinute => feed / 60.0,
            FeedUnit::PerSecond => feed,
        }
    }

    /// Writes a comment in this dialect's style.
    pub fn comment(&self, text: &str) -> String {
        if self.comment_parens {
            format!("({})", text.replace(['(', ')'], ""))
        } else {
            format!(";{text}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_compare_numerically() {
        let c = Code::parse("G01").unwrap();
        assert!(c.matches('G', 1.0));
        assert!(Code::parse("g64.1").unwrap().matches('G', 64.1));
        assert!(Code::parse("X").is_none());
        assert!(Code::parse("1G").is_none());
    }

    /// Every key of a dialect file has a row in docs/dialect.md, with its default.
    #[test]
    fn every_key_is_documented_with_its_default() {
        let docs = include_str!("../../../docs/dialect.md");
        let d = Dialect {
            tow_width: Some(1.0),
            course_width: Some(1.0),
            clearance: Some(Clearance { axis: "Z".into(), value: 1.0 }),
            ..Dialect::default()
        };
        let toml::Value::Table(t) = toml::from_str::<toml::Value>(&d.to_toml_string()).unwrap() else {
            panic!("a dialect is a table")
        };
        let reference: toml::Value = toml::from_str(&Dialect::default().to_toml_string()).unwrap();
        assert!(t.len() >= 24, "{t:?}");
        for k in t.keys() {
            let row = docs.lines().find(|l| l.starts_with(&format!("| `{k}` |")));
            let Some(row) = row else { panic!("key {k} is not documented in docs/dialect.md") };
            // The default column shows the reference value.
            let default = row.split('|').nth(2).unwrap_or("").trim().trim_matches('`').to_string();
            match reference.get(k) {
                Some(v) => {
                    let shown = match v {
                        toml::Value::String(s) => format!("\"{s}\""),
                        other => other.to_string().replace(", ", ","),
                    };
                    assert_eq!(default.replace(", ", ","), shown, "default of {k}");
                }
                None => assert_eq!(default, "none", "default of {k}"),
            }
        }
    }

    #[test]
    fn reference_dialect_round_trips_and_bad_keys_are_named() {
        let d = Dialect::default();
        assert_eq!(Dialect::from_toml_str(&d.to_toml_string()).unwrap(), d);
        let d = Dialect::from_toml_str("contact_on = \"\"\ncontact_off = \"\"\n").unwrap();
        assert!(d.codes().unwrap().contact.is_none());
        let e = Dialect::from_toml_str("rapid = [\"Q\"]").unwrap_err();
        assert!(e.to_string().contains("rapid"), "{e}");
        let e = Dialect::from_toml_str("\nrapidd = [\"G0\"]").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
        let e = Dialect::from_toml_str("contact_on = \"\"").unwrap_err();
        assert!(e.to_string().contains("both"), "{e}");
        let e = Dialect::from_toml_str("tow_width = -3.0").unwrap_err();
        assert!(e.to_string().contains("tow_width"), "{e}");
    }

    /// A code with two roles, a code with the wrong letter (the interpreter reads motion and mode
    /// codes only as G words, contact and tow codes only as M words), clashing word letters and
    /// one marker word for plies and courses are refused with the key, not left to misread
    /// programs.
    #[test]
    fn codes_with_two_roles_or_the_wrong_letter_are_refused() {
        let refused = |toml: &str, says: &str| {
            let e = Dialect::from_toml_str(toml).unwrap_err().to_string();
            assert!(e.contains(says), "{toml}: {e}");
        };
        refused("contact_on = \"M60\"", "tow_restart: M60 is also the dialect's contact_on code");
        refused("rapid = [\"G1\"]", "feed: G1 is also the dialect's rapid code");
        refused("tow_cut = \"M21\"", "tow_cut: M21 is also the dialect's contact_off code");
        refused("non_motion_codes = [\"G92\"]", "set_position: G92 is also the dialect's non_motion_codes code");
        refused("rapid = [\"M20\"]", "rapid: M20 is not a G code");
        refused("tow_restart = \"G60\"", "tow_restart: G60 is not an M code");
        refused("feed_word = \"P\"", "tow_mask_word: P is also the feed_word");
        refused("line_number_word = \"G\"", "line_number_word: G is the letter of G or M codes");
        refused("course_comment = \"ply\"", "course_comment: \"ply\" is also the ply_comment");
        // The same code twice in one role is harmless; G00 and G0 are one code.
        assert!(Dialect::from_toml_str("rapid = [\"G0\", \"G00\"]").is_ok());
        assert!(Dialect::from_toml_str("course_comment = \"\"").is_ok());
    }
}
