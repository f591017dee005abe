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

/// Reads a mesh file's bytes (STL, OBJ or PLY, by the name's extension); errors name the file.
pub fn read_soup(name: &str, bytes: &[u8]) -> Result<towpath_geom::Soup, crate::error::ApiError> {
    use crate::error::ApiError;
    let format = towpath_geom::io::Format::from_path(std::path::Path::new(name))
        .ok_or_else(|| ApiError::in_file(name, None, "a mesh must be a .stl, .obj or .ply file"))?;
    towpath_geom::io::read_bytes(bytes, format).map_err(|e| ApiError::in_file(name, None, e.to_string()))
}
