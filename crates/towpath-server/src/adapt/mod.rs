//! The only modules that call the library crates. Library APIs are still moving (request types,
//! typed errors, cycle-time costs), so every call from the server into `towpath-nc`,
//! `towpath-layup`, `towpath-geom` and `towpath-machine` goes through here, and the rest of the
//! server sees only the plain types these modules define.

pub mod layup;
pub mod machine;
pub mod nc;

/// Splits a library message that starts with `line N: ` into the line and the rest.
pub fn split_line(message: &str) -> (Option<usize>, String) {
    if let Some(rest) = message.strip_prefix("line ") {
        if let Some((n, tail)) = rest.split_once(": ") {
            if let Ok(n) = n.parse::<usize>() {
                return ((n > 0).then_some(n), tail.to_string());
            }
        }
    }
    (None, message.to_string())
}
