//! Reversal of a course: its span (approach, on-part, retract) run backwards.
//!
//! The reversed span visits the same points in reverse order, with the heading axis turned by
//! 180°. Tow restarts and cuts stay at the same points with restart and cut swapped (so the same
//! tows are on along every piece of the path), and roller contact on and off swap likewise. The
//! original retract, reversed, becomes the approach (it moves with the original approach's
//! motion code and feed), and the original approach, reversed, becomes the retract. Lines that
//! neither move nor change modes stay at their point. Axis values are written with the
//! original text (the heading axis: the original decimal text plus or minus 180, exactly).

use towpath_machine::{AxisKind, Machine};

use crate::dialect::Dialect;
use crate::interp::{Event, Interp, Modal, MotionMode};
use crate::lex::Lexed;
use crate::program::Program;

/// A course's span, reversed.
#[derive(Clone, Debug, PartialEq)]
pub struct Reversed {
    /// The lines of the reversed span (empty from [`reversal_of`]).
    pub lines: Vec<String>,
    /// The state the machine must be in before them (absolute mode).
    pub entry: Modal,
    /// The heading shift used (+180 or −180), 0 if the machine has no heading axis.
    pub shift: f64,
}

/// Which block of the span a move belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    Approach,
    On,
    Retract,
}

/// How a move of the span is written: at a rapid, or at the feed (its text as written).
#[derive(Clone, Debug, PartialEq)]
enum Pace {
    Rapid,
    Feed(Option<String>),
}

impl Part {
    /// The block of `course` that line `j` of its span is in.
    fn of(course: &crate::program::Course, j: usize) -> Self {
        if j < course.on_part.start {
            Part::Approach
        } else if j < course.on_part.end {
            Part::On
        } else {
            Part::Retract
        }
    }
}

impl Pace {
    /// The motion mode the move is written in.
    fn mode(&self) -> MotionMode {
        match self {
            Pace::Rapid => MotionMode::Rapid,
            Pace::Feed(_) => MotionMode::Linear,
        }
    }
}

/// A move of the span: its block, pace and comments.
#[derive(Clone, Debug)]
struct Move {
    part: Part,
    pace: Pace,
    comment: Option<String>,
}

#[derive(Clone, Debug)]
enum StationItem {
    /// An original line kept as it is (comments, point codes, dwells).
    Line(String),
    /// An event line: the original text with its code word swapped.
    Event(String),
    /// A switch line of the dialect: (switch and its words, on?, the line's text, its line).
    Switch(SwitchKey, bool, String, usize),
}

use crate::program::SwitchKey;

/// Why a course cannot be laid reversed (it is then laid forward only, and the report says why).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Irreversible {
    /// A line of the course holds codes or words the dialect does not describe, between
    /// contact and lift or around them: what they mean laid the other way is unknown.
    #[error(
        "line {line} holds {words}, which the dialect does not describe (declare it as a [[switch]] pair or in \
         point_codes if it may be laid the other way)"
    )]
    Undescribed {
        /// 1-based line.
        line: usize,
        /// The words, as written.
        words: String,
    },
    /// A switch of the dialect is not turned on and then off within the course.
    #[error("line {line}: {problem}")]
    Switch {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        problem: String,
    },
    /// The course holds an arc, sets positions, has codes outside its on-part block, or would
    /// turn the heading beyond its limits.
    #[error("{0}")]
    Other(String),
}

/// Builds the reversed span of course `c`, or says why it cannot be reversed.
pub fn reverse_course(
    program: &Program,
    c: usize,
    machine: &Machine,
    dialect: &Dialect,
) -> Result<Reversed, Irreversible> {
    reverse_span(program, c, machine, dialect, true)
}

/// Like [`reverse_course`], but without writing the lines (`lines` is left empty): enough to
/// know whether and how the course reverses.
pub fn reversal_of(
    program: &Program,
    c: usize,
    machine: &Machine,
    dialect: &Dialect,
) -> Result<Reversed, Irreversible> {
    reverse_span(program, c, machine, dialect, false)
}

/// What a line that neither moves nor has tow or contact codes is, for reversal.
enum Still {
    /// Changes modes only: the reversed moves carry their own modes.
    Modes,
    /// Kept at its point (comments, declared point codes, non-motion codes such as a dwell).
    Point,
    /// A switch of the dialect, on or off.
    Switch(SwitchKey, bool),
}

/// Classifies a line that neither moves nor has tow or contact codes; `Err` holds the words
/// the dialect does not describe.
fn still_line(lexed: Option<&Lexed>, line: &str, codes: &crate::dialect::Codes, modal: bool) -> Result<Still, String> {
    let Some(lexed) = lexed else { return Err(format!("{:?}", line.trim())) };
    let g_known = |v: f64| {
        codes
            .rapid
            .iter()
            .chain(&codes.feed)
            .chain(&codes.arc_cw)
            .chain(&codes.arc_ccw)
            .chain(&codes.planes)
            .any(|c| c.matches('G', v))
            || codes.absolute.matches('G', v)
            || codes.incremental.matches('G', v)
    };
    let non_motion =
        lexed.words.iter().any(|w| w.letter == 'G' && codes.non_motion.iter().any(|c| c.matches('G', w.value)));
    let is_switch = |v: f64| codes.switches.iter().any(|(on, off)| on.matches('M', v) || off.matches('M', v));
    // Words after a dwell, a point code or a switch code are their parameters.
    let parameters = non_motion
        || lexed
            .words
            .iter()
            .any(|x| x.letter == 'M' && (codes.point.iter().any(|c| c.matches('M', x.value)) || is_switch(x.value)));
    let mut switch: Option<(usize, bool, usize)> = None;
    let mut unknown: Vec<String> = Vec::new();
    for (k, w) in lexed.words.iter().enumerate() {
        let text = line.get(w.span.clone()).unwrap_or("").to_string();
        match w.letter {
            'G' if g_known(w.value) || codes.non_motion.iter().any(|c| c.matches('G', w.value)) => {}
            'M' if codes.point.iter().any(|c| c.matches('M', w.value)) => {}
            'M' => match codes.switches.iter().enumerate().find_map(|(i, (on, off))| {
                if on.matches('M', w.value) {
                    Some((i, true))
                } else if off.matches('M', w.value) {
                    Some((i, false))
                } else {
                    None
                }
            }) {
                Some((i, on)) if switch.is_none() => switch = Some((i, on, k)),
                _ => unknown.push(text),
            },
            l if l == codes.line_number_word || l == codes.feed_word => {}
            l if parameters && l != 'G' && l != 'M' => {}
            _ => unknown.push(text),
        }
    }
    if !unknown.is_empty() {
        return Err(unknown.join(" "));
    }
    match switch {
        Some((i, on, k)) => {
            if modal || non_motion {
                return Err(line.trim().to_string());
            }
            let words = lexed
                .words
                .iter()
                .enumerate()
                .filter(|&(x, w)| x != k && w.letter != codes.line_number_word)
                .map(|(_, w)| (w.letter, w.text.to_string()))
                .collect();
            Ok(Still::Switch((i, words), on))
        }
        None if modal => Ok(Still::Modes),
        None => Ok(Still::Point),
    }
}

/// The switch a line turns on or off, with its words: a line with one switch code of the
/// dialect (its other words, line number aside, name which switch). `None` for other lines.
pub(crate) fn switch_of(line: &str, dialect: &Dialect, codes: &crate::dialect::Codes) -> Option<(SwitchKey, bool)> {
    if codes.switches.is_empty() {
        return None;
    }
    let lexed = crate::lex::lex(line.trim_end_matches('\r'), dialect.comment_parens, dialect.comment_semicolon).ok()?;
    let mut found = None;
    for (k, w) in lexed.words.iter().enumerate() {
        if w.letter != 'M' {
            continue;
        }
        if let Some(x) = codes.switches.iter().enumerate().find_map(|(i, (on, off))| {
            (on.matches('M', w.value) || off.matches('M', w.value)).then_some((i, on.matches('M', w.value), k))
        }) {
            found = Some(x);
        }
    }
    let (i, on, k) = found?;
    let words = lexed
        .words
        .iter()
        .enumerate()
        .filter(|&(x, w)| x != k && w.letter != codes.line_number_word)
        .map(|(_, w)| (w.letter, w.text.to_string()))
        .collect();
    Some(((i, words), on))
}

/// Checks that the courses may be laid in any order without changing which switches of the
/// dialect are on where: every course, with the lines that travel with it, leaves each switch
/// as it found it (a switch turned on before a course's approach is turned off again after its
/// retract, before the next course; or it is left to the header and footer). Refused otherwise,
/// naming the line that leaves a switch on (or off) for the courses after it.
pub(crate) fn check_switch_scope(program: &Program, dialect: &Dialect) -> Result<(), crate::error::NcError> {
    let codes = dialect.codes()?;
    if codes.switches.is_empty() {
        return Ok(());
    }
    let apply = |state: &mut Vec<SwitchKey>, text: &str| -> Option<bool> {
        let (key, on) = switch_of(text, dialect, &codes)?;
        let had = state.contains(&key);
        state.retain(|k| *k != key);
        if on {
            state.push(key);
        }
        Some(had != on)
    };
    let mut base: Vec<SwitchKey> = Vec::new();
    for line in &program.lines[..program.header_end] {
        apply(&mut base, line);
    }
    base.sort();
    for course in &program.courses {
        let mut state = base.clone();
        let mut last: Option<(usize, String)> = None;
        let mut step = |j: usize, text: &str, state: &mut Vec<SwitchKey>| {
            if apply(state, text).is_some() {
                last = Some((j, text.trim_end_matches('\r').to_string()));
            }
        };
        for item in course.pre_before.iter().chain(&course.pre_after) {
            match item {
                crate::program::Item::Line(j) => step(*j, &program.lines[*j], &mut state),
                crate::program::Item::Kept(j, t) => step(*j, t, &mut state),
            }
        }
        for j in course.span.clone() {
            step(j, &program.lines[j], &mut state);
        }
        for item in &course.post {
            match item {
                crate::program::Item::Line(j) => step(*j, &program.lines[*j], &mut state),
                crate::program::Item::Kept(j, t) => step(*j, t, &mut state),
            }
        }
        state.sort();
        if state != base {
            let (j, text) = last.unwrap_or((course.span.start, String::new()));
            return Err(crate::error::NcError::line(
                j + 1,
                format!(
                    "{text:?} leaves a switch {on} for the courses after it: laid in another order, other courses \
                     would run with it {on}; switch it back within the course (or in the header and footer)",
                    on = if state.iter().any(|k| !base.contains(k)) { "on" } else { "off" },
                ),
            ));
        }
    }
    Ok(())
}

/// The span walked forward: its stations (points, `prog[k]` and `text[k]` with the items
/// written there) and the moves between them (move `k` from station `k` to `k + 1`).
struct Walk {
    prog: Vec<Vec<f64>>,
    text: Vec<Vec<Option<crate::lex::NumText>>>,
    stations: Vec<Vec<StationItem>>,
    moves: Vec<Move>,
}

impl Walk {
    /// Adds a move to state `to`, with the (swapped) events written before and after it.
    fn add_move(&mut self, mv: Move, to: &Modal, before: Vec<StationItem>, after: Vec<StationItem>) {
        if let Some(s) = self.stations.last_mut() {
            s.extend(before);
        }
        self.moves.push(mv);
        self.prog.push(to.prog.clone());
        self.text.push(to.text.clone());
        self.stations.push(after);
    }
}

fn reverse_span(
    program: &Program,
    c: usize,
    machine: &Machine,
    dialect: &Dialect,
    write: bool,
) -> Result<Reversed, Irreversible> {
    let course = &program.courses[c];
    let other = |e: crate::error::NcError| Irreversible::Other(e.to_string());
    let codes = dialect.codes().map_err(other)?;
    let mut walk = walk_span(program, c, machine, dialect, &codes)?;
    pair_switches(&mut walk.stations)?;
    refuse_switches_on(course, &walk.stations)?;
    let heading = machine.heading_axis();
    let shift = heading_shift(machine, &walk.prog)?;
    let values = Values { prog: &walk.prog, text: &walk.text, heading, shift, decimals: dialect.decimals };
    let lines = if write { write_lines(&walk, &values, machine, dialect) } else { Vec::new() };
    let n = walk.moves.len();
    let mut entry = course.span_start.clone();
    entry.prog = walk.prog[n].clone();
    entry.text = walk.text[n].clone();
    for i in 0..machine.dim() {
        entry.phys[i] = course.span_start.phys[i] - course.span_start.prog[i] + walk.prog[n][i];
    }
    if let Some(h) = heading {
        entry.prog[h] += shift;
        entry.phys[h] += shift;
        entry.text[h] = crate::lex::NumText::new(&values.text(n, h));
    }
    entry.incremental = false;
    entry.contact = false;
    entry.mask = 0;
    Ok(Reversed { lines, entry, shift })
}

/// Walks course `c`'s span: stations (points) with their items, and the moves between them;
/// refuses what cannot be laid reversed.
fn walk_span(
    program: &Program,
    c: usize,
    machine: &Machine,
    dialect: &Dialect,
    codes: &crate::dialect::Codes,
) -> Result<Walk, Irreversible> {
    let course = &program.courses[c];
    let other = |e: crate::error::NcError| Irreversible::Other(e.to_string());
    let mut it = Interp::new(dialect, machine).map_err(other)?;
    it.m = course.span_start.clone();
    let mut walk = Walk {
        prog: vec![it.m.prog.clone()],
        text: vec![it.m.text.clone()],
        stations: vec![Vec::new()],
        moves: vec![],
    };
    for j in course.span.clone() {
        let line = program.lines[j].trim_end_matches('\r');
        let a = it.apply(j, line).map_err(other)?;
        let part = Part::of(course, j);
        if a.set_position {
            return Err(Irreversible::Other(format!("line {} sets positions inside the course", j + 1)));
        }
        if a.events && part != Part::On {
            // Outside the on-part block such a code changes nothing (the roller is already
            // lifted, no tow is on); swapped, it would.
            return Err(Irreversible::Other(format!(
                "line {} has tow or contact codes outside the on-part block",
                j + 1
            )));
        }
        let lexed = a.lexed.clone().unwrap_or_default();
        let undescribed = |words: String| Irreversible::Undescribed { line: j + 1, words };
        if let Some(kind) = a.motion {
            if kind.is_arc() {
                return Err(Irreversible::Other(format!(
                    "line {} is an arc: towpath lays arcs only as they are written, forward",
                    j + 1
                )));
            }
            if a.unknown {
                return Err(undescribed(unknown_words(&lexed, line, codes, &it)));
            }
            let pace =
                if kind.is_rapid() { Pace::Rapid } else { Pace::Feed(it.m.feed.as_ref().map(|f| f.1.to_string())) };
            let comment = if lexed.comments.is_empty() { None } else { Some(lexed.comments.join(" ")) };
            let swapped = |evs: &[Event]| evs.iter().map(|e| StationItem::Event(swapped_event(e, dialect))).collect();
            walk.add_move(Move { part, pace, comment }, &it.m, swapped(&a.before), swapped(&a.after));
        } else if a.events {
            if a.modal {
                return Err(Irreversible::Other(format!("line {} mixes mode changes and tow or contact codes", j + 1)));
            }
            if a.unknown {
                return Err(undescribed(unknown_words(&lexed, line, codes, &it)));
            }
            let [e] = a.events().copied().collect::<Vec<Event>>()[..] else {
                return Err(Irreversible::Other(format!("line {} has several tow or contact codes", j + 1)));
            };
            if let Some(s) = walk.stations.last_mut() {
                s.push(StationItem::Event(swap_line_code(line, &e, dialect, codes, &lexed)));
            }
        } else {
            let item = match still_line(a.lexed.as_ref(), line, codes, a.modal).map_err(undescribed)? {
                // A pure mode change: the reversed moves carry their own modes.
                Still::Modes => None,
                Still::Point => Some(StationItem::Line(line.to_string())),
                Still::Switch(key, on) => Some(StationItem::Switch(key, on, line.to_string(), j)),
            };
            if let (Some(s), Some(item)) = (walk.stations.last_mut(), item) {
                s.push(item);
            }
        }
    }
    Ok(walk)
}

/// A switch already on where the course starts and switched within it would not be on along
/// the same stretch reversed (its on and off lines trade places assuming it starts off).
fn refuse_switches_on(course: &crate::program::Course, stations: &[Vec<StationItem>]) -> Result<(), Irreversible> {
    for item in stations.iter().flatten() {
        if let StationItem::Switch(key, _, text, j) = item {
            if course.switches_on.contains(key) {
                return Err(Irreversible::Switch {
                    line: j + 1,
                    problem: format!("{:?} switches what is already on where the course starts", text.trim()),
                });
            }
        }
    }
    Ok(())
}

/// The heading shift (+180 or −180; 0 without a heading axis): +180 unless that leaves a
/// rotary heading axis's limits (or, for a continuous one, goes beyond 360°).
fn heading_shift(machine: &Machine, prog: &[Vec<f64>]) -> Result<f64, Irreversible> {
    let Some(h) = machine.heading_axis() else { return Ok(0.0) };
    let ax = &machine.axes[h];
    let lo = prog.iter().map(|p| p[h]).fold(f64::INFINITY, f64::min);
    let hi = prog.iter().map(|p| p[h]).fold(f64::NEG_INFINITY, f64::max);
    Ok(match ax.kind {
        AxisKind::Rotary => {
            let fits = |s: f64| ax.max.is_none_or(|m| hi + s <= m + 1e-9) && ax.min.is_none_or(|m| lo + s >= m - 1e-9);
            if fits(180.0) {
                180.0
            } else if fits(-180.0) {
                -180.0
            } else {
                return Err(Irreversible::Other(format!(
                    "turning the heading axis {} by 180° leaves its travel limits",
                    ax.label
                )));
            }
        }
        _ => {
            if hi + 180.0 > 360.0 {
                -180.0
            } else {
                180.0
            }
        }
    })
}

/// The text of the stations' axis values, reversed: the original text where there is one
/// (the heading axis's shifted exactly), else the value formatted.
struct Values<'w> {
    prog: &'w [Vec<f64>],
    text: &'w [Vec<Option<crate::lex::NumText>>],
    heading: Option<usize>,
    shift: f64,
    decimals: usize,
}

impl Values<'_> {
    /// The text of axis `i` at station `k`.
    fn text(&self, k: usize, i: usize) -> String {
        let t = self.text[k][i].as_ref().map(|x| x.as_str());
        let v = self.prog[k][i];
        if Some(i) == self.heading {
            match t {
                Some(t) => shift_decimal(t, self.shift).unwrap_or_else(|| fmt_num(v + self.shift, self.decimals)),
                None => fmt_num(v + self.shift, self.decimals),
            }
        } else {
            match t {
                Some(t) => t.to_string(),
                None => fmt_num(v, self.decimals),
            }
        }
    }
}

/// Writes the reversed span: the stations from the last to the first, each station's items
/// in reverse order, and between them the moves run backwards (the original retract at the
/// original approach's last motion code and feed, the approach at the retract's first).
fn write_lines(walk: &Walk, values: &Values, machine: &Machine, dialect: &Dialect) -> Vec<String> {
    let moves = &walk.moves;
    let last_approach = moves.iter().rev().find(|m| m.part == Part::Approach).cloned();
    let first_retract = moves.iter().find(|m| m.part == Part::Retract).cloned();
    let rapid_code = dialect.rapid.first().cloned().unwrap_or_else(|| "G0".into());
    let feed_code = dialect.feed.first().cloned().unwrap_or_else(|| "G1".into());
    let dim = machine.dim();
    let n = moves.len();
    let mut lines = Vec::new();
    let mut cur: Vec<String> = (0..dim).map(|i| values.text(n, i)).collect();
    let mut cur_mode: Option<MotionMode> = None;
    let mut cur_feed: Option<&String> = None;
    for s in (0..=n).rev() {
        for item in walk.stations[s].iter().rev() {
            match item {
                StationItem::Line(t) | StationItem::Event(t) | StationItem::Switch(_, _, t, _) => lines.push(t.clone()),
            }
        }
        if s == 0 {
            break;
        }
        let mv = &moves[s - 1];
        let template = match mv.part {
            Part::Approach => first_retract.as_ref().unwrap_or(mv),
            Part::Retract => last_approach.as_ref().unwrap_or(mv),
            Part::On => mv,
        };
        let mode = template.pace.mode();
        let mut words = Vec::new();
        if cur_mode != Some(mode) {
            words.push(if mode.is_rapid() { rapid_code.clone() } else { feed_code.clone() });
            cur_mode = Some(mode);
        }
        for i in 0..dim {
            let t = values.text(s - 1, i);
            if t != cur[i] || walk.prog[s - 1][i] != walk.prog[s][i] {
                words.push(format!("{}{}", machine.axes[i].label.to_ascii_uppercase(), t));
                cur[i] = t;
            }
        }
        if let Pace::Feed(Some(f)) = &template.pace {
            if cur_feed != Some(f) {
                words.push(format!("{}{}", dialect.feed_word.to_ascii_uppercase(), f));
                cur_feed = Some(f);
            }
        }
        if !words.iter().any(|w| machine.axes.iter().any(|a| w.starts_with(&a.label.to_ascii_uppercase()))) {
            // A move to the same point: write one axis so that it stays a move.
            words.push(format!("{}{}", machine.axes[0].label.to_ascii_uppercase(), cur[0]));
        }
        let mut l = words.join(" ");
        if let Some(cm) = &mv.comment {
            l.push(' ');
            l.push_str(&dialect.comment(cm));
        }
        lines.push(l);
    }
    lines
}

/// The words of a line the dialect does not describe (or the whole line if it cannot be read).
fn unknown_words(lexed: &Lexed, line: &str, codes: &crate::dialect::Codes, it: &Interp) -> String {
    let known = |w: &crate::lex::Word| {
        let (l, v) = (w.letter, w.value);
        (l == 'G'
            && ((codes
                .rapid
                .iter()
                .chain(&codes.feed)
                .chain(&codes.arc_cw)
                .chain(&codes.arc_ccw)
                .chain(&codes.planes))
            .any(|c| c.matches(l, v))
                || codes.absolute.matches(l, v)
                || codes.incremental.matches(l, v)))
            || (l == 'M'
                && (codes.restart.matches(l, v)
                    || codes.cut.matches(l, v)
                    || codes.contact.is_some_and(|(on, off)| on.matches(l, v) || off.matches(l, v))))
            || l == codes.feed_word
            || l == codes.line_number_word
            || l == codes.mask_word
            || it.axis_of(l).is_some()
    };
    let words: Vec<&str> = lexed.words.iter().filter(|w| !known(w)).filter_map(|w| line.get(w.span.clone())).collect();
    if words.is_empty() {
        format!("{:?}", line.trim())
    } else {
        words.join(" ")
    }
}

/// Pairs each switch's on and off lines within the span (they must alternate, on first, and end
/// off) and swaps their texts: reversed, the on line is written where the off line was and
/// the other way round, so the same stretch of the path runs with the switch on.
fn pair_switches(stations: &mut [Vec<StationItem>]) -> Result<(), Irreversible> {
    // (key, position of its open on line)
    let mut open: Vec<(SwitchKey, (usize, usize))> = Vec::new();
    let mut pairs: Vec<((usize, usize), (usize, usize))> = Vec::new();
    for (si, items) in stations.iter().enumerate() {
        for (ii, item) in items.iter().enumerate() {
            let StationItem::Switch(key, on, text, j) = item else { continue };
            let at = open.iter().position(|(k, _)| k == key);
            match (on, at) {
                (true, None) => open.push((key.clone(), (si, ii))),
                (false, Some(x)) => {
                    let (_, from) = open.remove(x);
                    pairs.push((from, (si, ii)));
                }
                (true, Some(_)) => {
                    return Err(Irreversible::Switch {
                        line: j + 1,
                        problem: format!("{:?} switches on what is already on within the course", text.trim()),
                    })
                }
                (false, None) => {
                    return Err(Irreversible::Switch {
                        line: j + 1,
                        problem: format!(
                            "{:?} switches off what the course did not switch on (it was on before the course)",
                            text.trim()
                        ),
                    })
                }
            }
        }
    }
    if let Some((_, (si, ii))) = open.first() {
        if let Some(StationItem::Switch(_, _, text, j)) = stations.get(*si).and_then(|s| s.get(*ii)) {
            return Err(Irreversible::Switch {
                line: j + 1,
                problem: format!("{:?} switches on and the course does not switch it off again", text.trim()),
            });
        }
    }
    for ((s0, i0), (s1, i1)) in pairs {
        let t0 = match &stations[s0][i0] {
            StationItem::Switch(_, _, t, _) => t.clone(),
            _ => continue,
        };
        let t1 = match &mut stations[s1][i1] {
            StationItem::Switch(_, _, t, _) => std::mem::replace(t, t0),
            _ => continue,
        };
        if let StationItem::Switch(_, _, t, _) = &mut stations[s0][i0] {
            *t = t1;
        }
    }
    Ok(())
}

/// The text of an event split off a motion line: the swapped code and, for tows, the mask.
fn swapped_event(e: &Event, dialect: &Dialect) -> String {
    match *e {
        Event::ContactOn => dialect.contact_off.clone(),
        Event::ContactOff => dialect.contact_on.clone(),
        Event::TowRestart(mask) => tow_event(&dialect.tow_cut, mask, dialect),
        Event::TowCut(mask) => tow_event(&dialect.tow_restart, mask, dialect),
    }
}

/// A tow event's text: its code and mask word.
fn tow_event(code: &str, mask: u64, dialect: &Dialect) -> String {
    format!("{code} {}{mask}", dialect.tow_mask_word.to_ascii_uppercase())
}

/// An event line with its code word swapped (restart ↔ cut, contact on ↔ off; every copy of
/// it), the rest kept.
fn swap_line_code(line: &str, e: &Event, dialect: &Dialect, codes: &crate::dialect::Codes, lexed: &Lexed) -> String {
    let (from, to) = match *e {
        Event::ContactOn | Event::ContactOff => match &codes.contact {
            Some((c_on, _)) if *e == Event::ContactOn => (*c_on, dialect.contact_off.clone()),
            Some((_, c_off)) => (*c_off, dialect.contact_on.clone()),
            None => return swapped_event(e, dialect),
        },
        Event::TowRestart(_) => (codes.restart, dialect.tow_cut.clone()),
        Event::TowCut(_) => (codes.cut, dialect.tow_restart.clone()),
    };
    // Every word of that code (a line may repeat it), from the end so the spans stay right.
    let spans: Vec<_> =
        lexed.words.iter().filter(|w| from.matches(w.letter, w.value)).map(|w| w.span.clone()).collect();
    if spans.is_empty() {
        return swapped_event(e, dialect);
    }
    let mut out = line.to_string();
    for span in spans.into_iter().rev() {
        out.replace_range(span, &to);
    }
    out
}

/// Formats a number with at most `decimals` digits after the point, trailing zeros dropped.
pub fn fmt_num(v: f64, decimals: usize) -> String {
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

/// Adds a whole number of degrees to a decimal text exactly, keeping its digits after the point.
pub fn shift_decimal(text: &str, shift: f64) -> Option<String> {
    if shift.fract() != 0.0 || shift.abs() > 1e6 {
        return None;
    }
    let t = text.trim();
    let (neg, body) = match t.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let (int, frac) = match body.split_once('.') {
        Some((i, f)) => (i, f),
        None => (body, ""),
    };
    if !(int.chars().all(|c| c.is_ascii_digit()) && frac.chars().all(|c| c.is_ascii_digit())) || frac.len() > 18 {
        return None;
    }
    if int.is_empty() && frac.is_empty() {
        return None;
    }
    let scale = 10i128.checked_pow(frac.len() as u32)?;
    let digits: i128 = format!("{}{}", if int.is_empty() { "0" } else { int }, frac).parse().ok()?;
    let value = if neg { -digits } else { digits };
    let shifted = value.checked_add((shift as i128).checked_mul(scale)?)?;
    let (sign, mag) = if shifted < 0 { ("-", -shifted) } else { ("", shifted) };
    let whole = mag / scale;
    let part = mag % scale;
    Some(if frac.is_empty() {
        format!("{sign}{whole}")
    } else {
        format!("{sign}{whole}.{part:0width$}", width = frac.len())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_shift_is_exact() {
        assert_eq!(shift_decimal("12.345", 180.0).unwrap(), "192.345");
        assert_eq!(shift_decimal("-12.5", 180.0).unwrap(), "167.5");
        assert_eq!(shift_decimal("100", -180.0).unwrap(), "-80");
        assert_eq!(shift_decimal(".25", 180.0).unwrap(), "180.25");
        assert_eq!(shift_decimal("-0.250", -180.0).unwrap(), "-180.250");
        assert_eq!(shift_decimal("190.000", -180.0).unwrap(), "10.000");
        assert!(shift_decimal("1e5", 180.0).is_none());
    }

    #[test]
    fn numbers_are_trimmed() {
        assert_eq!(fmt_num(1.5, 4), "1.5");
        assert_eq!(fmt_num(-0.00001, 4), "0");
        assert_eq!(fmt_num(10.0, 3), "10");
    }
}
