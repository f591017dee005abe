//! G-code in and out (RS274 as laser, plasma, router and plotter post-processors write it).
//!
//! **Reading.** Lines are read with their modal state (motion mode G0–G3, feed, position; G17
//! plane, absolute coordinates G90, incremental arc centres I/J, or R). A **piece** is a run of
//! feed moves in X/Y (G1, G2, G3); it ends at any rapid (G0), at torch/spindle/pen off or on
//! (M3, M4, M5), or at the end of the program. The lines between two pieces are split at the
//! rapid that moves in X/Y: the lines before it go with the piece before (its retract, torch
//! off), the lines after it with the piece after (its plunge, torch on); the lines before the
//! first such rapid form the header, and from the rapid after the last piece on, the footer.
//! A piece is closed when it ends where it starts. A piece whose moves carry other axes
//! (Z ramps, rotary axes) is kept exactly as written (no reversal, no restart).
//!
//! Refused, naming the line: incremental coordinates (G91), absolute arc centres (G90.1),
//! arcs outside the XY plane (G18, G19), coordinate offsets (G92), words without a number,
//! arcs whose centre is not equidistant from their ends.
//!
//! **Writing.** Header; for each piece in the new order one rapid `G0 X.. Y..` to its entry
//! (none when the piece starts exactly where the one before ended and a torch/pen line between
//! them keeps them apart),
//! its plunge lines, its lead-in (feed moves), its moves (the original lines if it is done as
//! written, else regenerated as G1/G2/G3 with the feed that was in effect), its retract lines;
//! then the footer. Every other line is kept as written.

use crate::error::CutError;
use crate::geom::{arc_geometry, dist, Path, Seg, P2};
use crate::model::{Drawing, Piece, Placement};

/// A piece's lines.
#[derive(Clone, Debug)]
struct Block {
    prefix: Vec<String>,
    motion: Vec<String>,
    suffix: Vec<String>,
    /// The motion word in effect at the first move, if that line has none.
    motion_word: Option<String>,
    /// The feed in effect at the first move, if that line has no F.
    feed: Option<String>,
    /// Motion mode in effect where the prefix starts, if not G0.
    prefix_mode: Option<String>,
    original: Path,
    /// The prefix holds a line that ends a piece (torch/pen on or off, a rapid without X/Y).
    prefix_breaks: bool,
    /// The suffix holds such a line.
    suffix_breaks: bool,
}

/// What the G-code writer keeps of the input.
#[derive(Clone, Debug)]
pub struct GcodeSource {
    header: Vec<String>,
    footer: Vec<String>,
    blocks: Vec<Block>,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Motion {
    Rapid,
    Line,
    Cw,
    Ccw,
}

impl Motion {
    fn word(self) -> &'static str {
        match self {
            Motion::Rapid => "G0",
            Motion::Line => "G1",
            Motion::Cw => "G2",
            Motion::Ccw => "G3",
        }
    }
}

/// The words of a line (comments removed): letter and value, and the raw text of F.
fn words(line: &str, no: usize, name: &str) -> Result<Vec<(char, f64, String)>, CutError> {
    let mut out = Vec::new();
    let mut chars = line.chars().peekable();
    let mut depth = 0;
    while let Some(c) = chars.next() {
        if depth > 0 {
            if c == ')' {
                depth -= 1;
            }
            continue;
        }
        match c {
            '(' => depth += 1,
            ';' => break,
            '%' if out.is_empty() => break,
            c if c.is_whitespace() => {}
            c if c.is_ascii_alphabetic() => {
                while chars.peek().is_some_and(|c| *c == ' ' || *c == '\t') {
                    chars.next();
                }
                let mut num = String::new();
                while let Some(&d) = chars.peek() {
                    if d.is_ascii_digit() || d == '.' || d == '-' || d == '+' {
                        num.push(d);
                        chars.next();
                    } else {
                        break;
                    }
                }
                let v: f64 = num.parse().map_err(|_| {
                    CutError::Input(format!(
                        "{name}:{no}: word '{c}' has no number{}",
                        if num.is_empty() { String::new() } else { format!(" ({num:?})") }
                    ))
                })?;
                if !v.is_finite() {
                    return Err(CutError::Input(format!("{name}:{no}: word '{c}{num}' is not a finite number")));
                }
                out.push((c.to_ascii_uppercase(), v, num));
            }
            _ => {
                return Err(CutError::Input(format!("{name}:{no}: unexpected character {c:?}")));
            }
        }
    }
    Ok(out)
}

enum Kind {
    /// A feed move in X/Y: the segment, and whether the line names other axes.
    Feed(Seg, bool),
    /// A rapid in X/Y.
    RapidXy,
    /// A rapid without X/Y, or torch/pen on/off: ends a piece.
    Break,
    /// Anything else.
    Other,
}

/// Reads a G-code program.
pub fn read(text: &str, name: &str) -> Result<(Drawing, GcodeSource), CutError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut motion = Motion::Rapid;
    let mut pos: P2 = [0.0, 0.0];
    let mut feed: Option<String> = None;
    // Classified lines with the state at each.
    let mut kinds = Vec::with_capacity(lines.len());
    let mut at_line: Vec<(P2, Motion, Option<String>, bool, bool)> = Vec::with_capacity(lines.len());
    for (i, line) in lines.iter().enumerate() {
        let no = i + 1;
        let ws = words(line, no, name)?;
        let before = (pos, motion, feed.clone());
        let mut had_motion_word = false;
        let mut x = None;
        let mut y = None;
        let (mut ci, mut cj, mut r) = (None, None, None);
        let mut other_axes = false;
        let mut brk = false;
        for (c, v, raw) in &ws {
            match c {
                'G' => {
                    let g = (*v * 10.0).round() as i64;
                    match g {
                        0 => motion = Motion::Rapid,
                        10 => motion = Motion::Line,
                        20 => motion = Motion::Cw,
                        30 => motion = Motion::Ccw,
                        910 => {
                            return Err(CutError::Input(format!(
                            "{name}:{no}: incremental coordinates (G91) are not supported; post the program with G90"
                        )))
                        }
                        901 => {
                            return Err(CutError::Input(format!(
                            "{name}:{no}: absolute arc centres (G90.1) are not supported; use incremental I/J (G91.1)"
                        )))
                        }
                        180 | 190 => {
                            return Err(CutError::Input(format!(
                                "{name}:{no}: arcs outside the XY plane (G18/G19) are not supported"
                            )))
                        }
                        920 => {
                            return Err(CutError::Input(format!(
                                "{name}:{no}: coordinate offsets (G92) are not supported"
                            )))
                        }
                        _ => {}
                    }
                    if matches!(g, 0 | 10 | 20 | 30) {
                        had_motion_word = true;
                    }
                }
                'X' => x = Some(*v),
                'Y' => y = Some(*v),
                'I' => ci = Some(*v),
                'J' => cj = Some(*v),
                'R' => r = Some(*v),
                'F' => feed = Some(raw.clone()),
                'Z' | 'A' | 'B' | 'C' | 'U' | 'V' | 'W' => other_axes = true,
                'M' => {
                    let m = v.round() as i64;
                    if (3..=5).contains(&m) {
                        brk = true;
                    }
                }
                _ => {}
            }
        }
        let has_xy = x.is_some() || y.is_some();
        let to = [x.unwrap_or(pos[0]), y.unwrap_or(pos[1])];
        let kind = if has_xy {
            match motion {
                Motion::Rapid => Kind::RapidXy,
                Motion::Line => Kind::Feed(Seg::Line(to), other_axes),
                Motion::Cw | Motion::Ccw => {
                    let ccw = motion == Motion::Ccw;
                    let seg =
                        arc_seg(pos, to, ci, cj, r, ccw).map_err(|e| CutError::Input(format!("{name}:{no}: {e}")))?;
                    Kind::Feed(seg, other_axes)
                }
            }
        } else if brk || (motion == Motion::Rapid && other_axes) {
            Kind::Break
        } else {
            Kind::Other
        };
        if has_xy {
            pos = to;
        }
        let line_has_f = ws.iter().any(|w| w.0 == 'F');
        at_line.push((before.0, before.1, before.2, had_motion_word, line_has_f));
        kinds.push(kind);
    }
    // Pieces: maximal runs of feed moves, broken by rapids and breaks.
    let mut runs: Vec<(usize, usize)> = Vec::new(); // [first, last] motion line indices
    let mut cur: Option<(usize, usize)> = None;
    for (i, k) in kinds.iter().enumerate() {
        match k {
            Kind::Feed(..) => {
                cur = Some(match cur {
                    Some((a, _)) => (a, i),
                    None => (i, i),
                })
            }
            Kind::RapidXy | Kind::Break => {
                if let Some(r) = cur.take() {
                    runs.push(r);
                }
            }
            Kind::Other => {}
        }
    }
    if let Some(r) = cur.take() {
        runs.push(r);
    }
    let owned = |a: usize, b: usize| -> Vec<String> { lines[a..b].iter().map(|s| s.to_string()).collect() };
    let mut drawing = Drawing { operations: vec!["cut".into()], ..Drawing::default() };
    let mut blocks = Vec::new();
    // Split points between consecutive runs: the first X/Y rapid in the gap (excluded), else
    // just after the last break in the gap.
    let split = |from: usize, to: usize| -> (usize, usize, Vec<usize>) {
        let first = (from..to).find(|&k| matches!(kinds[k], Kind::RapidXy));
        let last = (from..to).rev().find(|&k| matches!(kinds[k], Kind::RapidXy));
        if let (Some(f), Some(l)) = (first, last) {
            // Lines between the rapids other than rapids travel with the piece before.
            let middle = (f + 1..l).filter(|&k| !matches!(kinds[k], Kind::RapidXy)).collect();
            return (f, l + 1, middle);
        }
        match (from..to).rev().find(|&k| matches!(kinds[k], Kind::Break)) {
            Some(k) => (k + 1, k + 1, Vec::new()),
            None => (from, from, Vec::new()),
        }
    };
    let header_end = match runs.first() {
        Some(&(a, _)) => {
            // The last X/Y rapid before the first piece; the header is everything before it.
            match (0..a).rev().find(|&k| matches!(kinds[k], Kind::RapidXy)) {
                Some(k) => (k, k + 1),
                None => (0, 0),
            }
        }
        None => (lines.len(), lines.len()),
    };
    let header = owned(0, header_end.0);
    let mut prefix_start = header_end.1;
    let mut footer = Vec::new();
    for (n, &(a, b)) in runs.iter().enumerate() {
        let (suffix_end, next_prefix, middle) = match runs.get(n + 1) {
            Some(&(na, _)) => split(b + 1, na),
            None => match (b + 1..lines.len()).find(|&k| matches!(kinds[k], Kind::RapidXy)) {
                Some(k) => (k, k, Vec::new()),
                None => (lines.len(), lines.len(), Vec::new()),
            },
        };
        if n + 1 == runs.len() {
            footer = owned(suffix_end, lines.len());
        }
        let start = at_line[a].0;
        let mut segs = Vec::new();
        let mut extra = false;
        for k in a..=b {
            if let Kind::Feed(s, o) = &kinds[k] {
                segs.push(*s);
                extra |= *o;
            }
        }
        let mut path = Path { start, segs, closed: false };
        let scale = 1.0 + path.length();
        if path.segs.len() >= 2 && dist(path.end(), path.start) <= 1e-9 * scale {
            path.closed = true;
        }
        if path.closed && path.segs.len() == 1 {
            path.closed = false;
        }
        let (_, mode_before, feed_before, has_word, has_f) = &at_line[a];
        let prefix_mode =
            at_line.get(prefix_start).map(|s| s.1).filter(|m| *m != Motion::Rapid).map(|m| m.word().to_string());
        let first_mode = match &kinds[a] {
            Kind::Feed(Seg::Arc { bulge, .. }, _) if *bulge < 0.0 => Motion::Cw,
            Kind::Feed(Seg::Arc { .. }, _) => Motion::Ccw,
            _ => Motion::Line,
        };
        let _ = mode_before;
        let breaks = |k: &usize| matches!(kinds[*k], Kind::Break);
        blocks.push(Block {
            prefix_breaks: (prefix_start.min(a)..a).any(|k| breaks(&k)),
            suffix_breaks: (b + 1..suffix_end.max(b + 1)).any(|k| breaks(&k)) || middle.iter().any(breaks),
            prefix: owned(prefix_start.min(a), a),
            motion: owned(a, b + 1),
            suffix: {
                let mut v = owned(b + 1, suffix_end.max(b + 1));
                v.extend(middle.iter().map(|&k| lines[k].to_string()));
                v
            },
            motion_word: (!has_word).then(|| first_mode.word().to_string()),
            feed: if *has_f { None } else { feed_before.clone() },
            prefix_mode,
            original: path.clone(),
        });
        drawing.pieces.push(Piece {
            id: format!("line {}", a + 1),
            operation: 0,
            path,
            reversible: true,
            fixed: extra,
        });
        prefix_start = next_prefix;
    }
    if runs.is_empty() {
        footer = Vec::new();
    }
    Ok((drawing, GcodeSource { header, footer, blocks }))
}

/// The segment of an arc move from `from` to `to` (I/J incremental centre, or R).
fn arc_seg(from: P2, to: P2, i: Option<f64>, j: Option<f64>, r: Option<f64>, ccw: bool) -> Result<Seg, String> {
    let sign = if ccw { 1.0 } else { -1.0 };
    if let Some(r) = r {
        let c = dist(from, to);
        if c == 0.0 {
            return Err("an R arc needs different start and end points".into());
        }
        if c > 2.0 * r.abs() * (1.0 + 1e-9) {
            return Err(format!("arc radius {} is smaller than half the chord {}", r.abs(), c / 2.0));
        }
        let half = (c / (2.0 * r.abs())).min(1.0).asin();
        let sweep = if r >= 0.0 { 2.0 * half } else { std::f64::consts::TAU - 2.0 * half };
        return Ok(Seg::Arc { to, bulge: sign * (sweep / 4.0).tan() });
    }
    let c = [from[0] + i.unwrap_or(0.0), from[1] + j.unwrap_or(0.0)];
    let (r0, r1) = (dist(c, from), dist(c, to));
    if r0 == 0.0 {
        return Err("arc centre (I, J) is at its start point".into());
    }
    if (r0 - r1).abs() > 1e-3 * r0.max(1e-3) + 1e-6 {
        return Err(format!("arc end is {r1} from the centre but its start {r0}"));
    }
    if dist(from, to) <= 1e-12 * (1.0 + r0) {
        return Err("full-circle arcs are not supported; split the circle in two moves".into());
    }
    let a0 = (from[1] - c[1]).atan2(from[0] - c[0]);
    let a1 = (to[1] - c[1]).atan2(to[0] - c[0]);
    let mut sweep = (a1 - a0).rem_euclid(std::f64::consts::TAU);
    if !ccw {
        sweep = std::f64::consts::TAU - sweep;
    }
    Ok(Seg::Arc { to, bulge: sign * (sweep / 4.0).tan() })
}

fn fmt(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// Regenerated feed moves of a path (the first line carries the feed).
fn moves(path: &Path, feed: Option<&str>, out: &mut Vec<String>) {
    let mut prev = path.start;
    for (k, s) in path.segs.iter().enumerate() {
        let f = if k == 0 { feed.map(|f| format!(" F{f}")).unwrap_or_default() } else { String::new() };
        match *s {
            Seg::Line(p) => out.push(format!("G1 X{} Y{}{f}", fmt(p[0]), fmt(p[1]))),
            Seg::Arc { to, bulge } => match arc_geometry(prev, to, bulge) {
                Some((c, ..)) => {
                    let g = if bulge > 0.0 { "G3" } else { "G2" };
                    out.push(format!(
                        "{g} X{} Y{} I{} J{}{f}",
                        fmt(to[0]),
                        fmt(to[1]),
                        fmt(c[0] - prev[0]),
                        fmt(c[1] - prev[1])
                    ));
                }
                None => out.push(format!("G1 X{} Y{}{f}", fmt(to[0]), fmt(to[1]))),
            },
            Seg::Cubic { .. } => {
                let mut pts = Vec::new();
                crate::geom::seg_flatten(prev, s, 1e-3, &mut pts);
                for (n, p) in pts.iter().enumerate() {
                    let f = if n == 0 { f.clone() } else { String::new() };
                    out.push(format!("G1 X{} Y{}{f}", fmt(p[0]), fmt(p[1])));
                }
            }
        }
        prev = s.end();
    }
}

/// Writes an ordering as G-code.
pub fn write(source: &GcodeSource, _drawing: &Drawing, order: &[Placement]) -> String {
    let mut out: Vec<String> = source.header.clone();
    // Where the previous piece ended, and whether its last lines end a piece: a piece that
    // starts exactly there needs no rapid (a move to where the tool already is) when a line
    // between them (torch off, pen up, ...) keeps the two pieces apart; without one the rapid
    // is what separates them, so it is written even though it does not move.
    let mut at: Option<([f64; 2], bool)> = None;
    for pl in order {
        let Some(b) = source.blocks.get(pl.piece) else { continue };
        let e = pl.entry();
        let joined = at.is_some_and(|(p, broken)| p == e && (broken || b.prefix_breaks));
        if pl.lead_in.is_some() || !joined {
            out.push(format!("G0 X{} Y{}", fmt(e[0]), fmt(e[1])));
        }
        at = Some((pl.path.end(), b.suffix_breaks));
        if let Some(m) = &b.prefix_mode {
            out.push(m.clone());
        }
        out.extend(b.prefix.iter().cloned());
        if let Some(l) = &pl.lead_in {
            moves(l, b.feed.as_deref(), &mut out);
        }
        if pl.path == b.original {
            for (k, line) in b.motion.iter().enumerate() {
                if k == 0 && (b.motion_word.is_some() || b.feed.is_some()) {
                    let w = b.motion_word.clone().unwrap_or_default();
                    let f = b.feed.as_ref().map(|f| format!("F{f} ")).unwrap_or_default();
                    out.push(format!("{w}{}{f}{line}", if w.is_empty() { "" } else { " " }));
                } else {
                    out.push(line.clone());
                }
            }
        } else {
            moves(&pl.path, b.feed.as_deref(), &mut out);
        }
        out.extend(b.suffix.iter().cloned());
    }
    out.extend(source.footer.iter().cloned());
    let mut s = out.join("\n");
    s.push('\n');
    s
}
