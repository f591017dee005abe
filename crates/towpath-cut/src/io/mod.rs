//! Readers and writers: each turns a file into a [`crate::Drawing`] and writes an ordering back
//! in the same format, keeping every piece's geometry.
//!
//! - [`json`]: towpath's own cut format (`towpath-cut/1`, documented in `docs/cut.md`).
//! - [`svg`]: SVG through `usvg` (transforms, groups, shapes, curves); top-level groups are
//!   operations (layers).
//! - [`dxf`](mod@dxf): DXF through the `dxf` crate: LINE, LWPOLYLINE, POLYLINE, ARC, CIRCLE,
//!   SPLINE; layers are operations.
//! - [`gcode`]: G-code pieces separated by rapids; rapids regenerated on writing.

pub mod dxf;
pub mod gcode;
pub mod json;
pub mod svg;

use crate::error::CutError;
use crate::model::{Drawing, Placement};

/// A file format for drawings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// towpath-cut/1 JSON.
    Json,
    /// SVG.
    Svg,
    /// DXF (ASCII).
    Dxf,
    /// G-code.
    Gcode,
}

impl Format {
    /// The format of a file name by its extension (`.json`, `.svg`, `.dxf`, `.nc`/`.gcode`/`.ngc`/`.tap`/`.g`).
    pub fn from_extension(name: &str) -> Option<Format> {
        let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase())?;
        match ext.as_str() {
            "json" => Some(Format::Json),
            "svg" => Some(Format::Svg),
            "dxf" => Some(Format::Dxf),
            "nc" | "gcode" | "ngc" | "tap" | "g" | "cnc" => Some(Format::Gcode),
            _ => None,
        }
    }
}

/// A drawing read from a file, with what its writer needs to write it back.
#[derive(Clone, Debug)]
pub enum Source {
    /// JSON: nothing more.
    Json(json::JsonSource),
    /// SVG: the document text and each piece's element.
    Svg(Box<svg::SvgSource>),
    /// DXF: the header and each piece's layer and entity.
    Dxf(Box<dxf::DxfSource>),
    /// G-code: the program's lines and each piece's block.
    Gcode(gcode::GcodeSource),
}

/// Reads a drawing in `format` from `text`; `name` is used in messages.
pub fn read(format: Format, text: &str, name: &str, tol: f64) -> Result<(Drawing, Source), CutError> {
    match format {
        Format::Json => json::read(text, name).map(|(d, s)| (d, Source::Json(s))),
        Format::Svg => svg::read(text, name, tol).map(|(d, s)| (d, Source::Svg(Box::new(s)))),
        Format::Dxf => dxf::read(text, name, tol).map(|(d, s)| (d, Source::Dxf(Box::new(s)))),
        Format::Gcode => gcode::read(text, name).map(|(d, s)| (d, Source::Gcode(s))),
    }
}

/// Writes an ordering of `drawing` in its source's format.
pub fn write(source: &Source, drawing: &Drawing, order: &[Placement]) -> Result<String, CutError> {
    match source {
        Source::Json(s) => Ok(json::write(s, drawing, order)),
        Source::Svg(s) => Ok(svg::write(s, drawing, order)),
        Source::Dxf(s) => dxf::write(s, drawing, order),
        Source::Gcode(s) => Ok(gcode::write(s, drawing, order)),
    }
}
