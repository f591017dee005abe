//! Names of things kept in the workspace: the only way a request names a file, so nothing can
//! reach outside the workspace folder.

use crate::error::ApiError;

/// Longest name accepted.
pub const MAX_NAME: usize = 100;

/// Checks a name given by a request: 1–100 characters of letters, digits, `.`, `_` and `-`,
/// not starting with `.` (so no `..`, no hidden files, no separators, no drive letters).
pub fn check(what: &str, name: &str) -> Result<(), ApiError> {
    let ok_chars = name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'));
    if name.is_empty() || name.len() > MAX_NAME || !ok_chars || name.starts_with('.') {
        return Err(ApiError::bad(format!(
            "{what} name {name:?} is not allowed: use 1 to {MAX_NAME} letters, digits, '.', '_' or '-', not starting with '.'"
        )));
    }
    Ok(())
}

/// A name made from an uploaded file's name: the characters a name may not hold become `_`.
pub fn sanitize(raw: &str) -> String {
    let base = raw.rsplit(['/', '\\']).next().unwrap_or(raw);
    let mut s: String =
        base.chars().map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') { c } else { '_' }).collect();
    while s.starts_with('.') {
        s.remove(0);
    }
    s.truncate(MAX_NAME);
    if s.is_empty() {
        "upload".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traversal_and_separators_are_refused() {
        for bad in ["..", "../x", "a/b", "a\\b", ".hidden", "", "c:x", "a b", "x\0y"] {
            assert!(check("program", bad).is_err(), "{bad:?}");
        }
        for good in ["part.nc", "planar-0", "A_1.toml"] {
            assert!(check("program", good).is_ok(), "{good:?}");
        }
    }

    #[test]
    fn sanitized_names_pass_the_check() {
        for raw in ["../../etc/passwd", "C:\\parts\\wing skin.nc", "...", "", "ü.nc"] {
            let s = sanitize(raw);
            assert!(check("x", &s).is_ok(), "{raw:?} -> {s:?}");
        }
        assert_eq!(sanitize("../../etc/passwd"), "passwd");
    }
}
