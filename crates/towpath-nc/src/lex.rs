//! Splits one program line into words (a letter and a number), comments and nothing else.
//!
//! A line the lexer cannot read (macro expressions, `%`, stray characters) is not an error here:
//! the parser keeps such lines as they are, unless they would move an axis.

use std::ops::Range;

/// A number's text as written, stored inline (no allocation). Numbers longer than
/// [`NumText::MAX`] characters are refused by the lexer.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct NumText {
    len: u8,
    bytes: [u8; NumText::MAX],
}

impl NumText {
    /// The longest number text kept.
    pub const MAX: usize = 31;

    /// Stores `s` if it is at most [`NumText::MAX`] bytes long.
    pub fn new(s: &str) -> Option<Self> {
        let b = s.as_bytes();
        if b.len() > Self::MAX {
            return None;
        }
        let mut bytes = [0u8; Self::MAX];
        bytes[..b.len()].copy_from_slice(b);
        Some(NumText { len: b.len() as u8, bytes })
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        // Built from a &str, so always valid UTF-8.
        std::str::from_utf8(&self.bytes[..self.len as usize]).unwrap_or("")
    }
}

impl std::fmt::Display for NumText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Debug for NumText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

/// A word: a letter and a number, with the number's text as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    /// The letter, upper case.
    pub letter: char,
    /// The number as written (`"010.50"`).
    pub text: NumText,
    /// The number's value.
    pub value: f64,
    /// Byte range of the whole word (letter and number) in the line.
    pub span: Range<usize>,
}

/// A lexed line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lexed {
    /// The words, in order.
    pub words: Vec<Word>,
    /// Comment texts (without delimiters), in order.
    pub comments: Vec<String>,
}

/// Why a line could not be lexed.
#[derive(Clone, Debug, PartialEq)]
pub struct LexIssue {
    /// What is wrong.
    pub message: String,
    /// The letter of the word that could not be read, if the problem is a word's value.
    pub letter: Option<char>,
}

/// Largest magnitude accepted for a number.
pub const MAX_ABS_VALUE: f64 = 1e15;

/// Lexes one line.
pub fn lex(line: &str, parens: bool, semicolon: bool) -> Result<Lexed, LexIssue> {
    let bytes = line.as_bytes();
    let mut out = Lexed::default();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if parens && c == b'(' {
            let Some(end) = line[i + 1..].find(')') else {
                return Err(LexIssue { message: "a comment opened with ( is not closed".into(), letter: None });
            };
            out.comments.push(line[i + 1..i + 1 + end].to_string());
            i += end + 2;
            continue;
        }
        if semicolon && c == b';' {
            out.comments.push(line[i + 1..].to_string());
            break;
        }
        if c.is_ascii_alphabetic() {
            let letter = (c as char).to_ascii_uppercase();
            let start = i;
            i += 1;
            while i < bytes.len() && (bytes[i] == b' ' || bytes[i] == b'\t') {
                i += 1;
            }
            let num_start = i;
            if i < bytes.len() && (bytes[i] == b'+' || bytes[i] == b'-') {
                i += 1;
            }
            let mut digits = 0;
            let mut dot = false;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || (bytes[i] == b'.' && !dot)) {
                if bytes[i] == b'.' {
                    dot = true;
                } else {
                    digits += 1;
                }
                i += 1;
            }
            if digits == 0 {
                return Err(LexIssue { message: format!("word {letter} has no number"), letter: Some(letter) });
            }
            let text = &line[num_start..i];
            let Some(num) = NumText::new(text) else {
                return Err(LexIssue { message: format!("{letter}{text} is too long a number"), letter: Some(letter) });
            };
            let value: f64 = text
                .parse()
                .map_err(|_| LexIssue { message: format!("{letter}{text} is not a number"), letter: Some(letter) })?;
            if !(value.is_finite() && value.abs() <= MAX_ABS_VALUE) {
                return Err(LexIssue {
                    message: format!("{letter}{text} is out of range (|value| ≤ 1e15)"),
                    letter: Some(letter),
                });
            }
            // A letter glued to another letter ("GOTO") is not a word.
            out.words.push(Word { letter, text: num, value, span: start..i });
            continue;
        }
        return Err(LexIssue { message: format!("unexpected character {:?}", c as char), letter: None });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_comments() {
        let l = lex("N10 G1 X-10.5 Y.25 z 3 F1000 (go) ; rest (x)", true, true).unwrap();
        let w: Vec<(char, f64)> = l.words.iter().map(|w| (w.letter, w.value)).collect();
        assert_eq!(w, vec![('N', 10.0), ('G', 1.0), ('X', -10.5), ('Y', 0.25), ('Z', 3.0), ('F', 1000.0)]);
        assert_eq!(l.words[2].text.as_str(), "-10.5");
        assert_eq!(&"N10 G1 X-10.5"[l.words[2].span.clone()], "X-10.5");
        assert_eq!(l.comments, vec!["go".to_string(), " rest (x)".to_string()]);
    }

    #[test]
    fn issues_name_the_word() {
        assert_eq!(lex("X#1", true, true).unwrap_err().letter, Some('X'));
        assert_eq!(lex("%", true, true).unwrap_err().letter, None);
        assert!(lex("(open", true, true).is_err());
        let huge = format!("X{}", "9".repeat(400));
        assert!(lex(&huge, true, true).unwrap_err().message.contains("too long"));
        assert!(lex("X9999999999999999", true, true).unwrap_err().message.contains("out of range"));
        // "1e5" is not scientific notation here: it is X1 followed by E5.
        assert_eq!(lex("X1e5", true, true).unwrap().words.len(), 2);
        // Without parenthesis comments a parenthesis is not allowed.
        assert!(lex("G1 (c)", false, true).is_err());
    }
}
