//! The program model: a program's lines, its motion, and its plies of courses.
//!
//! Every line of the source belongs to exactly one region: the header, a course's *span*
//! (approach block, on-part block, retract block: kept together), the *middle* region between
//! two spans (transit motion, which towpath regenerates, and the lines around it, which travel
//! with a course), or the footer.

use std::ops::Range;

use crate::interp::Modal;

/// One move of the machine (one motion line).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Line index (0-based).
    pub line: u32,
    /// Index of the start point in [`Program::points`].
    pub from: u32,
    /// Index of the end point.
    pub to: u32,
    /// Rapid (true) or feed move.
    pub rapid: bool,
    /// Feed rate in effect (NaN if none).
    pub feed: f64,
    /// Tows on during the move.
    pub mask: u64,
    /// The move lays material (roller in contact, or tows on when the dialect has no contact
    /// codes).
    pub on_part: bool,
}

/// A switch of the dialect (its index among the dialect's switches) and the words written
/// with its code (`M64 P3` and `M65 P3` are one switch, `M64 P4` another).
pub type SwitchKey = (usize, Vec<(char, String)>);

/// A line kept with a course outside its span: an original line, or text towpath kept from a
/// transit line whose motion it regenerates (comments and words it does not understand).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Item {
    /// An original line, by index.
    Line(usize),
    /// Text kept from a regenerated transit line (and the line it came from).
    Kept(usize, String),
}

/// A ply: consecutive courses after a ply marker.
#[derive(Clone, Debug, PartialEq)]
pub struct Ply {
    /// The marker comment's text (or a description if the program has no markers).
    pub label: String,
    /// The number in the marker, if any.
    pub number: Option<i64>,
    /// The marker's line, if any.
    pub line: Option<usize>,
    /// The courses of the ply (indices into [`Program::courses`]), in program order.
    pub courses: Vec<usize>,
}

/// A course: its span of lines and the states around it.
#[derive(Clone, Debug, PartialEq)]
pub struct Course {
    /// Index of the ply.
    pub ply: usize,
    /// Number from the course marker, if any.
    pub number: Option<i64>,
    /// The original off-part region before the span (lines).
    pub middle: Range<usize>,
    /// Lines of the middle region that go before the regenerated transit.
    pub pre_before: Vec<Item>,
    /// Lines of the middle region that go after the regenerated transit.
    pub pre_after: Vec<Item>,
    /// Lines after this course's span that stay with it (before the next course's marker).
    pub post: Vec<Item>,
    /// Approach block, on-part block and retract block: lines `span.start..span.end`.
    pub span: Range<usize>,
    /// The on-part block: from roller contact to lift.
    pub on_part: Range<usize>,
    /// Segments of the span.
    pub segments: Range<usize>,
    /// The machine state where the transit into this course ends (before `pre_after`).
    pub insert: Modal,
    /// The machine state at the start of the span.
    pub span_start: Modal,
    /// The machine state after the span.
    pub exit: Modal,
    /// The dialect's switches on where the span starts, reading the program in its order
    /// (sorted; empty without switches in the dialect).
    pub switches_on: Vec<SwitchKey>,
}

impl Course {
    /// The approach block's lines.
    pub fn approach(&self) -> Range<usize> {
        self.span.start..self.on_part.start
    }

    /// The retract block's lines.
    pub fn retract(&self) -> Range<usize> {
        self.on_part.end..self.span.end
    }
}

/// Which region a line belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Before the first course.
    Header,
    /// The middle region before course `c` (transit and the lines around it).
    Middle(usize),
    /// Course `c`'s approach block.
    Approach(usize),
    /// Course `c`'s on-part block.
    OnPart(usize),
    /// Course `c`'s retract block.
    Retract(usize),
    /// After the last course.
    Footer,
}

/// What separates the lines of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineBreak {
    /// LF (a CRLF program keeps the CR at the end of each line).
    Lf,
    /// CR alone (a program with no LF at all).
    Cr,
}

impl LineBreak {
    /// The separator character.
    pub fn separator(self) -> char {
        match self {
            LineBreak::Lf => '\n',
            LineBreak::Cr => '\r',
        }
    }
}

/// A parsed program.
#[derive(Clone, Debug)]
pub struct Program {
    /// The source lines, without line terminators (a `\r` of CRLF stays on its line).
    pub lines: Vec<String>,
    /// The source ended with a line terminator.
    pub final_newline: bool,
    /// What separates the lines.
    pub breaks: LineBreak,
    /// Number of machine axes.
    pub dim: usize,
    /// Physical axis values of every point the program reaches, `dim` values each.
    pub points: Vec<f64>,
    /// Every move.
    pub segments: Vec<Segment>,
    /// Index of the first segment of each line's move, if it moves (an arc has one segment per
    /// chord, all on its line).
    pub line_segment: Vec<Option<u32>>,
    /// Lines `0..header_end` are the header.
    pub header_end: usize,
    /// The machine state at the end of the header.
    pub start: Modal,
    /// The courses, in program order.
    pub courses: Vec<Course>,
    /// The plies, in program order.
    pub plies: Vec<Ply>,
    /// Lines `footer_start..` are the footer.
    pub footer_start: usize,
    /// The machine state at the end of the program.
    pub end: Modal,
}

impl Program {
    /// The values of point `i`.
    #[inline]
    pub fn point(&self, i: u32) -> &[f64] {
        let a = i as usize * self.dim;
        &self.points[a..a + self.dim]
    }

    /// Every point in R³ (the tool point in the part frame), if the machine has kinematics;
    /// indexed like [`Program::points`].
    pub fn part_points(&self, machine: &towpath_machine::Machine) -> Option<Vec<[f64; 3]>> {
        let kin = machine.kinematics()?;
        let n = self.points.len() / self.dim.max(1);
        Some((0..n as u32).map(|i| kin.part_point(self.point(i))).collect())
    }

    /// Which region each line belongs to.
    pub fn regions(&self) -> Vec<Region> {
        let mut r = vec![Region::Footer; self.lines.len()];
        for x in r.iter_mut().take(self.header_end) {
            *x = Region::Header;
        }
        for (c, course) in self.courses.iter().enumerate() {
            for x in &mut r[course.middle.clone()] {
                *x = Region::Middle(c);
            }
            for x in &mut r[course.approach()] {
                *x = Region::Approach(c);
            }
            for x in &mut r[course.on_part.clone()] {
                *x = Region::OnPart(c);
            }
            for x in &mut r[course.retract()] {
                *x = Region::Retract(c);
            }
        }
        r
    }

    /// The source text of the whole program.
    pub fn text(&self) -> String {
        join_lines(self.lines.iter().map(String::as_str), self.final_newline, self.breaks)
    }

    /// Lines of a course's span that are laid (on-part segments), as segment indices.
    pub fn on_part_segments(&self, c: usize) -> impl Iterator<Item = &Segment> {
        self.segments[self.courses[c].segments.clone()].iter().filter(|s| s.on_part)
    }

    /// A short name of a course for messages: ply label and course number or position.
    pub fn course_name(&self, c: usize) -> String {
        let course = &self.courses[c];
        let ply = &self.plies[course.ply];
        let pos = ply.courses.iter().position(|&x| x == c).map_or(0, |p| p + 1);
        match course.number {
            Some(n) => format!("course {n} of ply {} (line {})", ply_name(ply), course.on_part.start + 1),
            None => format!("course {pos} of ply {} (line {})", ply_name(ply), course.on_part.start + 1),
        }
    }
}

/// A ply's short name: its number, or its label.
pub fn ply_name(p: &Ply) -> String {
    match p.number {
        Some(n) => n.to_string(),
        None => p.label.clone(),
    }
}

/// Joins lines with the separator, with a final one if asked.
pub(crate) fn join_lines<'a>(lines: impl Iterator<Item = &'a str>, final_newline: bool, breaks: LineBreak) -> String {
    let sep = breaks.separator();
    let mut out = String::new();
    let mut first = true;
    for l in lines {
        if !first {
            out.push(sep);
        }
        first = false;
        out.push_str(l);
    }
    if final_newline {
        out.push(sep);
    }
    out
}
