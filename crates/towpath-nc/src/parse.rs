//! The parser: program text → [`Program`] (plies → courses with approach, on-part and retract
//! blocks, the middle regions between them, header and footer).
//!
//! Two passes over the lines with the [`Interp`]: the first finds the motion, the courses and
//! the markers; the second records the machine state at the boundaries the structure needs.

use towpath_machine::Machine;

use crate::dialect::{Codes, Dialect};
use crate::error::NcError;
use crate::interp::{Interp, Marker, Modal};
use crate::lex::Lexed;
use crate::program::{Course, Item, LineBreak, Ply, Program, Segment, SwitchKey};

/// What pass 1 learns of a line.
#[derive(Clone, Debug, Default)]
struct LineFacts {
    motion: bool,
    marker: Option<Marker>,
    /// Text kept if the line's motion is regenerated (comments, unknown words).
    residue: Option<String>,
}

/// What pass 1 learns of the whole program: each line's facts, every move, and the on-part
/// blocks.
struct Pass1 {
    facts: Vec<LineFacts>,
    points: Vec<f64>,
    segments: Vec<Segment>,
    line_segment: Vec<Option<u32>>,
    /// On-part blocks, as lines `[s, e]` (both included).
    spans: Vec<(usize, usize)>,
}

/// One course while the parser finds its parts: its line boundaries, ply and number, the lines
/// that travel with it and the switches on where its span starts.
#[derive(Clone, Debug, Default)]
struct CourseDraft {
    /// The on-part block, lines `[s, e]` (both included).
    on_part: (usize, usize),
    /// First line of the span (the approach block's first move).
    span_start: usize,
    /// Line after the span (after the retract block's last move).
    span_end: usize,
    /// First line of the middle region before the span.
    middle_start: usize,
    /// Line where the regenerated transit into the course goes (after the middle region's last
    /// move).
    insert_at: usize,
    ply: usize,
    number: Option<i64>,
    pre_before: Vec<Item>,
    pre_after: Vec<Item>,
    post: Vec<Item>,
    switches_on: Vec<SwitchKey>,
}

/// Parses a program for a machine in a dialect. Lines may end with LF, CRLF or (in a program
/// without any LF) CR alone; a CR alone in the middle of a line of an LF or CRLF program (mixed
/// line ends, which would silently join two lines) is refused, naming the line.
pub fn parse(text: &str, machine: &Machine, dialect: &Dialect) -> Result<Program, NcError> {
    let (lines, final_newline, breaks) = split_lines(text, dialect)?;
    let codes = dialect.codes()?;
    let dim = machine.dim();

    // Pass 1: motion, courses, markers.
    let pass1 = read_motion(&lines, machine, dialect, &codes)?;
    // Structure: spans, middles, header and footer; plies; which lines go where.
    let (mut drafts, header_end) = course_bounds(&pass1, dialect, lines.len());
    let footer_start = drafts.last().map_or(lines.len(), |d| d.span_end);
    let plies = assign_plies(&pass1.facts, &mut drafts);
    place_middle_lines(&pass1.facts, &mut drafts);
    // Pass 2: machine states at the boundaries.
    let snaps = Snapshots::take(&lines, machine, dialect, header_end, &drafts)?;
    switches_at_span_starts(&lines, dialect, &codes, &mut drafts);

    let Pass1 { points, segments, line_segment, .. } = pass1;
    let seg_index = |line: usize| segments.partition_point(|s| (s.line as usize) < line);
    let courses = drafts
        .into_iter()
        .map(|d| Course {
            ply: d.ply,
            number: d.number,
            middle: d.middle_start..d.span_start,
            pre_before: d.pre_before,
            pre_after: d.pre_after,
            post: d.post,
            span: d.span_start..d.span_end,
            on_part: d.on_part.0..d.on_part.1 + 1,
            segments: seg_index(d.span_start)..seg_index(d.span_end),
            insert: snaps.at(d.insert_at),
            span_start: snaps.at(d.span_start),
            exit: snaps.at(d.span_end),
            switches_on: d.switches_on,
        })
        .collect();
    Ok(Program {
        start: snaps.at(header_end),
        end: snaps.at(lines.len()),
        lines,
        final_newline,
        breaks,
        dim,
        points,
        segments,
        line_segment,
        header_end,
        courses,
        plies,
        footer_start,
    })
}

/// Splits the text into lines (see [`parse`]): the lines, whether the text ended with a line
/// break, and which.
fn split_lines(text: &str, dialect: &Dialect) -> Result<(Vec<String>, bool, LineBreak), NcError> {
    let breaks = if !text.contains('\n') && text.contains('\r') { LineBreak::Cr } else { LineBreak::Lf };
    let sep = breaks.separator();
    let mut lines: Vec<String> = text.split(sep).map(str::to_string).collect();
    let final_newline = text.ends_with(sep);
    if final_newline {
        lines.pop();
    }
    if breaks == LineBreak::Lf {
        for (i, l) in lines.iter().enumerate() {
            if stray_cr(l.trim_end_matches('\r'), dialect) {
                return Err(NcError::line(
                    i + 1,
                    "a carriage return (CR) in the middle of the line: the program mixes line ends (CR alone \
                     and LF); give it one kind of line end (LF, CRLF or CR)",
                ));
            }
        }
    }
    Ok((lines, final_newline, breaks))
}

/// Pass 1: runs the interpreter over every line, recording the moves (an arc as its chords),
/// where courses open and close, and each line's facts.
fn read_motion(lines: &[String], machine: &Machine, dialect: &Dialect, codes: &Codes) -> Result<Pass1, NcError> {
    let dim = machine.dim();
    let timing_after = dialect.event_timing == crate::dialect::EventTiming::After;
    let mut it = Interp::new(dialect, machine)?;
    let has_contact = it.has_contact();
    let in_course = |contact: bool, mask: u64| if has_contact { contact } else { mask != 0 };
    let mut p = Pass1 {
        facts: Vec::with_capacity(lines.len()),
        points: it.m.phys.clone(),
        segments: Vec::new(),
        line_segment: vec![None; lines.len()],
        spans: Vec::new(),
    };
    let mut open: Option<usize> = None;
    for (i, line) in lines.iter().enumerate() {
        let (before_contact, before_mask) = (it.m.contact, it.m.mask);
        let a = it.apply(i, line).map_err(|e| name_open_course(e, open, has_contact, dialect))?;
        let was = in_course(before_contact, before_mask);
        let now = in_course(it.m.contact, it.m.mask);
        if let Some(m) = &a.marker {
            if was || now {
                let what = if matches!(m, Marker::Ply(..)) { "ply" } else { "course" };
                let opened = open.map_or(i, |o| o + 1);
                return Err(NcError::line(
                    i + 1,
                    format!("{what} marker inside the course opened at line {opened}: that course is never closed"),
                ));
            }
        }
        if let Some(kind) = a.motion {
            // The state during the move: before the line's events if they come after it.
            let (contact, mask) = if timing_after { (before_contact, before_mask) } else { (it.m.contact, it.m.mask) };
            // An arc is laid as its chords: one segment per piece, all on this line.
            p.line_segment[i] = Some(p.segments.len() as u32);
            for point in a.path.iter().map(Vec::as_slice).chain(std::iter::once(it.m.phys.as_slice())) {
                let from = (p.points.len() / dim.max(1) - 1) as u32;
                p.points.extend_from_slice(point);
                p.segments.push(Segment {
                    line: i as u32,
                    from,
                    to: from + 1,
                    rapid: kind.is_rapid(),
                    feed: it.m.feed.as_ref().map_or(f64::NAN, |f| f.0),
                    mask,
                    on_part: in_course(contact, mask),
                });
            }
        }
        // A line that both opens and closes a course would leave an empty on-part block.
        let toggles = a.events().filter(|e| e.is_contact()).count();
        if has_contact && toggles >= 2 && a.events().any(|e| *e == crate::interp::Event::ContactOn) {
            return Err(NcError::line(i + 1, "roller contact on and off on the same line"));
        }
        match (was, now) {
            (false, true) => open = Some(i),
            (true, false) => {
                let s = open.take().unwrap_or(i);
                p.spans.push((s, i));
            }
            _ => {}
        }
        let residue = if a.motion.is_some() { residue(line, a.lexed.as_ref(), codes, &it) } else { None };
        p.facts.push(LineFacts { motion: a.motion.is_some(), marker: a.marker, residue });
    }
    if let Some(s) = open {
        let close = if has_contact {
            format!("no {} before the end of the program", dialect.contact_off)
        } else {
            "its tows are never all cut".to_string()
        };
        return Err(NcError::line(s + 1, format!("the course opened here is never closed ({close})")));
    }
    if p.spans.is_empty() {
        let what =
            if has_contact { format!("no {} roller contact", dialect.contact_on) } else { "no tow restart".into() };
        return Err(NcError::Request(format!("the program has no courses ({what} found)")));
    }
    Ok(p)
}

/// Says which course a line towpath cannot read inside a course is in: often a course that
/// was never closed running into the footer.
fn name_open_course(e: NcError, open: Option<usize>, has_contact: bool, dialect: &Dialect) -> NcError {
    match (e, open) {
        (NcError::InCourse { line, message }, Some(o)) => {
            let end = if has_contact { dialect.contact_off.as_str() } else { "last tow cut" };
            NcError::Line {
                line,
                message: format!(
                    "{message}, inside the course opened at line {} (if that course should have ended before, its \
                     {end} is missing)",
                    o + 1
                ),
            }
        }
        (NcError::InCourse { line, message }, None) => NcError::Line { line, message },
        (e, _) => e,
    }
}

/// The courses' line boundaries: each span takes the dialect's approach moves before its
/// on-part block and retract moves after it; the middle region before a course runs from the
/// previous span's end (from the header's end for the first). Returns the drafts and the
/// header's end (the first marker, or without one the first move).
fn course_bounds(pass1: &Pass1, dialect: &Dialect, n_lines: usize) -> (Vec<CourseDraft>, usize) {
    let (facts, spans) = (&pass1.facts, &pass1.spans);
    let k = spans.len();
    let motion_lines = |lo: usize, hi: usize| -> Vec<usize> { (lo..hi).filter(|&j| facts[j].motion).collect() };
    let mut drafts: Vec<CourseDraft> =
        spans.iter().map(|&on_part| CourseDraft { on_part, ..CourseDraft::default() }).collect();
    for c in 0..k {
        let lo = if c == 0 { 0 } else { spans[c - 1].1 + 1 };
        let hi = spans[c].0;
        let ms = motion_lines(lo, hi);
        let r = if c == 0 { 0 } else { dialect.retract_moves.min(ms.len()) };
        let a = dialect.approach_moves.min(ms.len() - r);
        if c > 0 {
            drafts[c - 1].span_end = if r > 0 { ms[r - 1] + 1 } else { lo };
            drafts[c].middle_start = drafts[c - 1].span_end;
        }
        drafts[c].span_start = if a > 0 { ms[ms.len() - a] } else { hi };
    }
    {
        let lo = spans[k - 1].1 + 1;
        let ms = motion_lines(lo, n_lines);
        let r = dialect.retract_moves.min(ms.len());
        drafts[k - 1].span_end = if r > 0 { ms[r - 1] + 1 } else { lo };
    }
    // The header runs to the first marker, or without one to the first move.
    let first = drafts[0].span_start;
    let header_end = (0..first)
        .find(|&j| facts[j].marker.is_some())
        .or_else(|| (0..first).find(|&j| facts[j].motion))
        .unwrap_or(first);
    drafts[0].middle_start = header_end;
    (drafts, header_end)
}

/// Plies and course numbers, in line order: each course joins the ply of the last ply marker
/// before its on-part block (a ply of its own if there is none) and takes the number of the
/// course marker since.
fn assign_plies(facts: &[LineFacts], drafts: &mut [CourseDraft]) -> Vec<Ply> {
    let k = drafts.len();
    let mut plies: Vec<Ply> = Vec::new();
    let mut c = 0;
    let mut pending_number: Option<i64> = None;
    for (j, f) in facts.iter().enumerate() {
        if c < k && j == drafts[c].on_part.0 {
            if plies.is_empty() {
                plies.push(Ply { label: "(no ply marker)".into(), number: None, line: None, courses: Vec::new() });
            }
            drafts[c].ply = plies.len() - 1;
            drafts[c].number = pending_number.take();
            if let Some(p) = plies.last_mut() {
                p.courses.push(c);
            }
            c += 1;
        }
        match &f.marker {
            Some(Marker::Ply(n, label)) => {
                plies.push(Ply { label: label.clone(), number: *n, line: Some(j), courses: Vec::new() });
                pending_number = None;
            }
            Some(Marker::Course(n)) => pending_number = *n,
            None => {}
        }
    }
    plies
}

/// Middle regions: which lines go where. Before the region's first marker (or without one its
/// first move) a line stays with the course before (`post`); after its last move it goes after
/// the regenerated transit (`pre_after`), else before it (`pre_before`). A transit line is kept
/// only for its residue (comments, unknown words).
fn place_middle_lines(facts: &[LineFacts], drafts: &mut [CourseDraft]) {
    for c in 0..drafts.len() {
        let (lo, hi) = (drafts[c].middle_start, drafts[c].span_start);
        let first_marker = (lo..hi).find(|&j| facts[j].marker.is_some());
        let first_motion = (lo..hi).find(|&j| facts[j].motion);
        let last_motion = (lo..hi).rev().find(|&j| facts[j].motion);
        drafts[c].insert_at = last_motion.map_or(hi, |l| l + 1);
        for j in lo..hi {
            let to_post = c > 0
                && match first_marker {
                    Some(fm) => j < fm,
                    None => first_motion.is_some_and(|f| j < f),
                };
            let item = if facts[j].motion {
                match &facts[j].residue {
                    Some(t) => Item::Kept(j, t.clone()),
                    None => continue,
                }
            } else {
                Item::Line(j)
            };
            if to_post {
                drafts[c - 1].post.push(item);
            } else if last_motion.is_some_and(|l| j > l) {
                drafts[c].pre_after.push(item);
            } else {
                drafts[c].pre_before.push(item);
            }
        }
    }
}

/// Machine states before chosen lines (pass 2), sorted by line.
struct Snapshots(Vec<(usize, Modal)>);

impl Snapshots {
    /// Pass 2: runs the interpreter again, keeping the state before the header's end, each
    /// course's transit end, span start and span end, and at the end of the program.
    fn take(
        lines: &[String],
        machine: &Machine,
        dialect: &Dialect,
        header_end: usize,
        drafts: &[CourseDraft],
    ) -> Result<Self, NcError> {
        let mut wanted: Vec<usize> = Vec::with_capacity(3 * drafts.len() + 2);
        wanted.push(header_end);
        for d in drafts {
            wanted.extend([d.insert_at, d.span_start, d.span_end]);
        }
        wanted.push(lines.len());
        wanted.sort_unstable();
        wanted.dedup();
        let mut snaps: Vec<(usize, Modal)> = Vec::with_capacity(wanted.len());
        let mut it = Interp::new(dialect, machine)?;
        let mut w = 0;
        for (i, line) in lines.iter().enumerate() {
            while w < wanted.len() && wanted[w] == i {
                snaps.push((i, it.m.clone()));
                w += 1;
            }
            it.apply(i, line)?;
        }
        while w < wanted.len() {
            snaps.push((wanted[w], it.m.clone()));
            w += 1;
        }
        Ok(Snapshots(snaps))
    }

    /// The state before line `i` (one of the lines asked for).
    fn at(&self, i: usize) -> Modal {
        let p = self.0.partition_point(|(j, _)| *j < i);
        self.0[p].1.clone()
    }
}

/// The dialect's switches on where each span starts, reading the program in its order.
fn switches_at_span_starts(lines: &[String], dialect: &Dialect, codes: &Codes, drafts: &mut [CourseDraft]) {
    if codes.switches.is_empty() {
        return;
    }
    let k = drafts.len();
    let mut on: Vec<SwitchKey> = Vec::new();
    let mut c = 0;
    for (j, line) in lines.iter().enumerate() {
        while c < k && drafts[c].span_start == j {
            drafts[c].switches_on = on.clone();
            c += 1;
        }
        if let Some((key, is_on)) = crate::reverse::switch_of(line, dialect, codes) {
            on.retain(|x| *x != key);
            if is_on {
                on.push(key);
                on.sort();
            }
        }
    }
}

/// True if a CR stands between words of the line, outside comments (where it would join what
/// was meant as two lines).
fn stray_cr(line: &str, dialect: &Dialect) -> bool {
    let Some(first) = line.find('\r') else { return false };
    let mut in_parens = false;
    for (i, c) in line.char_indices() {
        match c {
            '(' if dialect.comment_parens && !in_parens => in_parens = true,
            ')' if in_parens => in_parens = false,
            ';' if dialect.comment_semicolon && !in_parens => return false,
            // Only trailing whitespace after it is harmless.
            '\r' if !in_parens && i >= first && !line[i..].trim().is_empty() => return true,
            _ => {}
        }
    }
    false
}

/// The text of a motion line that is kept when its motion is regenerated: everything but the
/// motion words (rapid/feed/distance codes, axis words, feed, line number).
fn residue(line: &str, lexed: Option<&Lexed>, codes: &Codes, it: &Interp) -> Option<String> {
    let lexed = lexed?;
    let motion_word = |l: char, v: f64| {
        (l == 'G'
            && (codes.rapid.iter().chain(codes.feed.iter()).any(|c| c.matches(l, v))
                || codes.absolute.matches(l, v)
                || codes.incremental.matches(l, v)))
            || l == codes.feed_word
            || l == codes.line_number_word
            || it.axis_of(l).is_some()
    };
    let mut out = String::with_capacity(line.len());
    let mut last = 0;
    for w in &lexed.words {
        if motion_word(w.letter, w.value) {
            out.push_str(&line[last..w.span.start]);
            last = w.span.end;
        }
    }
    out.push_str(&line[last..]);
    let t = out.trim();
    if t.is_empty() {
        None
    } else {
        Some(t.to_string())
    }
}
