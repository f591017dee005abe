//! Mesh files: STL (ascii and binary), OBJ and PLY, read into a [`Soup`] and written back.
//!
//! Readers never panic on bad input: every failure is a [`MeshError`] that names the format and,
//! where the underlying reader tells, the line or element.

mod obj;
mod ply;
mod stl;

use std::path::Path;

pub use obj::{read_obj, write_obj};
pub use ply::{read_ply, write_ply};
pub use stl::{read_stl, write_stl};

use crate::{MeshError, Soup};

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// STL, ascii or binary (detected from the content).
    Stl,
    /// Wavefront OBJ (polygons are fanned into triangles).
    Obj,
    /// PLY, ascii or binary (faces are fanned into triangles).
    Ply,
}

impl Format {
    /// The format named by a file's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Format::Stl),
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            _ => None,
        }
    }
}

/// Reads mesh bytes of a given format.
pub fn read_bytes(bytes: &[u8], format: Format) -> Result<Soup, MeshError> {
    match format {
        Format::Stl => read_stl(bytes),
        Format::Obj => read_obj(bytes),
        Format::Ply => read_ply(bytes),
    }
}

/// Reads a mesh file, the format chosen by extension. Errors name the file.
pub fn read_path(path: &Path) -> Result<Soup, MeshError> {
    let format = Format::from_path(path).ok_or_else(|| MeshError::UnknownFormat { path: path.to_path_buf() })?;
    let bytes = std::fs::read(path).map_err(|error| MeshError::Io { path: path.to_path_buf(), error })?;
    read_bytes(&bytes, format).map_err(|e| e.in_file(path))
}

/// A mesh in a given format, as bytes (STL binary, PLY ascii).
pub fn write_bytes(soup: &Soup, format: Format) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    match format {
        Format::Stl => write_stl(&mut out, soup),
        Format::Obj => write_obj(&mut out, soup),
        Format::Ply => write_ply(&mut out, soup),
    }?;
    Ok(out)
}

/// Writes a mesh file, the format chosen by extension (STL is written binary, PLY ascii).
pub fn write_path(path: &Path, soup: &Soup) -> Result<(), MeshError> {
    let format = Format::from_path(path).ok_or_else(|| MeshError::UnknownFormat { path: path.to_path_buf() })?;
    let out = write_bytes(soup, format).map_err(|error| MeshError::Io { path: path.to_path_buf(), error })?;
    std::fs::write(path, out).map_err(|error| MeshError::Io { path: path.to_path_buf(), error })
}

/// Fans a polygon (vertex indices) into triangles.
pub(crate) fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}
