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
use crate::program::{Course, Item, LineBreak, Ply, Program, Segment};

/// What pass 1 learns of a line.
#[derive(Clone, Debug, Default)]
struct LineFacts {
    motion: bool,
    marker: Option<Marker>,
    /// Text kept if the line's motion is regenerated (comments, unknown words).
    residue: Option<String>,
}

/// Parses a program for a machine in a dialect. Lines may end with LF, CRLF or (in a program
/// without any LF) CR alone; a CR alone in the middle of a line of an LF or CRLF program (mixed
/// line ends, which would silently join two lines) is refused, naming the line.
pub fn parse(text: &str, machine: &Machine, dialect: &Dialect) -> Result<Program, NcError> {
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
    let codes = dialect.codes()?;
    let dim = machine.dim();
    let timing_after = dialect.event_timing == crate::dialect::EventTiming::After;

    // Pass 1: motion, courses, markers.
    let mut it = Interp::new(dialect, machine)?;
    let has_contact = it.has_contact();
    let mut facts: Vec<LineFacts> = Vec::with_capacity(lines.len());
    let mut points: Vec<f64> = it.m.phys.clone();
    let mut segments: Vec<Segment> = Vec::new();
    let mut line_segment: Vec<Option<u32>> = vec![None; lines.len()];
    let mut spans: Vec<(usize, usize)> = Vec::new(); // on-part lines [s, e]
    let mut open: Option<usize> = None;
    for (i, line) in lines.iter().enumerate() {
        let before_contact = it.m.contact;
        let before_mask = it.m.mask;
        let a = it.apply(i, line).map_err(|e| match (e, open) {
            // Say which course: a line towpath cannot read inside one is often a course that
            // was never closed running into the footer.
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
        })?;
        let in_course = |contact: bool, mask: u64| if has_contact { contact } else { mask != 0 };
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
            let rapid = kind.is_rapid();
            // The state during the move: before the line's events if they come after it.
            let (contact, mask) = if timing_after { (before_contact, before_mask) } else { (it.m.contact, it.m.mask) };
            // An arc is laid as its chords: one segment per piece, all on this line.
            line_segment[i] = Some(segments.len() as u32);
            for p in a.path.iter().map(Vec::as_slice).chain(std::iter::once(it.m.phys.as_slice())) {
                let from = (points.len() / dim.max(1) - 1) as u32;
                points.extend_from_slice(p);
                segments.push(Segment {
                    line: i as u32,
                    from,
                    to: from + 1,
                    rapid,
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
                spans.push((s, i));
            }
            _ => {}
        }
        let residue = if a.motion.is_some() { residue(line, a.lexed.as_ref(), &codes, &it) } else { None };
        facts.push(LineFacts { motion: a.motion.is_some(), marker: a.marker, residue });
    }
    if let Some(s) = open {
        let close = if has_contact {
            format!("no {} before the end of the program", dialect.contact_off)
        } else {
            "its tows are never all cut".to_string()
        };
        return Err(NcError::line(s + 1, format!("the course opened here is never closed ({close})")));
    }
    if spans.is_empty() {
        let what =
            if has_contact { format!("no {} roller contact", dialect.contact_on) } else { "no tow restart".into() };
        return Err(NcError::Request(format!("the program has no courses ({what} found)")));
    }

    // Structure: spans, middles, header and footer.
    let k = spans.len();
    let motion_lines = |lo: usize, hi: usize| -> Vec<usize> { (lo..hi).filter(|&j| facts[j].motion).collect() };
    let mut span_start = vec![0usize; k];
    let mut span_end = vec![0usize; k];
    let mut middle_start = vec![0usize; k];
    for c in 0..k {
        let lo = if c == 0 { 0 } else { spans[c - 1].1 + 1 };
        let hi = spans[c].0;
        let ms = motion_lines(lo, hi);
        let r = if c == 0 { 0 } else { dialect.retract_moves.min(ms.len()) };
        let a = dialect.approach_moves.min(ms.len() - r);
        if c > 0 {
            span_end[c - 1] = if r > 0 { ms[r - 1] + 1 } else { lo };
        }
        span_start[c] = if a > 0 { ms[ms.len() - a] } else { hi };
        middle_start[c] = if c == 0 { 0 } else { span_end[c - 1] };
    }
    {
        let lo = spans[k - 1].1 + 1;
        let ms = motion_lines(lo, lines.len());
        let r = dialect.retract_moves.min(ms.len());
        span_end[k - 1] = if r > 0 { ms[r - 1] + 1 } else { lo };
    }
    let footer_start = span_end[k - 1];
    // The header runs to the first marker, or without one to the first move.
    let header_end = (0..span_start[0])
        .find(|&j| facts[j].marker.is_some())
        .or_else(|| (0..span_start[0]).find(|&j| facts[j].motion))
        .unwrap_or(span_start[0]);
    middle_start[0] = header_end;

    // Plies and course numbers, in line order.
    let mut plies: Vec<Ply> = Vec::new();
    let mut course_ply = vec![0usize; k];
    let mut course_number = vec![None; k];
    {
        let mut c = 0;
        let mut pending_number: Option<i64> = None;
        for (j, f) in facts.iter().enumerate() {
            if c < k && j == spans[c].0 {
                if plies.is_empty() {
                    plies.push(Ply { label: "(no ply marker)".into(), number: None, line: None, courses: Vec::new() });
                }
                course_ply[c] = plies.len() - 1;
                course_number[c] = pending_number.take();
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
    }

    // Middle regions: which lines go where.
    let mut pre_before: Vec<Vec<Item>> = vec![Vec::new(); k];
    let mut pre_after: Vec<Vec<Item>> = vec![Vec::new(); k];
    let mut post: Vec<Vec<Item>> = vec![Vec::new(); k];
    let mut insert_at = vec![0usize; k];
    for c in 0..k {
        let (lo, hi) = (middle_start[c], span_start[c]);
        let first_marker = (lo..hi).find(|&j| facts[j].marker.is_some());
        let first_motion = (lo..hi).find(|&j| facts[j].motion);
        let last_motion = (lo..hi).rev().find(|&j| facts[j].motion);
        insert_at[c] = last_motion.map_or(hi, |l| l + 1);
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
                post[c - 1].push(item);
            } else if last_motion.is_some_and(|l| j > l) {
                pre_after[c].push(item);
            } else {
                pre_before[c].push(item);
            }
        }
    }

    // Pass 2: machine states at the boundaries.
    let mut wanted: Vec<usize> = Vec::with_capacity(3 * k + 2);
    wanted.push(header_end);
    for c in 0..k {
        wanted.extend([insert_at[c], span_start[c], span_end[c]]);
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
    let snap = |i: usize| -> Modal {
        let p = snaps.partition_point(|(j, _)| *j < i);
        snaps[p].1.clone()
    };

    // The dialect's switches on where each span starts.
    let mut switches_on: Vec<Vec<crate::program::SwitchKey>> = vec![Vec::new(); k];
    if !codes.switches.is_empty() {
        let mut on: Vec<crate::program::SwitchKey> = Vec::new();
        let mut c = 0;
        for (j, line) in lines.iter().enumerate() {
            while c < k && span_start[c] == j {
                switches_on[c] = on.clone();
                c += 1;
            }
            if let Some((key, is_on)) = crate::reverse::switch_of(line, dialect, &codes) {
                on.retain(|x| *x != key);
                if is_on {
                    on.push(key);
                    on.sort();
                }
            }
        }
    }
    let seg_index = |line: usize| segments.partition_point(|s| (s.line as usize) < line);
    let mut courses = Vec::with_capacity(k);
    for c in 0..k {
        courses.push(Course {
            ply: course_ply[c],
            number: course_number[c],
            middle: middle_start[c]..span_start[c],
            pre_before: std::mem::take(&mut pre_before[c]),
            pre_after: std::mem::take(&mut pre_after[c]),
            post: std::mem::take(&mut post[c]),
            span: span_start[c]..span_end[c],
            on_part: spans[c].0..spans[c].1 + 1,
            segments: seg_index(span_start[c])..seg_index(span_end[c]),
            insert: snap(insert_at[c]),
            span_start: snap(span_start[c]),
            exit: snap(span_end[c]),
            switches_on: std::mem::take(&mut switches_on[c]),
        });
    }
    Ok(Program {
        start: snap(header_end),
        end: snap(lines.len()),
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
