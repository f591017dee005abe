//! Finds the line of a machine file that sets a key, so that a value refused after reading
//! (out of range, inconsistent) is named by its line as well as its key.
//!
//! Keys are the paths validation uses: `name`, `tool_offset`, `axis`, `axis[2].weight`,
//! `dh[0].alpha`. The file is scanned line by line for `[[axis]]`/`[[dh]]` headers and
//! `key = value` lines; a key that is not written (a default) is located at its table's header.
//! Inline tables (`axis = [{ ... }]`) are not followed: their keys get line 0 (unknown).

/// The 1-based line of `text` that sets `key`, or 0 if it cannot be found.
pub(crate) fn line_of(text: &str, key: &str) -> usize {
    let (table, field) = split(key);
    // The table header we are under: (name, index among tables of that name).
    let mut current: Option<(String, usize)> = None;
    let mut counts: Vec<(String, usize)> = Vec::new();
    let mut header_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let line = strip_comment(raw).trim();
        if let Some(name) = line.strip_prefix("[[").and_then(|l| l.strip_suffix("]]")) {
            let name = unquote(name.trim()).to_string();
            let n = match counts.iter_mut().find(|(k, _)| *k == name) {
                Some((_, n)) => {
                    *n += 1;
                    *n
                }
                None => {
                    counts.push((name.clone(), 0));
                    0
                }
            };
            current = Some((name, n));
            if let Some((t, k)) = &table {
                if current.as_ref().is_some_and(|(c, ci)| c == t && ci == k) {
                    header_line = i + 1;
                    if field.is_none() {
                        return i + 1;
                    }
                }
            }
            continue;
        }
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            // A plain table (`[head]`): index usize::MAX, as `split` gives for `head.radius`.
            current = Some((unquote(name.trim()).to_string(), usize::MAX));
            if let Some((t, usize::MAX)) = &table {
                if *t == unquote(name.trim()) {
                    header_line = i + 1;
                }
            }
            continue;
        }
        let Some((k, _)) = line.split_once('=') else { continue };
        let k = unquote(k.trim());
        let here = match (&table, &current) {
            (None, None) => true,
            (Some((t, n)), Some((c, cn))) => t == c && n == cn,
            _ => false,
        };
        if here && field.is_some_and(|f| f == k) {
            return i + 1;
        }
        // A whole array of tables written at top level (`axis = []`).
        if current.is_none() && field.is_none() && table.as_ref().is_some_and(|(t, _)| t == k) {
            return i + 1;
        }
    }
    header_line
}

/// `axis[2].weight` → (Some(("axis", 2)), Some("weight")); `tool_offset` → (None,
/// Some("tool_offset")); `axis` → (Some(("axis", 0)), None).
fn split(key: &str) -> (Option<(String, usize)>, Option<&str>) {
    let (head, field) = match key.split_once('.') {
        Some((h, f)) => (h, Some(f)),
        None => (key, None),
    };
    match head.split_once('[') {
        Some((name, rest)) => {
            let index = rest.trim_end_matches(']').parse().unwrap_or(0);
            (Some((name.to_string(), index)), field)
        }
        None if field.is_none() && (head == "axis" || head == "dh") => (Some((head.to_string(), 0)), None),
        None if field.is_none() => (None, Some(head)),
        // A key of a plain table (`head.radius`).
        None => (Some((head.to_string(), usize::MAX)), field),
    }
}

fn unquote(s: &str) -> &str {
    s.trim_matches('"').trim_matches('\'')
}

/// The line without a `#` comment (outside quotes).
fn strip_comment(line: &str) -> &str {
    let mut quote: Option<char> = None;
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '#') => return &line[..i],
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            _ => {}
        }
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_in_their_tables() {
        let text = "name = \"m\" # a machine\ntool_offset = [0, 0, 1]\n\n[[axis]]\nlabel = \"X\"\nkind = \"linear\"\n\
                    [[axis]]\nlabel = \"A\"\n\"weight\" = 1e308\n[[dh]]\na = 1\n[[dh]]\nalpha = 5\n";
        assert_eq!(line_of(text, "tool_offset"), 2);
        assert_eq!(line_of(text, "axis[0].kind"), 6);
        assert_eq!(line_of(text, "axis[1].weight"), 9);
        // A default (not written): the table's header.
        assert_eq!(line_of(text, "axis[1].max_velocity"), 7);
        assert_eq!(line_of(text, "dh[1].alpha"), 13);
        assert_eq!(line_of(text, "dh[1]"), 12);
        assert_eq!(line_of(text, "axis"), 4);
        let with_head = "name = \"m\"\n[head]\nradius = 4\n\nbottom = 1\n[[axis]]\nlabel = \"X\"\n";
        assert_eq!(line_of(with_head, "head.bottom"), 5);
        assert_eq!(line_of(with_head, "head.top"), 2);
        // Not there at all.
        assert_eq!(line_of(text, "axis[5].weight"), 0);
        assert_eq!(line_of("axis = [{ label = \"X\", kind = \"linear\" }]", "axis[0].kind"), 0);
    }
}
