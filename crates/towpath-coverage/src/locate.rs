//! Finds where a value sits in a JSON text (line and column), so that errors found after parsing
//! (a vertex index out of range, say) can point at the line of the input that holds the value.
//!
//! A small scanner that walks the text along a path of object keys and array indices. It
//! never panics: on anything unexpected it gives up and returns `None`.

/// One step of a path into a JSON document.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Seg<'a> {
    /// A member of an object.
    Key(&'a str),
    /// An element of an array.
    Index(usize),
}

/// The 1-based line and column where the value at `path` begins.
pub(crate) fn locate(text: &str, path: &[Seg<'_>]) -> Option<(usize, usize)> {
    let mut s = Scanner { b: text.as_bytes(), i: 0 };
    s.ws();
    let pos = s.find(path)?;
    Some(line_col(text, pos))
}

/// The 1-based line and column of byte offset `pos` (columns count characters).
fn line_col(text: &str, pos: usize) -> (usize, usize) {
    let pos = pos.min(text.len());
    let before = text.get(..pos).unwrap_or(text);
    let line = before.bytes().filter(|&c| c == b'\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |k| k + 1);
    let col = before.get(line_start..).map_or(1, |l| l.chars().count() + 1);
    (line, col)
}

struct Scanner<'t> {
    b: &'t [u8],
    i: usize,
}

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> Option<()> {
        self.ws();
        if self.peek() == Some(c) {
            self.i += 1;
            Some(())
        } else {
            None
        }
    }

    /// At the start of a value: walk `path` from here and return the byte offset of its end.
    fn find(&mut self, path: &[Seg<'_>]) -> Option<usize> {
        self.ws();
        let Some((first, rest)) = path.split_first() else {
            return Some(self.i);
        };
        match *first {
            Seg::Key(k) => {
                self.eat(b'{')?;
                if self.eat(b'}').is_some() {
                    return None;
                }
                loop {
                    self.ws();
                    let matches = self.string()? == k.as_bytes();
                    self.eat(b':')?;
                    if matches {
                        return self.find(rest);
                    }
                    self.skip_value()?;
                    self.ws();
                    match self.peek()? {
                        b',' => self.i += 1,
                        _ => return None,
                    }
                }
            }
            Seg::Index(n) => {
                self.eat(b'[')?;
                let mut k = 0;
                loop {
                    self.ws();
                    if self.peek()? == b']' {
                        return None;
                    }
                    if k == n {
                        return self.find(rest);
                    }
                    self.skip_value()?;
                    self.ws();
                    match self.peek()? {
                        b',' => self.i += 1,
                        _ => return None,
                    }
                    k += 1;
                }
            }
        }
    }

    /// Reads a string's raw bytes (escapes left as they are).
    fn string(&mut self) -> Option<&[u8]> {
        if self.peek()? != b'"' {
            return None;
        }
        self.i += 1;
        let start = self.i;
        loop {
            match self.peek()? {
                b'\\' => self.i += 2,
                b'"' => {
                    let s = self.b.get(start..self.i)?;
                    self.i += 1;
                    return Some(s);
                }
                _ => self.i += 1,
            }
        }
    }

    fn skip_value(&mut self) -> Option<()> {
        self.ws();
        match self.peek()? {
            b'"' => self.string().map(|_| ()),
            open @ (b'[' | b'{') => {
                let close = if open == b'[' { b']' } else { b'}' };
                self.i += 1;
                self.ws();
                if self.peek()? == close {
                    self.i += 1;
                    return Some(());
                }
                loop {
                    if open == b'{' {
                        self.ws();
                        self.string()?;
                        self.eat(b':')?;
                    }
                    self.skip_value()?;
                    self.ws();
                    match self.peek()? {
                        b',' => self.i += 1,
                        c if c == close => {
                            self.i += 1;
                            return Some(());
                        }
                        _ => return None,
                    }
                }
            }
            _ => {
                // number or literal
                let start = self.i;
                while matches!(self.peek(), Some(c) if c.is_ascii_alphanumeric() || matches!(c, b'-' | b'+' | b'.')) {
                    self.i += 1;
                }
                (self.i > start).then_some(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_values() {
        let text =
            "{\n  \"a\": [1, {\"x\": \"]\"}],\n  \"edges\": [\n    {\"a\": 0},\n    {\"a\": 7}\n  ],\n  \"s\": 3\n}";
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(1)]), Some((5, 5)));
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(1), Seg::Key("a")]), Some((5, 11)));
        assert_eq!(locate(text, &[Seg::Key("s")]), Some((7, 8)));
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(2)]), None);
        assert_eq!(locate(text, &[Seg::Key("nope")]), None);
        assert_eq!(locate("[", &[Seg::Index(3)]), None);
        assert_eq!(locate("\"abc", &[Seg::Key("x")]), None);
    }
}
