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

/// Largest axis value accepted, in mm or degrees (the machine file's range).
pub const MAX_AXIS_VALUE: f64 = towpath_machine::MAX_AXIS_VALUE;

/// Most chords a program's arcs may be split into (within [`ARC_CHORD_TOLERANCE`] each): the
/// bound on the memory the moves of a program's arcs take.
pub const MAX_ARC_CHORDS: usize = 1_000_000;

/// Words of an arc: centre offsets from the start (I along X, J along Y, K along Z) or radius.
const ARC_WORDS: &str = "IJKR";

/// How far (mm) an arc's end may be off its circle, as controllers allow.
pub const ARC_RADIUS_TOLERANCE: f64 = 0.01;

/// Largest distance (mm) between an arc and the chords towpath replaces it by for footprints
/// and costs.
pub const ARC_CHORD_TOLERANCE: f64 = 0.002;

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
    /// Modal motion mode (`None` until a line sets one).
    pub motion: Option<MotionMode>,
    /// Modal arc plane (G17/G18/G19; modal on its own, whatever the motion mode).
    pub plane: Plane,
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
            motion: None,
            plane: Plane::XY,
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

/// The plane of an arc, as the dialect's plane codes select it (G17, G18, G19).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Plane {
    /// The XY plane (G17), centre offsets I and J.
    #[default]
    XY,
    /// The ZX plane (G18), centre offsets K and I.
    ZX,
    /// The YZ plane (G19), centre offsets J and K.
    YZ,
}

impl Plane {
    /// The planes in the order of the dialect's `arc_planes` codes.
    pub const ALL: [Plane; 3] = [Plane::XY, Plane::ZX, Plane::YZ];

    /// The plane's position among the dialect's `arc_planes` codes.
    pub fn index(self) -> usize {
        match self {
            Plane::XY => 0,
            Plane::ZX => 1,
            Plane::YZ => 2,
        }
    }

    /// The plane's two axis letters (in the order that makes its arcs turn the G2/G3 way) and
    /// the centre-offset letters of each.
    pub fn letters(self) -> ([char; 2], [char; 2]) {
        match self {
            Plane::XY => (['X', 'Y'], ['I', 'J']),
            Plane::ZX => (['Z', 'X'], ['K', 'I']),
            Plane::YZ => (['Y', 'Z'], ['J', 'K']),
        }
    }
}

/// The turning sense of an arc, seen from the positive side of its plane's normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ArcDir {
    /// Clockwise (G2).
    Cw,
    /// Counter-clockwise (G3).
    Ccw,
}

/// A modal motion mode: what axis words on a line without a motion code do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MotionMode {
    /// Rapid positioning (G0).
    Rapid,
    /// Straight feed move (G1).
    Linear,
    /// Arc at the feed (G2/G3), in the modal [`Plane`].
    Arc(ArcDir),
}

impl MotionMode {
    /// True for rapid positioning.
    pub fn is_rapid(self) -> bool {
        self == MotionMode::Rapid
    }
}

/// The kind of move one line made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MoveKind {
    /// A rapid move.
    Rapid,
    /// A straight move at the feed.
    Linear,
    /// An arc at the feed, in its plane.
    Arc {
        /// Its turning sense.
        dir: ArcDir,
        /// Its plane.
        plane: Plane,
    },
}

impl MoveKind {
    /// True for a rapid move.
    pub fn is_rapid(self) -> bool {
        self == MoveKind::Rapid
    }

    /// True for an arc.
    pub fn is_arc(self) -> bool {
        matches!(self, MoveKind::Arc { .. })
    }
}

/// A contact or tow event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// Roller contact on.
    ContactOn,
    /// Roller lifted (contact off).
    ContactOff,
    /// Tows restarted, with their mask.
    TowRestart(u64),
    /// Tows cut, with their mask.
    TowCut(u64),
}

impl Event {
    /// True for roller contact on or off.
    pub fn is_contact(self) -> bool {
        matches!(self, Event::ContactOn | Event::ContactOff)
    }
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
    /// The move the line made, if it moved the axes.
    pub motion: Option<MoveKind>,
    /// Physical states the move passes through before its end point: an arc's tessellation
    /// (empty for a straight move).
    pub path: Vec<Vec<f64>>,
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

    /// True if the line made an arc.
    pub fn is_arc(&self) -> bool {
        self.motion.is_some_and(MoveKind::is_arc)
    }
}

/// The words of one line, sorted by what they do (the second phase of [`Interp::apply`]).
#[derive(Default)]
struct Words<'l> {
    motion: Option<MotionMode>,
    plane: Option<Plane>,
    arc_words: Vec<&'l Word>,
    /// `Some(true)` incremental, `Some(false)` absolute.
    distance: Option<bool>,
    set_pos: bool,
    feed: Option<&'l Word>,
    contact_on: bool,
    contact_off: bool,
    restart: bool,
    cut: bool,
    mask: Option<&'l Word>,
    axes: Vec<(usize, &'l Word)>,
    /// The first G word the dialect does not know.
    other_g: Option<&'l Word>,
    /// A non-motion code (dwell and such): the line's other words are its parameters.
    passthrough: bool,
}

/// Applies lines to a [`Modal`] state.
#[derive(Clone, Debug)]
pub struct Interp<'a> {
    codes: Codes,
    dialect: &'a Dialect,
    letters: Vec<char>,
    kinds: Vec<AxisKind>,
    non_motion: Vec<crate::dialect::Code>,
    /// Arc chords made so far.
    chords: usize,
    /// The current state.
    pub m: Modal,
}

impl<'a> Interp<'a> {
    /// An interpreter for a dialect and machine, starting at the machine's home state.
    pub fn new(dialect: &'a Dialect, machine: &Machine) -> Result<Self, NcError> {
        let codes = dialect.codes()?;
        dialect.clearance_axis(machine)?;
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
            chords: 0,
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
    ///
    /// In phases: lex the line, sort its words, apply its modal words, gather its events, then
    /// set positions or move (with the events before or after the move, as the dialect has it).
    pub fn apply(&mut self, line: usize, text: &str) -> Result<Applied, NcError> {
        let n = line + 1;
        let Some(lexed) = self.lex_line(n, text)? else {
            return Ok(Applied { unknown: true, ..Applied::default() });
        };
        let mut out = Applied { marker: self.marker(&lexed.comments), ..Applied::default() };
        let words = self.read_words(n, &lexed, &mut out)?;
        let arc_move = self.apply_modal(n, &words, &mut out)?;
        let events = self.line_events(n, &words)?;
        out.events = !events.is_empty();
        if !words.axes.is_empty() && !events.is_empty() && words.set_pos {
            return Err(NcError::line(n, "tow or contact codes on a set-position line"));
        }
        if words.set_pos {
            if words.axes.is_empty() {
                return Err(NcError::line(n, "set-position code without axis words"));
            }
            for (i, w) in &words.axes {
                self.m.prog[*i] = w.value;
                self.m.text[*i] = Some(w.text);
            }
            out.set_position = true;
        } else if !words.axes.is_empty() && words.passthrough {
            // A dwell or similar: the words are not positions.
            out.unknown = true;
        } else if !words.axes.is_empty() || arc_move {
            self.apply_move(n, &words, arc_move, events, &mut out)?;
            out.lexed = Some(lexed);
            return Ok(out);
        }
        self.events(n, &events)?;
        out.before = events;
        out.lexed = Some(lexed);
        Ok(out)
    }

    /// Phase 1 of [`Interp::apply`]: lexes the line. `None` for a line that cannot be lexed
    /// but may be kept as it is (outside a course, with no axis, G or feed word in the way).
    fn lex_line(&self, n: usize, text: &str) -> Result<Option<Lexed>, NcError> {
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
                    return Err(NcError::InCourse { line: n, message: issue.message });
                }
                return Ok(None);
            }
        };
        // `X1e308` or `F1.5E3`: a number in exponent notation, which G-code does not have (the
        // words read as X1 and E308). Refused rather than read as something else.
        if self.axis_of('E').is_none() {
            for w in lexed.words.windows(2) {
                let (a, b) = (&w[0], &w[1]);
                if b.letter == 'E'
                    && b.span.start == a.span.end
                    && (self.axis_of(a.letter).is_some() || a.letter == self.codes.feed_word)
                {
                    return Err(NcError::line(
                        n,
                        format!(
                            "{}: exponent notation is not G-code (it reads as {}{} and a word {}); write the number out",
                            &text[a.span.start..b.span.end],
                            a.letter,
                            a.text,
                            &text[b.span.clone()]
                        ),
                    ));
                }
            }
        }
        Ok(Some(lexed))
    }

    /// Phase 2 of [`Interp::apply`]: sorts the line's words by what they do, refusing words
    /// written twice, two codes of one modal group and unknown axes; marks the line unknown if
    /// it has words the dialect does not know.
    fn read_words<'l>(&self, n: usize, lexed: &'l Lexed, out: &mut Applied) -> Result<Words<'l>, NcError> {
        let c = &self.codes;
        let mut r = Words::default();
        for w in &lexed.words {
            let l = w.letter;
            if l == 'G' {
                if let Some(mode) = self.motion_code(w) {
                    set_once(&mut r.motion, mode, n, "two motion codes")?;
                } else if let Some(k) = c.planes.iter().position(|k| k.matches(l, w.value)) {
                    set_once(&mut r.plane, Plane::ALL[k % 3], n, "two arc planes")?;
                } else if c.absolute.matches(l, w.value) {
                    set_once(&mut r.distance, false, n, "two distance modes")?;
                } else if c.incremental.matches(l, w.value) {
                    set_once(&mut r.distance, true, n, "two distance modes")?;
                } else if c.set_position.matches(l, w.value) {
                    r.set_pos = true;
                } else {
                    if self.non_motion.iter().any(|k| k.matches(l, w.value)) {
                        r.passthrough = true;
                    }
                    r.other_g = r.other_g.or(Some(w));
                    out.unknown = true;
                }
            } else if l == 'M' {
                match &c.contact {
                    Some((on, _)) if on.matches(l, w.value) => r.contact_on = true,
                    Some((_, off)) if off.matches(l, w.value) => r.contact_off = true,
                    _ if c.restart.matches(l, w.value) => r.restart = true,
                    _ if c.cut.matches(l, w.value) => r.cut = true,
                    _ => out.unknown = true,
                }
            } else if l == c.feed_word {
                if r.feed.is_some() {
                    return Err(NcError::line(n, format!("two {l} words")));
                }
                r.feed = Some(w);
            } else if l == c.line_number_word {
                // Line numbers stay with their line.
            } else if let Some(i) = self.axis_of(l) {
                if r.axes.iter().any(|(j, _)| *j == i) {
                    return Err(NcError::line(n, format!("axis {l} is written twice")));
                }
                r.axes.push((i, w));
            } else if l == c.mask_word && (r.restart || r.cut || lexed.words.iter().any(|x| is_tow(c, x))) {
                r.mask = Some(w);
            } else if ARC_WORDS.contains(l) {
                if r.arc_words.iter().any(|x| x.letter == l) {
                    return Err(NcError::line(n, format!("{l} is written twice")));
                }
                r.arc_words.push(w);
            } else {
                if AXIS_LETTERS.contains(l) && !r.passthrough && !lexed.words.iter().any(|x| self.is_non_motion(x)) {
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
        r.passthrough = r.passthrough || lexed.words.iter().any(|x| self.is_non_motion(x));
        Ok(r)
    }

    /// The motion mode a G word selects, if it is one of the dialect's motion codes.
    fn motion_code(&self, w: &Word) -> Option<MotionMode> {
        let c = &self.codes;
        let is = |codes: &[crate::dialect::Code]| codes.iter().any(|k| k.matches(w.letter, w.value));
        if is(&c.rapid) {
            Some(MotionMode::Rapid)
        } else if is(&c.feed) {
            Some(MotionMode::Linear)
        } else if is(&c.arc_cw) {
            Some(MotionMode::Arc(ArcDir::Cw))
        } else if is(&c.arc_ccw) {
            Some(MotionMode::Arc(ArcDir::Ccw))
        } else {
            None
        }
    }

    /// Phase 3 of [`Interp::apply`]: applies the line's modal words (distance mode, motion
    /// mode, plane, feed) and checks its axis values' range. Returns whether the line is an
    /// arc move: axis words in arc mode, or centre words alone (a full circle where it stands).
    fn apply_modal(&mut self, n: usize, words: &Words, out: &mut Applied) -> Result<bool, NcError> {
        if let Some(inc) = words.distance {
            self.m.incremental = inc;
            out.modal = true;
        }
        if let Some(mode) = words.motion {
            if words.set_pos {
                return Err(NcError::line(n, "a set-position code and a motion code on one line"));
            }
            self.m.motion = Some(mode);
            out.modal = true;
        }
        if let Some(p) = words.plane {
            self.m.plane = p;
            out.modal = true;
        }
        let arc_move = matches!(self.m.motion, Some(MotionMode::Arc(_)))
            && (!words.axes.is_empty() || !words.arc_words.is_empty())
            && !words.set_pos
            && !words.passthrough
            && words.other_g.is_none();
        if !arc_move && !words.arc_words.is_empty() {
            // Centre or radius words on a line that is no arc: words towpath does not know.
            out.unknown = true;
        }
        if let Some(f) = words.feed {
            if f.value <= 0.0 || f.value.is_nan() {
                return Err(NcError::line(n, format!("feed {}{} must be > 0", f.letter, f.text)));
            }
            self.m.feed = Some((f.value, f.text));
            out.modal = true;
        }
        for (_, w) in &words.axes {
            if w.value.abs() > MAX_AXIS_VALUE {
                return Err(NcError::line(n, format!("{}{} is out of range (|value| ≤ 1e7)", w.letter, w.text)));
            }
        }
        Ok(arc_move)
    }

    /// Phase 4 of [`Interp::apply`]: the line's events, in the order they happen (contact on,
    /// tow restart or cut, contact off).
    fn line_events(&self, n: usize, words: &Words) -> Result<Vec<Event>, NcError> {
        let mut events = Vec::new();
        if words.contact_on {
            events.push(Event::ContactOn);
        }
        if words.restart && words.cut {
            return Err(NcError::line(n, "a tow restart and a tow cut on one line"));
        }
        if words.restart || words.cut {
            let Some(mw) = words.mask else {
                return Err(NcError::line(
                    n,
                    format!(
                        "tow {} without a {} mask word",
                        if words.restart { "restart" } else { "cut" },
                        self.codes.mask_word
                    ),
                ));
            };
            let v = mw.value;
            if !(v >= 1.0 && v.fract() == 0.0 && v < 9.0e15) {
                return Err(NcError::line(n, format!("tow mask {}{} must be a whole number ≥ 1", mw.letter, mw.text)));
            }
            events.push(if words.restart { Event::TowRestart(v as u64) } else { Event::TowCut(v as u64) });
        }
        if words.contact_off {
            events.push(Event::ContactOff);
        }
        Ok(events)
    }

    /// Phase 5 of [`Interp::apply`]: a move (straight, or an arc as its chords), with the
    /// line's events before or after it as the dialect's event timing says.
    fn apply_move(
        &mut self,
        n: usize,
        words: &Words,
        arc_move: bool,
        events: Vec<Event>,
        out: &mut Applied,
    ) -> Result<(), NcError> {
        if let Some(g) = words.other_g {
            return Err(NcError::line(
                n,
                format!("G{} with axis words: the dialect knows only rapid and feed moves here", g.text),
            ));
        }
        let Some(mode) = self.m.motion else {
            return Err(NcError::line(n, "axis words but no motion mode (rapid or feed) is active"));
        };
        if !mode.is_rapid() && self.m.feed.is_none() {
            return Err(NcError::line(n, "a feed move with no feed rate set"));
        }
        let timing = self.dialect.event_timing;
        if timing == EventTiming::Before {
            self.events(n, &events)?;
            out.before = events.clone();
        }
        if mode.is_rapid() {
            self.check_rapid(n)?;
        }
        // The state where an arc starts (straight moves need none).
        let start = if arc_move { Some((self.m.prog.clone(), self.m.phys.clone())) } else { None };
        if arc_move {
            let laying = if self.codes.contact.is_some() { self.m.contact } else { self.m.mask != 0 };
            if !laying {
                return Err(NcError::line(
                    n,
                    "an arc outside a course's on-part block: towpath keeps arcs only where material is laid \
                     (off-part motion is regenerated with straight moves)",
                ));
            }
        }
        self.move_axes(n, &words.axes)?;
        out.motion = Some(match mode {
            MotionMode::Rapid => MoveKind::Rapid,
            MotionMode::Linear => MoveKind::Linear,
            MotionMode::Arc(dir) => MoveKind::Arc { dir, plane: self.m.plane },
        });
        if let (MotionMode::Arc(dir), Some((prog, phys))) = (mode, &start) {
            out.path = self.arc_path(n, prog, phys, dir, &words.arc_words)?;
            self.chords += out.path.len() + 1;
            if self.chords > MAX_ARC_CHORDS {
                return Err(NcError::line(
                    n,
                    format!(
                        "the program's arcs need more than {MAX_ARC_CHORDS} chords to be followed within \
                         {ARC_CHORD_TOLERANCE} mm: too many arcs (or arcs too large) for towpath to read"
                    ),
                ));
            }
        }
        if timing == EventTiming::After {
            self.events(n, &events)?;
            out.after = events;
        }
        Ok(())
    }

    /// A rapid move may not touch the part: not with the roller in contact, nor (without
    /// contact codes) with tows on.
    fn check_rapid(&self, n: usize) -> Result<(), NcError> {
        let code = self.dialect.rapid.first().map_or("G0", String::as_str);
        if self.codes.contact.is_some() && self.m.contact {
            return Err(NcError::InCourse {
                line: n,
                message: format!(
                    "a rapid move ({code}) while the roller is in contact: rapids do not lay material or press the \
                     roller; write it as a feed move"
                ),
            });
        }
        if self.m.mask != 0 {
            return Err(NcError::InCourse {
                line: n,
                message: format!(
                    "a rapid move ({code}) while tows are on (mask {}): rapids do not lay material; write it as a \
                     feed move",
                    self.m.mask
                ),
            });
        }
        Ok(())
    }

    /// Moves the axes a line writes: programmed values (absolute or incremental) and physical
    /// ones (the programmed value plus the set-position offset, kept exact when there is none,
    /// or, for a roll-over controller, the short way round).
    fn move_axes(&mut self, n: usize, axes: &[(usize, &Word)]) -> Result<(), NcError> {
        for (i, w) in axes {
            let i = *i;
            let (target, text) =
                if self.m.incremental { (self.m.prog[i] + w.value, None) } else { (w.value, Some(w.text)) };
            let offset = self.m.phys[i] - self.m.prog[i];
            if !self.m.incremental && self.dialect.rollover && self.kinds[i].wraps() {
                self.m.phys[i] += wrap(target - self.m.prog[i]);
            } else if offset == 0.0 {
                self.m.phys[i] = target;
            } else {
                self.m.phys[i] = target + offset;
            }
            self.m.prog[i] = target;
            self.m.text[i] = text;
            if self.m.prog[i].abs() > MAX_AXIS_VALUE || self.m.phys[i].abs() > 1e9 {
                return Err(NcError::line(n, format!("axis {} leaves the accepted range", w.letter)));
            }
        }
        Ok(())
    }

    /// The physical states an arc from `start` to the current state passes through (its end
    /// excluded), every chord within [`ARC_CHORD_TOLERANCE`] of the arc.
    fn arc_path(
        &self,
        n: usize,
        start_prog: &[f64],
        start_phys: &[f64],
        dir: ArcDir,
        words: &[&Word],
    ) -> Result<Vec<Vec<f64>>, NcError> {
        let cw = dir == ArcDir::Cw;
        let (labels, centre) = self.m.plane.letters();
        let plane_name: String = labels.iter().collect();
        let mut idx = [0usize; 2];
        for k in 0..2 {
            match self.axis_of(labels[k]) {
                Some(i) if self.kinds[i] == AxisKind::Linear => idx[k] = i,
                _ => {
                    return Err(NcError::line(
                        n,
                        format!("an arc in the {plane_name} plane needs linear axes {} and {}", labels[0], labels[1]),
                    ))
                }
            }
        }
        let word = |l: char| words.iter().find(|w| w.letter == l).map(|w| w.value);
        let (s, e) = ([start_prog[idx[0]], start_prog[idx[1]]], [self.m.prog[idx[0]], self.m.prog[idx[1]]]);
        let chord = ((e[0] - s[0]).powi(2) + (e[1] - s[1]).powi(2)).sqrt();
        let offsets = [word(centre[0]), word(centre[1])];
        let c = arc_centre(n, s, e, cw, word('R'), offsets, centre)?;
        let r0 = ((s[0] - c[0]).powi(2) + (s[1] - c[1]).powi(2)).sqrt();
        let r1 = ((e[0] - c[0]).powi(2) + (e[1] - c[1]).powi(2)).sqrt();
        if r0 <= 1e-9 {
            return Err(NcError::line(n, "an arc of zero radius"));
        }
        if (r0 - r1).abs() > ARC_RADIUS_TOLERANCE {
            return Err(NcError::line(
                n,
                format!("the arc's end is not on its circle: radius {r0:.4} at the start, {r1:.4} at the end"),
            ));
        }
        let a0 = (s[1] - c[1]).atan2(s[0] - c[0]);
        let a1 = (e[1] - c[1]).atan2(e[0] - c[0]);
        let tau = std::f64::consts::TAU;
        let mut sweep = if cw { (a0 - a1).rem_euclid(tau) } else { (a1 - a0).rem_euclid(tau) };
        if chord <= 1e-9 {
            sweep = tau;
        }
        let r = r0.max(r1);
        let step = if r > ARC_CHORD_TOLERANCE { 2.0 * (1.0 - ARC_CHORD_TOLERANCE / r).acos() } else { tau / 4.0 };
        let pieces = ((sweep / step).ceil() as usize).clamp(1, 4096);
        let dir = if cw { -1.0 } else { 1.0 };
        let mut path = Vec::with_capacity(pieces.saturating_sub(1));
        for k in 1..pieces {
            let t = k as f64 / pieces as f64;
            let a = a0 + dir * sweep * t;
            let rt = r0 + (r1 - r0) * t;
            let mut p: Vec<f64> = start_phys.iter().zip(&self.m.phys).map(|(x, y)| x + (y - x) * t).collect();
            for (k2, v) in [c[0] + rt * a.cos(), c[1] + rt * a.sin()].into_iter().enumerate() {
                let i = idx[k2];
                p[i] = v + (start_phys[i] - start_prog[i]);
            }
            path.push(p);
        }
        Ok(path)
    }

    fn is_non_motion(&self, w: &Word) -> bool {
        w.letter == 'G' && self.non_motion.iter().any(|k| k.matches('G', w.value))
    }

    fn events(&mut self, n: usize, events: &[Event]) -> Result<(), NcError> {
        let has_contact = self.codes.contact.is_some();
        for e in events {
            match *e {
                Event::ContactOn => {
                    if self.m.contact {
                        return Err(NcError::line(n, "roller contact on again without a lift in between"));
                    }
                    self.m.contact = true;
                }
                Event::ContactOff => {
                    if self.m.mask != 0 {
                        return Err(NcError::line(
                            n,
                            format!("roller lifted with tows still on (mask {})", self.m.mask),
                        ));
                    }
                    self.m.contact = false;
                }
                Event::TowRestart(mask) => {
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
                Event::TowCut(mask) => {
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

/// The centre of an arc in its plane from start `s` to end `e`: from its
/// radius word R (the short way round for R > 0, the long way for R < 0) or its centre
/// offsets (letters `letters`) from the start.
fn arc_centre(
    n: usize,
    s: [f64; 2],
    e: [f64; 2],
    cw: bool,
    radius: Option<f64>,
    offsets: [Option<f64>; 2],
    letters: [char; 2],
) -> Result<[f64; 2], NcError> {
    let chord = ((e[0] - s[0]).powi(2) + (e[1] - s[1]).powi(2)).sqrt();
    Ok(match (radius, offsets) {
        (Some(_), [Some(_), _] | [_, Some(_)]) => {
            return Err(NcError::line(n, "an arc with both a radius R and centre offsets"));
        }
        (Some(r), _) => {
            if chord <= 1e-9 {
                return Err(NcError::line(n, "an arc given by its radius R must end away from its start"));
            }
            let h2 = r * r - chord * chord / 4.0;
            if h2 < -(ARC_RADIUS_TOLERANCE * chord) {
                return Err(NcError::line(
                    n,
                    format!("the arc's radius R{r} is shorter than half the distance to its end ({:.4})", chord / 2.0),
                ));
            }
            let h = h2.max(0.0).sqrt();
            let u = [(e[0] - s[0]) / chord, (e[1] - s[1]) / chord];
            // Clockwise arcs of at most half a turn have their centre right of the chord.
            let side = if cw == (r > 0.0) { 1.0 } else { -1.0 };
            [(s[0] + e[0]) / 2.0 + side * h * u[1], (s[1] + e[1]) / 2.0 - side * h * u[0]]
        }
        (None, [None, None]) => {
            return Err(NcError::line(
                n,
                format!("an arc needs its centre ({}, {}) or its radius R", letters[0], letters[1]),
            ));
        }
        (None, [i, j]) => [s[0] + i.unwrap_or(0.0), s[1] + j.unwrap_or(0.0)],
    })
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
        assert!(it.apply(0, "G0 X10 Y5").unwrap().motion == Some(MoveKind::Rapid));
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
        assert!(it.apply(2, "G5 X10").unwrap_err().to_string().contains("G5 with axis words"));
        assert!(it.apply(3, "G0 X#1").is_err());
        assert!(it.apply(4, "G0 X99999999").unwrap_err().to_string().contains("range"));
        assert!(it.apply(5, "G1 X3").unwrap_err().to_string().contains("no feed"));
        assert!(it.apply(5, "G2 X10 I5 F100").unwrap_err().to_string().contains("outside a course's on-part block"));
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

    /// In the ZX plane (G18) a clockwise arc, seen from +Y, turns from +X towards +Z.
    #[test]
    fn arcs_in_the_zx_plane() {
        let d = Dialect::default();
        let m = Machine::new(
            "m",
            vec![Axis::new("X", AxisKind::Linear), Axis::new("Y", AxisKind::Linear), Axis::new("Z", AxisKind::Linear)],
        )
        .unwrap();
        let mut it = Interp::new(&d, &m).unwrap();
        it.apply(0, "G0 X10 Y0 Z0").unwrap();
        it.apply(1, "M20").unwrap();
        it.apply(2, "M60 P1").unwrap();
        it.apply(3, "G18").unwrap();
        let a = it.apply(4, "G2 X0 Z10 I-10 K0 F100").unwrap();
        assert!(
            a.is_arc() && a.motion == Some(MoveKind::Arc { dir: ArcDir::Cw, plane: Plane::ZX }) && !a.path.is_empty()
        );
        let mid = &a.path[a.path.len() / 2];
        assert!(mid[0] > 6.0 && mid[2] > 6.0 && mid[1] == 0.0, "{mid:?}");
        for p in &a.path {
            assert!((p[0].hypot(p[2]) - 10.0).abs() < 1e-9);
        }
        // Modal: the next line without a motion code is an arc too (back the other way).
        let b = it.apply(5, "G3 X10 Z0 I0 K-10").unwrap();
        assert!(b.is_arc() && b.path.iter().all(|p| p[0] > -1e-9 && p[2] > -1e-9));
        let c = it.apply(6, "X0 Z10 I-10").unwrap();
        assert!(c.is_arc());
        // Centre words alone in arc mode: a full circle from where the tool stands.
        let full = it.apply(7, "K-5").unwrap();
        assert!(full.motion == Some(MoveKind::Arc { dir: ArcDir::Ccw, plane: Plane::ZX }) && full.path.len() > 8);
        assert!(full.path.iter().all(|p| (p[0].hypot(p[2] - 5.0) - 5.0).abs() < 1e-9));
        assert_eq!(it.m.prog, vec![0.0, 0.0, 10.0]);
        // A machine without the plane's axes cannot lay the arc.
        it.apply(8, "G19").unwrap();
        let m2 = Machine::new("m", vec![Axis::new("X", AxisKind::Linear), Axis::new("Y", AxisKind::Linear)]).unwrap();
        let mut it2 = Interp::new(&d, &m2).unwrap();
        it2.apply(0, "M20").unwrap();
        it2.apply(1, "M60 P1").unwrap();
        it2.apply(2, "G19").unwrap();
        let e = it2.apply(3, "G2 Y10 J5 F100").unwrap_err();
        assert!(e.to_string().contains("YZ plane needs linear axes Y and Z"), "{e}");
    }
}
