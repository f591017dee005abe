//! The line interpreter: applies one program line to the modal machine state.
//!
//! It knows the dialect's words and the machine's axes, tracks programmed and physical axis
//! values (they differ after a set-position line, and for continuous axes moved by a roll-over
//! controller), the distance mode, the motion mode, the feed, roller contact and the tows on,
//! and refuses what a machine could not do (cutting tows that are not on, lifting with tows
//! on, axis words without a motion mode, unknown axes) with a message naming the line.

use towpath_machine::{AxisKind, Machine};

use crate::dialect::{Codes, Dialect, EventTiming};
use crate::error::NcError;
use crate::lex::{lex, Lexed, NumText, Word};

/// Largest axis value accepted, in mm or degrees.
pub const MAX_AXIS_VALUE: f64 = 1e7;

/// Letters that address axes in ISO programs; one of these on a motion line that the machine
/// does not have is an unknown axis.
const AXIS_LETTERS: &str = "XYZABCUVW";

/// The modal state of the machine between two lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Modal {
    /// Programmed axis values (the values lines write).
    pub prog: Vec<f64>,
    /// The text of each axis's value as last written in absolute mode (`None` if computed).
    pub text: Vec<Option<NumText>>,
    /// Physical axis values, unwound (continuous axes may exceed 360°).
    pub phys: Vec<f64>,
    /// Incremental distance mode.
    pub incremental: bool,
    /// Modal motion: `Some(true)` rapid, `Some(false)` feed, `None` not yet set.
    pub rapid: Option<bool>,
    /// Modal feed value and its text.
    pub feed: Option<(f64, NumText)>,
    /// Roller in contact.
    pub contact: bool,
    /// Tows on, as a bit set.
    pub mask: u64,
}

impl Modal {
    /// The state before a program runs: every axis at home, nothing set.
    pub fn home(machine: &Machine) -> Self {
        let h = machine.home();
        Modal {
            prog: h.clone(),
            text: vec![None; h.len()],
            phys: h,
            incremental: false,
            rapid: None,
            feed: None,
            contact: false,
            mask: 0,
        }
    }

    /// Physical minus programmed value of each axis (the set-position offset).
    pub fn offset(&self, i: usize) -> f64 {
        self.phys[i] - self.prog[i]
    }
}

/// A contact or tow event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// Roller contact on (true) or off.
    Contact(bool),
    /// Tows restarted (true) or cut, with their mask.
    Tow(bool, u64),
}

/// A comment marking a ply or a course.
#[derive(Clone, Debug, PartialEq)]
pub enum Marker {
    /// Start of a ply: its number, if any, and the comment text.
    Ply(Option<i64>, String),
    /// Start of a course: its number, if any.
    Course(Option<i64>),
}

/// What one line did.
#[derive(Clone, Debug, Default)]
pub struct Applied {
    /// The lexed line (`None` if it could not be lexed; it is then kept as it is).
    pub lexed: Option<Lexed>,
    /// The line moved the axes: true for rapid, false for feed.
    pub motion: Option<bool>,
    /// Events before the move (or the line's only events if it does not move).
    pub before: Vec<Event>,
    /// Events after the move.
    pub after: Vec<Event>,
    /// A ply or course marker in the line's comments.
    pub marker: Option<Marker>,
    /// The line has words or text the dialect does not understand.
    pub unknown: bool,
    /// The line sets positions (G92-style).
    pub set_position: bool,
    /// The line changes the distance mode, motion mode or feed.
    pub modal: bool,
    /// The line carries tow or contact codes.
    pub events: bool,
}

impl Applied {
    /// All events, in order.
    pub fn events(&self) -> impl Iterator<Item = &Event> {
        self.before.iter().chain(self.after.iter())
    }
}

/// Applies lines to a [`Modal`] state.
#[derive(Clone, Debug)]
pub struct Interp<'a> {
    codes: Codes,
    dialect: &'a Dialect,
    letters: Vec<char>,
    kinds: Vec<AxisKind>,
    non_motion: Vec<crate::dialect::Code>,
    /// The current state.
    pub m: Modal,
}

impl<'a> Interp<'a> {
    /// An interpreter for a dialect and machine, starting at the machine's home state.
    pub fn new(dialect: &'a Dialect, machine: &Machine) -> Result<Self, NcError> {
        let codes = dialect.codes()?;
        let reserved = [codes.feed_word, codes.line_number_word, codes.mask_word, 'G', 'M'];
        let mut letters = Vec::new();
        for a in &machine.axes {
            let mut c = a.label.chars();
            let l = match (c.next(), c.next()) {
                (Some(l), None) if l.is_ascii_alphabetic() => l.to_ascii_uppercase(),
                _ => {
                    return Err(NcError::Machine(format!(
                        "axis label {:?} cannot be written in this dialect: labels must be single letters",
                        a.label
                    )))
                }
            };
            if reserved.contains(&l) {
                return Err(NcError::Machine(format!("axis label {l} is a word the dialect uses for something else")));
            }
            letters.push(l);
        }
        let non_motion = dialect
            .non_motion_codes
            .iter()
            .map(|c| {
                crate::dialect::Code::parse(c)
                    .ok_or_else(|| NcError::Dialect(format!("non_motion_codes: {c:?} is not a code like G4")))
            })
            .collect::<Result<_, _>>()?;
        Ok(Interp {
            codes,
            dialect,
            letters,
            kinds: machine.axes.iter().map(|a| a.kind).collect(),
            non_motion,
            m: Modal::home(machine),
        })
    }

    /// The axis index of a letter, if the machine has it.
    pub fn axis_of(&self, letter: char) -> Option<usize> {
        self.letters.iter().position(|&l| l == letter)
    }

    /// The axis letters, in machine order.
    pub fn letters(&self) -> &[char] {
        &self.letters
    }

    /// True if the dialect has roller contact codes.
    pub fn has_contact(&self) -> bool {
        self.codes.contact.is_some()
    }

    /// Applies line `line` (0-based index, for messages) with text `text`.
    pub fn apply(&mut self, line: usize, text: &str) -> Result<Applied, NcError> {
        let n = line + 1;
        let lexed = match lex(text, self.dialect.comment_parens, self.dialect.comment_semicolon) {
            Ok(l) => l,
            Err(issue) => {
                if let Some(l) = issue.letter {
                    if self.axis_of(l).is_some() {
                        return Err(NcError::line(n, format!("{} (axis words need plain numbers)", issue.message)));
                    }
                    if l == 'G' || l == self.codes.feed_word {
                        return Err(NcError::line(n, issue.message));
                    }
                }
                if self.m.contact || self.m.mask != 0 {
                    return Err(NcError::line(n, format!("{} inside a course", issue.message)));
                }
                return Ok(Applied { unknown: true, ..Applied::default() });
            }
        };
        let mut out = Applied { marker: self.marker(&lexed.comments), ..Applied::default() };

        let c = &self.codes;
        let mut motion_code: Option<bool> = None;
        let mut distance: Option<bool> = None;
        let mut set_pos = false;
        let mut feed: Option<&Word> = None;
        let mut contact_on = false;
        let mut contact_off = false;
        let mut restart = false;
        let mut cut = false;
        let mut mask: Option<&Word> = None;
        let mut axes: Vec<(usize, &Word)> = Vec::new();
        let mut other_g: Option<&Word> = None;
        let mut passthrough = false;
        for w in &lexed.words {
            let l = w.letter;
            if l == 'G' {
                if c.rapid.iter().any(|k| k.matches(l, w.value)) {
                    set_once(&mut motion_code, true, n, "two motion codes")?;
                } else if c.feed.iter().any(|k| k.matches(l, w.value)) {
                    set_once(&mut motion_code, false, n, "two motion codes")?;
                } else if c.absolute.matches(l, w.value) {
                    set_once(&mut distance, false, n, "two distance modes")?;
                } else if c.incremental.matches(l, w.value) {
                    set_once(&mut distance, true, n, "two distance modes")?;
                } else if c.set_position.matches(l, w.value) {
                    set_pos = true;
                } else {
                    if self.non_motion.iter().any(|k| k.matches(l, w.value)) {
                        passthrough = true;
                    }
                    other_g = other_g.or(Some(w));
                    out.unknown = true;
                }
            } else if l == 'M' {
                match &c.contact {
                    Some((on, _)) if on.matches(l, w.value) => contact_on = true,
                    Some((_, off)) if off.matches(l, w.value) => contact_off = true,
                    _ if c.restart.matches(l, w.value) => restart = true,
                    _ if c.cut.matches(l, w.value) => cut = true,
                    _ => out.unknown = true,
                }
            } else if l == c.feed_word {
                if feed.is_some() {
                    return Err(NcError::line(n, format!("two {l} words")));
                }
                feed = Some(w);
            } else if l == c.line_number_word {
                // Line numbers stay with their line.
            } else if let Some(i) = self.axis_of(l) {
                if axes.iter().any(|(j, _)| *j == i) {
                    return Err(NcError::line(n, format!("axis {l} is written twice")));
                }
                axes.push((i, w));
            } else if l == c.mask_word && (restart || cut || lexed.words.iter().any(|x| is_tow(c, x))) {
                mask = Some(w);
            } else {
                if AXIS_LETTERS.contains(l) && !passthrough && !lexed.words.iter().any(|x| self.is_non_motion(x)) {
                    return Err(NcError::line(
                        n,
                        format!(
                            "unknown axis {l}: the machine has {}",
                            self.letters.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(", ")
                        ),
                    ));
                }
                out.unknown = true;
            }
        }
        let passthrough = passthrough || lexed.words.iter().any(|x| self.is_non_motion(x));

        // Modal words first.
        if let Some(inc) = distance {
            self.m.incremental = inc;
            out.modal = true;
        }
        if let Some(r) = motion_code {
            if set_pos {
                return Err(NcError::line(n, "a set-position code and a motion code on one line"));
            }
            self.m.rapid = Some(r);
            out.modal = true;
        }
        if let Some(f) = feed {
            if f.value <= 0.0 || f.value.is_nan() {
                return Err(NcError::line(n, format!("feed {}{} must be > 0", f.letter, f.text)));
            }
            self.m.feed = Some((f.value, f.text));
            out.modal = true;
        }
        for (_, w) in &axes {
            if w.value.abs() > MAX_AXIS_VALUE {
                return Err(NcError::line(n, format!("{}{} is out of range (|value| ≤ 1e7)", w.letter, w.text)));
            }
        }

        // Events.
        let mut events = Vec::new();
        if contact_on {
            events.push(Event::Contact(true));
        }
        if restart && cut {
            return Err(NcError::line(n, "a tow restart and a tow cut on one line"));
        }
        if restart || cut {
            let Some(mw) = mask else {
                return Err(NcError::line(
                    n,
                    format!("tow {} without a {} mask word", if restart { "restart" } else { "cut" }, c.mask_word),
                ));
            };
            let v = mw.value;
            if !(v >= 1.0 && v.fract() == 0.0 && v < 9.0e15) {
                return Err(NcError::line(n, format!("tow mask {}{} must be a whole number ≥ 1", mw.letter, mw.text)));
            }
            events.push(Event::Tow(restart, v as u64));
        }
        if contact_off {
            events.push(Event::Contact(false));
        }
        out.events = !events.is_empty();
        if !axes.is_empty() && !events.is_empty() && set_pos {
            return Err(NcError::line(n, "tow or contact codes on a set-position line"));
        }

        if set_pos {
            if axes.is_empty() {
                return Err(NcError::line(n, "set-position code without axis words"));
            }
            for (i, w) in &axes {
                self.m.prog[*i] = w.value;
                self.m.text[*i] = Some(w.text);
            }
            out.set_position = true;
        } else if !axes.is_empty() && passthrough {
            // A dwell or similar: the words are not positions.
            out.unknown = true;
        } else if !axes.is_empty() {
            if let Some(g) = other_g {
                return Err(NcError::line(
                    n,
                    format!("G{} with axis words: the dialect knows only rapid and feed moves here", g.text),
                ));
            }
            let Some(rapid) = self.m.rapid else {
                return Err(NcError::line(n, "axis words but no motion mode (rapid or feed) is active"));
            };
            if !rapid && self.m.feed.is_none() {
                return Err(NcError::line(n, "a feed move with no feed rate set"));
            }
            let timing = self.dialect.event_timing;
            if timing == EventTiming::Before {
                self.events(n, &events)?;
                out.before = events.clone();
            }
            for (i, w) in &axes {
                let (target, text) =
                    if self.m.incremental { (self.m.prog[*i] + w.value, None) } else { (w.value, Some(w.text)) };
                // Physical value: the programmed one plus the set-position offset (kept exact
                // when there is none), or, for a roll-over controller, the short way round.
                let offset = self.m.phys[*i] - self.m.prog[*i];
                if !self.m.incremental && self.dialect.rollover && self.kinds[*i].wraps() {
                    self.m.phys[*i] += wrap(target - self.m.prog[*i]);
                } else if offset == 0.0 {
                    self.m.phys[*i] = target;
                } else {
                    self.m.phys[*i] = target + offset;
                }
                self.m.prog[*i] = target;
                self.m.text[*i] = text;
                if self.m.prog[*i].abs() > MAX_AXIS_VALUE || self.m.phys[*i].abs() > 1e9 {
                    return Err(NcError::line(n, format!("axis {} leaves the accepted range", w.letter)));
                }
            }
            out.motion = Some(rapid);
            if timing == EventTiming::After {
                self.events(n, &events)?;
                out.after = events;
            }
            out.lexed = Some(lexed);
            return Ok(out);
        }
        self.events(n, &events)?;
        out.before = events;
        out.lexed = Some(lexed);
        Ok(out)
    }

    fn is_non_motion(&self, w: &Word) -> bool {
        w.letter == 'G' && self.non_motion.iter().any(|k| k.matches('G', w.value))
    }

    fn events(&mut self, n: usize, events: &[Event]) -> Result<(), NcError> {
        let has_contact = self.codes.contact.is_some();
        for e in events {
            match *e {
                Event::Contact(true) => {
                    if self.m.contact {
                        return Err(NcError::line(n, "roller contact on again without a lift in between"));
                    }
                    self.m.contact = true;
                }
                Event::Contact(false) => {
                    if self.m.mask != 0 {
                        return Err(NcError::line(
                            n,
                            format!("roller lifted with tows still on (mask {})", self.m.mask),
                        ));
                    }
                    self.m.contact = false;
                }
                Event::Tow(true, mask) => {
                    if has_contact && !self.m.contact {
                        return Err(NcError::line(n, "tows restarted while the roller is lifted"));
                    }
                    if self.m.mask & mask != 0 {
                        return Err(NcError::line(
                            n,
                            format!("tow restart of tows already on (mask {} while {} are on)", mask, self.m.mask),
                        ));
                    }
                    self.m.mask |= mask;
                }
                Event::Tow(false, mask) => {
                    if self.m.mask == 0 {
                        return Err(NcError::line(n, format!("tow cut (mask {mask}) with no tows on")));
                    }
                    if self.m.mask & mask != mask {
                        return Err(NcError::line(
                            n,
                            format!("tow cut of tows that are not on (mask {} while {} are on)", mask, self.m.mask),
                        ));
                    }
                    self.m.mask &= !mask;
                }
            }
        }
        Ok(())
    }

    fn marker(&self, comments: &[String]) -> Option<Marker> {
        for text in comments {
            let t = text.trim();
            if let Some(rest) = strip_prefix_ci(t, &self.dialect.ply_comment) {
                return Some(Marker::Ply(leading_int(rest), t.to_string()));
            }
            if !self.dialect.course_comment.trim().is_empty() {
                if let Some(rest) = strip_prefix_ci(t, &self.dialect.course_comment) {
                    return Some(Marker::Course(leading_int(rest)));
                }
            }
        }
        None
    }
}

fn is_tow(c: &Codes, w: &Word) -> bool {
    w.letter == 'M' && (c.restart.matches('M', w.value) || c.cut.matches('M', w.value))
}

fn set_once<T: PartialEq + Copy>(slot: &mut Option<T>, v: T, n: usize, what: &str) -> Result<(), NcError> {
    match slot {
        Some(old) if *old != v => Err(NcError::line(n, format!("{what} on one line"))),
        _ => {
            *slot = Some(v);
            Ok(())
        }
    }
}

/// Wraps degrees to (−180, 180].
pub(crate) fn wrap(d: f64) -> f64 {
    let r = d - 360.0 * (d / 360.0).round();
    if r <= -180.0 {
        r + 360.0
    } else if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}

/// Strips `prefix` (case-insensitive) if the text starts with it followed by the end, a space,
/// a digit or punctuation (so `PLYWOOD` is not a ply marker).
fn strip_prefix_ci<'t>(text: &'t str, prefix: &str) -> Option<&'t str> {
    let p = prefix.trim();
    if p.is_empty() || text.len() < p.len() || !text.is_char_boundary(p.len()) {
        return None;
    }
    let (head, rest) = text.split_at(p.len());
    if !head.eq_ignore_ascii_case(p) {
        return None;
    }
    match rest.chars().next() {
        None => Some(rest),
        Some(ch) if !ch.is_ascii_alphabetic() => Some(rest),
        _ => None,
    }
}

fn leading_int(rest: &str) -> Option<i64> {
    let t = rest.trim_start_matches(|c: char| c.is_whitespace() || c == ':' || c == '#' || c == '=');
    let end = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    t[..end].parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use towpath_machine::Axis;

    fn machine() -> Machine {
        Machine::new(
            "m",
            vec![
                Axis::new("X", AxisKind::Linear),
                Axis::new("Y", AxisKind::Linear),
                Axis::new("A", AxisKind::Continuous),
            ],
        )
        .unwrap()
    }

    #[test]
    fn modal_state_is_tracked() {
        let d = Dialect::default();
        let m = machine();
        let mut it = Interp::new(&d, &m).unwrap();
        assert!(it.apply(0, "G0 X10 Y5").unwrap().motion == Some(true));
        assert_eq!(it.m.prog, vec![10.0, 5.0, 0.0]);
        it.apply(1, "G91").unwrap();
        it.apply(2, "G1 X1 F100").unwrap();
        assert_eq!(it.m.prog[0], 11.0);
        assert_eq!(it.m.text[0], None);
        it.apply(3, "G90 A350").unwrap();
        it.apply(4, "G92 A-10").unwrap();
        assert_eq!((it.m.prog[2], it.m.phys[2]), (-10.0, 350.0));
        it.apply(5, "A10").unwrap();
        assert_eq!(it.m.phys[2], 370.0);
    }

    #[test]
    fn tows_and_contact_are_checked() {
        let d = Dialect::default();
        let m = machine();
        let mut it = Interp::new(&d, &m).unwrap();
        let e = it.apply(0, "M61 P3").unwrap_err();
        assert_eq!(e.to_string(), "line 1: tow cut (mask 3) with no tows on");
        let e = it.apply(1, "M60 P3").unwrap_err();
        assert!(e.to_string().contains("roller is lifted"), "{e}");
        it.apply(2, "M20").unwrap();
        it.apply(3, "M60 P3").unwrap();
        assert!(it.apply(4, "M61 P4").unwrap_err().to_string().contains("not on"));
        assert!(it.apply(5, "M21").unwrap_err().to_string().contains("tows still on"));
        assert!(it.apply(6, "M60 P1").unwrap_err().to_string().contains("already on"));
        it.apply(7, "M61 P3").unwrap();
        it.apply(8, "M21").unwrap();
        assert!(it.apply(9, "M60").unwrap_err().to_string().contains("mask"));
    }

    #[test]
    fn bad_input_names_the_line() {
        let d = Dialect::default();
        let m = machine();
        let mut it = Interp::new(&d, &m).unwrap();
        assert!(it.apply(0, "X10").unwrap_err().to_string().contains("no motion mode"));
        assert!(it.apply(1, "G0 Z10").unwrap_err().to_string().starts_with("line 2: unknown axis Z"));
        assert!(it.apply(2, "G2 X10").unwrap_err().to_string().contains("G2 with axis words"));
        assert!(it.apply(3, "G0 X#1").is_err());
        assert!(it.apply(4, "G0 X99999999").unwrap_err().to_string().contains("range"));
        assert!(it.apply(5, "G1 X3").unwrap_err().to_string().contains("no feed"));
        // Unknown but harmless lines are kept.
        let a = it.apply(6, "%").unwrap();
        assert!(a.unknown);
        let a = it.apply(7, "G4 P1 S300").unwrap();
        assert!(a.unknown && a.motion.is_none());
        let a = it.apply(8, "(PLY 3 angle 45)").unwrap();
        assert_eq!(a.marker, Some(Marker::Ply(Some(3), "PLY 3 angle 45".into())));
        assert_eq!(it.apply(9, "(plywood)").unwrap().marker, None);
        assert_eq!(it.apply(10, "(COURSE)").unwrap().marker, Some(Marker::Course(None)));
    }
}
