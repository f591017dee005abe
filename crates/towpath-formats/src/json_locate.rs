//! Finds the line and column of a value in JSON text by its path (`precedence[3][1]`), so that
//! errors found after deserialization can point into the file like syntax errors do. The one
//! locator of the workspace: the JSON problem reader here and the travel-graph reader of
//! `towpath-coverage` both use it.
//!
//! The text has usually been parsed successfully by serde_json already; this scanner only walks
//! it (without recursion, so any nesting depth is fine) and gives up (returns `None`) on anything
//! unexpected, never panics.

/// One step of a JSON path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seg<'a> {
    /// An object member (its name as written, escapes and all).
    Key(&'a str),
    /// An array element.
    Index(usize),
}

/// Renders a path as `tasks[2].modes[0].entry`.
pub fn path_text(path: &[Seg<'_>]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The 1-based line and column where the value at `path` begins.
pub fn locate(text: &str, path: &[Seg<'_>]) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let mut i = skip_ws(b, 0);
    for seg in path {
        i = match seg {
            Seg::Key(k) => member(b, i, k)?,
            Seg::Index(n) => element(b, i, *n)?,
        };
    }
    let before = text.get(..i)?;
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    Some((line, col))
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while b.get(i).is_some_and(|c| c.is_ascii_whitespace()) {
        i += 1;
    }
    i
}

/// `i` at an opening quote; returns the index after the closing quote.
fn skip_string(b: &[u8], mut i: usize) -> Option<usize> {
    if b.get(i) != Some(&b'"') {
        return None;
    }
    i += 1;
    loop {
        match b.get(i)? {
            b'\\' => i += 2,
            b'"' => return Some(i + 1),
            _ => i += 1,
        }
    }
}

/// `i` at the start of a value; returns the index after it.
fn skip_value(b: &[u8], mut i: usize) -> Option<usize> {
    match b.get(i)? {
        b'"' => skip_string(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            loop {
                match b.get(i)? {
                    b'"' => {
                        i = skip_string(b, i)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth = depth.checked_sub(1)?;
                        if depth == 0 {
                            return Some(i + 1);
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
        }
        _ => {
            while b.get(i).is_some_and(|c| !matches!(c, b',' | b'}' | b']') && !c.is_ascii_whitespace()) {
                i += 1;
            }
            Some(i)
        }
    }
}

/// `i` at an object; returns the start of the value of member `key`.
fn member(b: &[u8], i: usize, key: &str) -> Option<usize> {
    if b.get(i) != Some(&b'{') {
        return None;
    }
    let mut i = i + 1;
    loop {
        i = skip_ws(b, i);
        if b.get(i)? == &b'}' {
            return None;
        }
        let end = skip_string(b, i)?;
        let name = b.get(i + 1..end - 1)?;
        i = skip_ws(b, end);
        if b.get(i)? != &b':' {
            return None;
        }
        i = skip_ws(b, i + 1);
        if name == key.as_bytes() {
            return Some(i);
        }
        i = skip_ws(b, skip_value(b, i)?);
        match b.get(i)? {
            b',' => i += 1,
            _ => return None,
        }
    }
}

/// `i` at an array; returns the start of element `n`.
fn element(b: &[u8], i: usize, n: usize) -> Option<usize> {
    if b.get(i) != Some(&b'[') {
        return None;
    }
    let mut i = i + 1;
    for k in 0.. {
        i = skip_ws(b, i);
        if b.get(i)? == &b']' {
            return None;
        }
        if k == n {
            return Some(i);
        }
        i = skip_ws(b, skip_value(b, i)?);
        match b.get(i)? {
            b',' => i += 1,
            _ => return None,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_values() {
        let t = "{\n  \"a\": {\"x\": \"}\"},\n  \"precedence\": [\n    [\"p\", \"q\"],\n    [\"r\",  \"s\"]\n  ]\n}";
        let p = [Seg::Key("precedence"), Seg::Index(1), Seg::Index(1)];
        assert_eq!(locate(t, &p), Some((5, 12)));
        assert_eq!(path_text(&p), "precedence[1][1]");
        assert_eq!(locate(t, &[Seg::Key("missing")]), None);
        assert_eq!(locate("{\"a\": [1", &[Seg::Key("a"), Seg::Index(3)]), None);
    }

    #[test]
    fn finds_members_of_objects_in_arrays_and_gives_up_on_broken_text() {
        let text =
            "{\n  \"a\": [1, {\"x\": \"]\"}],\n  \"edges\": [\n    {\"a\": 0},\n    {\"a\": 7}\n  ],\n  \"s\": 3\n}";
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(1)]), Some((5, 5)));
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(1), Seg::Key("a")]), Some((5, 11)));
        assert_eq!(locate(text, &[Seg::Key("s")]), Some((7, 8)));
        assert_eq!(locate(text, &[Seg::Key("edges"), Seg::Index(2)]), None);
        assert_eq!(locate(text, &[Seg::Key("nope")]), None);
        assert_eq!(locate("[", &[Seg::Index(3)]), None);
        assert_eq!(locate("\"abc", &[Seg::Key("x")]), None);
        // Deeper than any recursion would go.
        let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
        assert_eq!(locate(&deep, &[Seg::Index(0), Seg::Index(0)]), Some((1, 3)));
        assert_eq!(locate(&deep, &[Seg::Index(1)]), None);
    }
}
