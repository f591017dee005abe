//! The verifier's line accounting: every line of the original is accounted for, and every line
//! of the optimized program is the original's, part of a legal reversal, or a transit towpath
//! writes. Own code (it reads lines with the lexer and the dialect's codes, not with the
//! rewriter's or the reversal's logic).
//!
//! - The header and the footer are the original's, line for line.
//! - A course laid forward is its original span, line for line, around its on-part block.
//! - A course laid reversed holds only moves (checked by motion elsewhere), tow and contact
//!   lines (checked through the tows on each move), and the original span's point lines
//!   (comments, dwells, declared point codes) and switch lines, each at the mirrored point,
//!   switches on along the mirrored stretch; a span with lines the dialect does not describe
//!   cannot be reversed at all.
//! - Between two courses lie the lines that travel with them (each original line once, next to
//!   its course), ply comments, and transits: rapid moves, set-position lines and mode lines
//!   with nothing else on them.

use std::collections::HashMap;
use std::ops::Range;

use towpath_machine::Machine;

use crate::dialect::{Code, Codes, Dialect};
use crate::lex::{lex, Lexed};
use crate::program::{Item, Program};
use crate::rewrite::Placement;
use crate::verify::VerifyError;

/// What a line is, to the verifier.
#[derive(Clone, Debug, PartialEq)]
enum Kind {
    /// No words (comments, blank).
    Empty,
    /// Words of a move only: motion and distance codes, axis words, feed, line number.
    Move,
    /// Tow or contact codes with their mask (and a line number).
    Event,
    /// Mode words only (distance, motion, plane codes, feed).
    Modes,
    /// A set-position code with axis words.
    SetPosition,
    /// A dwell or other non-motion code, or a declared point code, with its words.
    Point,
    /// A switch of the dialect: (switch, its words), on?
    Switch((usize, Vec<(char, String)>), bool),
    /// An arc (centre or radius words with a move).
    Arc,
    /// Anything else: words the dialect does not describe, or a line that cannot be read.
    Undescribed,
}

struct Reader<'a> {
    dialect: &'a Dialect,
    codes: Codes,
    axes: Vec<char>,
}

impl<'a> Reader<'a> {
    fn new(dialect: &'a Dialect, machine: &Machine) -> Option<Self> {
        let codes = dialect.codes().ok()?;
        let axes = machine.axes.iter().filter_map(|a| a.label.chars().next()).map(|c| c.to_ascii_uppercase()).collect();
        Some(Reader { dialect, codes, axes })
    }

    fn lex(&self, line: &str) -> Option<Lexed> {
        lex(line.trim_end_matches('\r'), self.dialect.comment_parens, self.dialect.comment_semicolon).ok()
    }

    fn any(list: &[Code], l: char, v: f64) -> bool {
        list.iter().any(|c| c.matches(l, v))
    }

    fn kind(&self, line: &str) -> Kind {
        let Some(lexed) = self.lex(line) else {
            return if line.trim().is_empty() { Kind::Empty } else { Kind::Undescribed };
        };
        let c = &self.codes;
        let (mut motion, mut distance, mut plane, mut set_pos, mut non_motion) = (false, false, false, false, false);
        let (mut axis, mut feed, mut mask) = (false, false, false);
        let (mut event, mut point, mut other, mut arc) = (false, false, false, false);
        let mut switch: Option<(usize, bool)> = None;
        let mut switches = 0;
        let is_switch = |v: f64| c.switches.iter().any(|(a, b)| a.matches('M', v) || b.matches('M', v));
        // Words after a dwell, a point code or a switch code are their parameters.
        let parameters = lexed.words.iter().any(|x| {
            (x.letter == 'M' && (Self::any(&c.point, 'M', x.value) || is_switch(x.value)))
                || (x.letter == 'G' && Self::any(&c.non_motion, 'G', x.value))
        });
        for w in &lexed.words {
            let (l, v) = (w.letter, w.value);
            if l == 'G' {
                if Self::any(&c.rapid, l, v)
                    || Self::any(&c.feed, l, v)
                    || Self::any(&c.arc_cw, l, v)
                    || Self::any(&c.arc_ccw, l, v)
                {
                    motion = true;
                } else if c.absolute.matches(l, v) || c.incremental.matches(l, v) {
                    distance = true;
                } else if Self::any(&c.planes, l, v) {
                    plane = true;
                } else if c.set_position.matches(l, v) {
                    set_pos = true;
                } else if Self::any(&c.non_motion, l, v) {
                    non_motion = true;
                } else {
                    other = true;
                }
            } else if l == 'M' {
                let contact = c.contact.is_some_and(|(on, off)| on.matches(l, v) || off.matches(l, v));
                if contact || c.restart.matches(l, v) || c.cut.matches(l, v) {
                    event = true;
                } else if Self::any(&c.point, l, v) {
                    point = true;
                } else if let Some(s) =
                    c.switches.iter().enumerate().find_map(|(i, (on, off))| {
                        (on.matches(l, v) || off.matches(l, v)).then_some((i, on.matches(l, v)))
                    })
                {
                    switch = Some(s);
                    switches += 1;
                } else {
                    other = true;
                }
            } else if l == c.feed_word {
                feed = true;
            } else if l == c.line_number_word {
            } else if self.axes.contains(&l) {
                axis = true;
            } else if l == c.mask_word {
                mask = true;
            } else if parameters {
            } else if "IJKR".contains(l) {
                arc = true;
            } else {
                other = true;
            }
        }
        if other || switches > 1 {
            return Kind::Undescribed;
        }
        let modal = motion || distance || plane || feed;
        if arc {
            return if (axis || motion) && !(event || set_pos || non_motion || point || switch.is_some() || mask) {
                Kind::Arc
            } else {
                Kind::Undescribed
            };
        }
        if lexed.words.iter().all(|w| w.letter == c.line_number_word) {
            return Kind::Empty;
        }
        if event {
            return if !(modal || set_pos || non_motion || point || switch.is_some() || axis) {
                Kind::Event
            } else if axis && !set_pos && !non_motion && !point && switch.is_none() {
                // Tow or contact codes written on a move.
                Kind::Move
            } else {
                Kind::Undescribed
            };
        }
        if set_pos {
            return if axis && !(modal || non_motion || point || switch.is_some() || mask) {
                Kind::SetPosition
            } else {
                Kind::Undescribed
            };
        }
        if non_motion || point {
            return if !(modal || switch.is_some()) { Kind::Point } else { Kind::Undescribed };
        }
        if let Some((i, on)) = switch {
            if modal || axis {
                return Kind::Undescribed;
            }
            let words = lexed
                .words
                .iter()
                .filter(|w| w.letter != c.line_number_word && w.letter != 'M')
                .map(|w| (w.letter, w.text.to_string()))
                .collect();
            return Kind::Switch((i, words), on);
        }
        if mask {
            return Kind::Undescribed;
        }
        if axis {
            Kind::Move
        } else {
            Kind::Modes
        }
    }

    /// True for a transit line towpath writes: a rapid move (a distance code allowed before
    /// it), a set-position line, or a mode line; nothing else on it, no comment, no number.
    fn is_transit(&self, line: &str) -> bool {
        let Some(lexed) = self.lex(line) else { return false };
        if !lexed.comments.is_empty() || lexed.words.is_empty() {
            return false;
        }
        let c = &self.codes;
        let axis = |l: char| self.axes.contains(&l);
        let words = &lexed.words;
        let all = |f: &dyn Fn(char, f64) -> bool| words.iter().all(|w| f(w.letter, w.value));
        let distance = |l: char, v: f64| c.absolute.matches(l, v) || c.incremental.matches(l, v);
        let rapid_move = words.iter().filter(|w| w.letter == 'G' && Self::any(&c.rapid, 'G', w.value)).count() == 1
            && words.iter().any(|w| axis(w.letter))
            && all(&|l, v| axis(l) || (l == 'G' && (Self::any(&c.rapid, l, v) || distance(l, v))));
        let set_position = words.first().is_some_and(|w| c.set_position.matches(w.letter, w.value))
            && words.len() > 1
            && words[1..].iter().all(|w| axis(w.letter));
        let modes = all(&|l, v| {
            (l == 'G'
                && (Self::any(&c.rapid, l, v)
                    || Self::any(&c.feed, l, v)
                    || Self::any(&c.arc_cw, l, v)
                    || Self::any(&c.arc_ccw, l, v)
                    || Self::any(&c.planes, l, v)
                    || distance(l, v)))
                || l == c.feed_word
        });
        rapid_move || set_position || modes
    }

    /// True for a comment-only ply marker line (`(PLY 2 …)`).
    fn ply_marker(&self, line: &str) -> Option<Option<i64>> {
        let lexed = self.lex(line)?;
        if !lexed.words.is_empty() || lexed.comments.len() != 1 {
            return None;
        }
        let t = lexed.comments[0].trim();
        let p = self.dialect.ply_comment.trim();
        let head = t.get(..p.len())?;
        if !head.eq_ignore_ascii_case(p) || t[p.len()..].chars().next().is_some_and(|ch| ch.is_ascii_alphabetic()) {
            return None;
        }
        let rest = t[p.len()..].trim_start();
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        Some(digits.parse().ok())
    }
}

fn bare(line: &str) -> &str {
    line.trim_end_matches('\r')
}

/// The header and the footer must be the original's, line for line, at the start and the end;
/// the first difference is named: a line inserted, a line missing, or a line changed.
pub(crate) fn check_header_footer(orig: &Program, opt: &Program) -> Result<(), VerifyError> {
    let o: Vec<&str> = orig.lines.iter().map(|l| bare(l)).collect();
    let k: Vec<&str> = opt.lines.iter().map(|l| bare(l)).collect();
    let header = &o[..orig.header_end];
    if let Some(j) = (0..header.len()).find(|&j| k.get(j) != Some(&header[j])) {
        return Err(difference(&o, &k, j, j, "in the header"));
    }
    let footer = &o[orig.footer_start..];
    let n = footer.len();
    if k.len() < orig.header_end + n {
        let j = orig.footer_start.min(o.len().saturating_sub(1));
        return Err(VerifyError::LostLine { line: j + 1, text: o.get(j).copied().unwrap_or("").to_string() });
    }
    let off = k.len() - n;
    if k[off..] == *footer {
        return Ok(());
    }
    // Extra lines after the footer?
    for start in (orig.header_end..off).rev() {
        if k[start..start + n] == *footer {
            let extra = start + n;
            return Err(VerifyError::ExtraLine {
                line: extra + 1,
                text: k[extra].to_string(),
                place: "after the original's footer".into(),
            });
        }
    }
    // Cut short: the program ends with the footer's first lines.
    for m in (1..n).rev() {
        if k.len() >= m && k[k.len() - m..] == footer[..m] {
            return Err(VerifyError::LostLine { line: orig.footer_start + m + 1, text: footer[m].to_string() });
        }
    }
    // Align from the end: the last footer line that differs.
    let i = (0..n).rev().find(|&i| k[off + i] != footer[i]).unwrap_or(0);
    let (oj, kj) = (orig.footer_start + i, off + i);
    // Read backwards: the optimized line is the original's line before (one is missing), or
    // the original line is the optimized line before (one was added), or it is changed.
    if oj > 0 && o.get(oj - 1) == k.get(kj) {
        return Err(VerifyError::LostLine { line: oj + 1, text: o[oj].to_string() });
    }
    if kj > 0 && k.get(kj - 1) == o.get(oj) {
        return Err(VerifyError::ExtraLine { line: kj + 1, text: k[kj].to_string(), place: "in the footer".into() });
    }
    Err(difference(&o, &k, oj, kj, "in the footer"))
}

/// The error for original line `oj` against optimized line `kj` where they first differ.
fn difference(o: &[&str], k: &[&str], oj: usize, kj: usize, place: &str) -> VerifyError {
    match (o.get(oj), k.get(kj)) {
        (Some(a), Some(b)) if k.get(kj + 1) == Some(a) => {
            let _ = b;
            VerifyError::ExtraLine { line: kj + 1, text: k[kj].to_string(), place: place.to_string() }
        }
        (Some(a), Some(b)) if o.get(oj + 1) == Some(b) => VerifyError::LostLine { line: oj + 1, text: a.to_string() },
        (Some(a), Some(b)) => VerifyError::ExtraLine {
            line: kj + 1,
            text: b.to_string(),
            place: format!("{place}, where the original has line {} ({a:?})", oj + 1),
        },
        (Some(a), None) => VerifyError::LostLine { line: oj + 1, text: a.to_string() },
        (None, Some(b)) => VerifyError::ExtraLine { line: kj + 1, text: b.to_string(), place: place.to_string() },
        (None, None) => VerifyError::LostLine { line: oj + 1, text: String::new() },
    }
}

/// The lines of optimized course `kc` laid forward as original course `oc`: its on-part block
/// with as many lines before and after it as the original's approach and retract blocks have.
fn forward_block(orig: &Program, oc: usize, opt: &Program, kc: usize) -> Option<Range<usize>> {
    let (o, k) = (&orig.courses[oc], &opt.courses[kc]);
    let before = o.on_part.start - o.span.start;
    let after = o.span.end - o.on_part.end;
    let start = k.on_part.start.checked_sub(before)?;
    let end = k.on_part.end + after;
    (end <= opt.lines.len()).then_some(start..end)
}

/// The lines of optimized course `kc` written anew: from its first move in `window` (segment
/// indices) or its on-part block, whichever comes first, to the last.
fn rewritten_block(opt: &Program, kc: usize, window: &Range<usize>) -> Range<usize> {
    let k = &opt.courses[kc];
    let first = opt.segments.get(window.start).filter(|_| !window.is_empty()).map(|s| s.line as usize);
    let last = window
        .end
        .checked_sub(1)
        .and_then(|i| opt.segments.get(i))
        .filter(|_| !window.is_empty())
        .map(|s| s.line as usize);
    let start = first.map_or(k.on_part.start, |f| f.min(k.on_part.start));
    let end = last.map_or(k.on_part.end, |l| (l + 1).max(k.on_part.end));
    start..end
}

/// A span's point and switch lines: (line, text, station, kind), the station being the number of
/// the span's moves before the line.
fn still_lines(
    reader: &Reader,
    p: &Program,
    lines: Range<usize>,
    segs: &Range<usize>,
) -> Result<Vec<(usize, String, usize, Kind)>, String> {
    let mut out = Vec::new();
    for j in lines {
        let text = bare(&p.lines[j]);
        let station = p.segments[segs.clone()].iter().filter(|s| (s.line as usize) < j).count();
        let refuse = |why: &str| {
            Err(format!("original line {} ({text:?}) {why}, so the course may only be laid forward", j + 1))
        };
        match reader.kind(text) {
            Kind::Undescribed => return refuse("holds words the dialect does not describe"),
            Kind::Arc => return refuse("is an arc"),
            Kind::SetPosition => return refuse("sets positions"),
            k @ (Kind::Point | Kind::Switch(..)) => out.push((j, text.to_string(), station, k)),
            Kind::Empty if !text.trim().is_empty() => out.push((j, text.to_string(), station, Kind::Point)),
            _ => {}
        }
    }
    Ok(out)
}

/// Stretches (first station, last station) each switch is on, as sorted (switch, from, to).
fn switch_stretches(lines: &[(usize, String, usize, Kind)]) -> Result<Vec<(String, usize, usize)>, String> {
    let mut open: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    for (j, text, station, kind) in lines {
        let Kind::Switch(key, on) = kind else { continue };
        let key = format!("{key:?}");
        match (on, open.remove(&key)) {
            (true, None) => {
                open.insert(key, *station);
            }
            (false, Some(from)) => out.push((key, from, *station)),
            (true, Some(_)) => return Err(format!("line {} ({text:?}) switches on what is already on", j + 1)),
            (false, None) => {
                return Err(format!("line {} ({text:?}) switches off what the course did not switch on", j + 1))
            }
        }
    }
    if let Some((key, _)) = open.into_iter().next() {
        return Err(format!("switch {key} is left on at the end of the course"));
    }
    out.sort();
    Ok(out)
}

/// Checks the lines of optimized course `kc` as original course `oc` written anew, reversed or
/// (a reversal reversed again) forward, its moves being `window` (segment indices of `opt`,
/// already checked point by point): nothing but moves, tow and contact lines, and the
/// original's point and switch lines at the same points (mirrored if reversed), switches on
/// along the same stretches; and the original span holds nothing the dialect does not describe.
pub(crate) fn rewritten_lines(
    orig: &Program,
    oc: usize,
    opt: &Program,
    kc: usize,
    window: Range<usize>,
    reversed: bool,
    dialect: &Dialect,
    machine: &Machine,
) -> Result<(), String> {
    let Some(reader) = Reader::new(dialect, machine) else { return Err("the dialect cannot be read".into()) };
    let course = &orig.courses[oc];
    let n = course.segments.len();
    let original = still_lines(&reader, orig, course.span.clone(), &course.segments)?;
    let block = rewritten_block(opt, kc, &window);
    let at = |s: usize| if reversed { n - s } else { s };
    let mut written = Vec::new();
    for j in block.clone() {
        let text = bare(&opt.lines[j]);
        let station = opt.segments[window.clone()].iter().filter(|s| (s.line as usize) < j).count();
        let moves_here = opt.line_segment.get(j).copied().flatten().is_some_and(|s| window.contains(&(s as usize)));
        match reader.kind(text) {
            Kind::Move if moves_here => {}
            Kind::Event => {}
            k @ (Kind::Point | Kind::Switch(..)) => written.push((j, text.to_string(), station, k)),
            Kind::Empty if text.trim().is_empty() => {}
            Kind::Empty => written.push((j, text.to_string(), station, Kind::Point)),
            _ => {
                return Err(format!(
                    "optimized line {} ({text:?}) is no part of a course written anew (moves, tow and contact \
                     codes, and the course's own comments, point codes and switches)",
                    j + 1
                ))
            }
        }
    }
    // The same point lines, each at the mirrored point.
    let mut want: Vec<(String, usize)> =
        original.iter().filter(|l| l.3 == Kind::Point).map(|l| (l.1.clone(), at(l.2))).collect();
    let mut have: Vec<(String, usize)> =
        written.iter().filter(|l| l.3 == Kind::Point).map(|l| (l.1.clone(), l.2)).collect();
    want.sort();
    have.sort();
    if want != have {
        let missing = want.iter().find(|w| !have.contains(w));
        return Err(match missing {
            Some((t, s)) => format!("the original's line {t:?} is not at its point (after move {s} of the course)"),
            None => "it holds comment or point lines the original's course does not".into(),
        });
    }
    // The same switches, on along the mirrored stretches.
    let a = switch_stretches(&original).map_err(|e| format!("original {e}"))?;
    let b = switch_stretches(&written).map_err(|e| format!("optimized {e}"))?;
    let mut mirrored: Vec<(String, usize, usize)> =
        a.into_iter().map(|(k, f, t)| if reversed { (k, n - t, n - f) } else { (k, f, t) }).collect();
    mirrored.sort();
    if mirrored != b {
        return Err("its switches are not on along the stretches the original's are".into());
    }
    // Every switch line of the original is written (switch texts trade places within a pair).
    let count = |v: &[(usize, String, usize, Kind)]| {
        let mut t: Vec<String> = v.iter().filter(|l| matches!(l.3, Kind::Switch(..))).map(|l| l.1.clone()).collect();
        t.sort();
        t
    };
    if count(&original) != count(&written) {
        return Err("its switch lines are not the original's".into());
    }
    Ok(())
}

/// Every line of the optimized program is accounted for (see the module docs), and every line
/// of the original. `order[k]` is optimized course k as an original course; `windows[k]` the
/// moves of a reversed course (segment indices of `opt`).
pub(crate) fn account(
    orig: &Program,
    opt: &Program,
    order: &[Placement],
    windows: &[Option<Range<usize>>],
    dialect: &Dialect,
    machine: &Machine,
) -> Result<(), VerifyError> {
    let Some(reader) = Reader::new(dialect, machine) else { return Ok(()) };
    let footer_len = orig.lines.len() - orig.footer_start;
    let footer_start = opt.lines.len() - footer_len;
    let blocks = course_blocks(orig, opt, order, windows, dialect, machine, footer_start)?;
    let missing_marker = between_courses(orig, opt, order, &blocks, &reader, footer_start)?;
    same_switches(orig, opt, order, &blocks, &reader, footer_start)?;
    match missing_marker {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Each optimized course's block of lines (in the optimized program's order): the original's
/// lines as they were, or a reversal's lines as the rules of a reversal write them; blocks in
/// order, none inside the header, the footer or another.
fn course_blocks(
    orig: &Program,
    opt: &Program,
    order: &[Placement],
    windows: &[Option<Range<usize>>],
    dialect: &Dialect,
    machine: &Machine,
    footer_start: usize,
) -> Result<Vec<Range<usize>>, VerifyError> {
    // The courses' blocks, in the optimized program's order.
    let len = opt.lines.len();
    let mut blocks: Vec<Range<usize>> = Vec::with_capacity(order.len());
    for (kc, p) in order.iter().enumerate() {
        let name = || orig.course_name(p.course);
        let block = match (&windows[kc], p.reversed) {
            (Some(w), true) => rewritten_block(opt, kc, w),
            (w, _) => {
                let span = orig.courses[p.course].span.clone();
                let o: Vec<&str> = orig.lines[span.clone()].iter().map(|l| bare(l)).collect();
                let b = forward_block(orig, p.course, opt, kc);
                let differs = match &b {
                    Some(b) => {
                        let k: Vec<&str> = opt.lines[b.clone()].iter().map(|l| bare(l)).collect();
                        (0..o.len()).find(|&i| o[i] != k[i])
                    }
                    None => Some(0),
                };
                // Written anew forward (a reversal reversed again), by the rules of a reversal.
                let anew = || {
                    w.as_ref().is_some_and(|w| {
                        rewritten_lines(orig, p.course, opt, kc, w.clone(), false, dialect, machine).is_ok()
                    })
                };
                match (b, differs) {
                    (Some(b), None) => b,
                    (_, Some(_)) if anew() => rewritten_block(opt, kc, w.as_ref().unwrap_or(&(0..0))),
                    (Some(b), Some(i)) => {
                        // Name the first line where the optimized course and the original differ.
                        let all: Vec<&str> = opt.lines.iter().map(|l| bare(l)).collect();
                        let orig_all: Vec<&str> = orig.lines.iter().map(|l| bare(l)).collect();
                        return Err(difference(
                            &orig_all,
                            &all,
                            span.start + i,
                            b.start + i,
                            &format!("in {}", name()),
                        ));
                    }
                    (None, _) => {
                        return Err(VerifyError::LostLine {
                            line: span.start + 1,
                            text: o.first().unwrap_or(&"").to_string(),
                        })
                    }
                }
            }
        };
        if blocks.last().is_some_and(|l: &Range<usize>| block.start < l.end)
            || block.start < orig.header_end
            || block.end > footer_start
        {
            return Err(VerifyError::ExtraLine {
                line: block.start + 1,
                text: bare(&opt.lines[block.start.min(len - 1)]).to_string(),
                place: format!("where {} starts, inside another course or the header or footer", name()),
            });
        }
        blocks.push(block);
    }
    Ok(blocks)
}

/// The lines between the course blocks: each one travels with a course (once), is a ply
/// comment, a transit, one of the original's on-part lines the rewriter may repeat, or it is
/// extra. Every line that must travel is found. A ply comment that is missing is returned (not
/// failed on), so that the switch check speaks first.
fn between_courses(
    orig: &Program,
    opt: &Program,
    order: &[Placement],
    blocks: &[Range<usize>],
    reader: &Reader,
    footer_start: usize,
) -> Result<Option<VerifyError>, VerifyError> {
    // Ply comments of plies with courses may move and repeat; every one must be there (those
    // between courses: one inside a span, where a long retract block reaches, stays with it).
    let between = |j: usize| {
        orig.courses
            .iter()
            .any(|c| [&c.pre_before, &c.pre_after, &c.post].iter().any(|items| items.contains(&Item::Line(j))))
    };
    let mut marker_lines: Vec<usize> =
        orig.plies.iter().filter(|p| !p.courses.is_empty()).filter_map(|p| p.line).filter(|&j| between(j)).collect();
    marker_lines.sort_unstable();
    let marker_texts: Vec<&str> = marker_lines.iter().map(|&j| bare(&orig.lines[j])).collect();
    let mut markers_seen = vec![false; marker_lines.len()];
    // Copies of any ply comment may stand between courses (the rewriter repeats them where a ply
    // starts again).
    let any_marker: Vec<&str> = orig
        .plies
        .iter()
        .filter(|p| !p.courses.is_empty())
        .filter_map(|p| p.line)
        .map(|j| bare(&orig.lines[j]))
        .collect();
    let first_ply_unmarked = orig.plies.first().is_some_and(|p| p.line.is_none() && !p.courses.is_empty());
    // Every line that travels with a course, exactly once (where is not checked: look-alike
    // courses may be matched either way round), and the original's transit lines, which the
    // original order keeps.
    let mut need: Vec<(usize, Vec<&str>)> = Vec::new();
    let mut optional: HashMap<&str, usize> = HashMap::new();
    for c in &orig.courses {
        for items in [&c.pre_before, &c.pre_after, &c.post] {
            travelling(orig, items, &marker_lines, &mut need);
        }
        for j in c.middle.clone().filter(|&j| orig.line_segment[j].is_some()) {
            *optional.entry(bare(&orig.lines[j])).or_default() += 1;
        }
    }
    let mut by_text: HashMap<&str, Vec<usize>> = HashMap::new();
    for (x, (_, alts)) in need.iter().enumerate() {
        for t in alts {
            by_text.entry(t).or_default().push(x);
        }
    }
    let mut used = vec![false; need.len()];
    // The regions between blocks: before course k (k = 0..), and after the last.
    for r in 0..=blocks.len() {
        let lo = if r == 0 { orig.header_end } else { blocks[r - 1].end };
        let hi = if r == blocks.len() { footer_start } else { blocks[r].start };
        for j in lo..hi {
            let text = bare(&opt.lines[j]);
            if let Some(x) = by_text.get_mut(text).and_then(|v| {
                while v.last().is_some_and(|&x| used[x]) {
                    v.pop();
                }
                v.pop()
            }) {
                used[x] = true;
                continue;
            }
            if any_marker.contains(&text) {
                for (seen, t) in markers_seen.iter_mut().zip(&marker_texts) {
                    *seen |= *t == text;
                }
                continue;
            }
            if reader.is_transit(text) {
                continue;
            }
            if let Some(n) = optional.get_mut(text).filter(|n| **n > 0) {
                *n -= 1;
                continue;
            }
            if first_ply_unmarked && reader.ply_marker(text) == Some(Some(0)) {
                continue;
            }
            let place = match (r, order.get(r)) {
                (0, _) => "before the first course".to_string(),
                (_, Some(p)) => format!("between courses, before {}", orig.course_name(p.course)),
                (_, None) => "after the last course".to_string(),
            };
            return Err(VerifyError::ExtraLine { line: j + 1, text: text.to_string(), place });
        }
    }
    if let Some((j, alts)) = need.iter().zip(&used).filter(|(_, u)| !**u).map(|(n, _)| n).min_by_key(|n| n.0) {
        return Err(VerifyError::LostLine { line: j + 1, text: alts.last().copied().unwrap_or("").to_string() });
    }
    Ok(markers_seen
        .iter()
        .position(|s| !s)
        .map(|m| VerifyError::LostLine { line: marker_lines[m] + 1, text: marker_texts[m].to_string() }))
}

/// Each course runs with the switches on that it ran with in the original (a reversed one
/// switches nothing that is on where it starts), and so does the footer.
fn same_switches(
    orig: &Program,
    opt: &Program,
    order: &[Placement],
    blocks: &[Range<usize>],
    reader: &Reader,
    footer_start: usize,
) -> Result<(), VerifyError> {
    let states = |p: &Program| {
        let mut on: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
        let mut before = Vec::with_capacity(p.lines.len() + 1);
        for l in &p.lines {
            before.push(on.clone());
            if let Kind::Switch(key, is_on) = reader.kind(bare(l)) {
                let key = format!("{key:?}");
                if is_on {
                    on.insert(key);
                } else {
                    on.remove(&key);
                }
            }
        }
        before.push(on);
        before
    };
    if !reader.codes.switches.is_empty() {
        let (a, b) = (states(orig), states(opt));
        for (kc, p) in order.iter().enumerate() {
            let span = orig.courses[p.course].span.clone();
            let want = &a[span.start];
            let have = &b[blocks[kc].start];
            if p.reversed {
                // Reversed, a switch turned on and off within the course must be off where it starts.
                if let Some(key) = span.clone().find_map(|j| match reader.kind(bare(&orig.lines[j])) {
                    Kind::Switch(key, _) => Some(format!("{key:?}")).filter(|k| want.contains(k)),
                    _ => None,
                }) {
                    return Err(VerifyError::Order(format!(
                        "{} is laid reversed, but it switches {key} which is on where it starts: reversed, that \
                         switch would not be on along the same stretch",
                        orig.course_name(p.course)
                    )));
                }
            }
            if want != have {
                return Err(VerifyError::Order(format!(
                    "{} is laid with the switches {:?} on (optimized line {}), the original with {:?}",
                    orig.course_name(p.course),
                    have,
                    blocks[kc].start + 1,
                    want
                )));
            }
        }
        if a[orig.footer_start] != b[footer_start] {
            return Err(VerifyError::Order(format!(
                "the footer runs with the switches {:?} on, the original's with {:?}",
                b[footer_start], a[orig.footer_start]
            )));
        }
    }
    Ok(())
}

/// The texts of lines that travel with a course (ply comments of plies with courses apart, which
/// may move): each with the texts it may be written as (a transit line's kept words on a line
/// of their own, or the whole original line where the transit itself was kept).
fn travelling<'p>(orig: &'p Program, items: &'p [Item], markers: &[usize], need: &mut Vec<(usize, Vec<&'p str>)>) {
    for item in items {
        match item {
            Item::Line(j) if markers.binary_search(j).is_ok() => {}
            Item::Line(j) => need.push((*j, vec![bare(&orig.lines[*j])])),
            Item::Kept(j, t) => need.push((*j, vec![t.as_str(), bare(&orig.lines[*j])])),
        }
    }
}
