//! PLY through the `ply-rs-bw` crate (ascii and binary; `vertex` x/y/z and `face`
//! `vertex_indices`/`vertex_index` lists).

use std::io::Write;

use glam::DVec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use crate::{MeshError, Soup};

fn err(message: String) -> MeshError {
    MeshError::Format { format: "PLY", message }
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

/// Upper bound on announced element counts, checked against the file size before parsing so a
/// hostile header cannot make the reader allocate without bound.
fn check_header_counts(bytes: &[u8]) -> Result<(), MeshError> {
    let head_end = bytes.windows(10).position(|w| w == b"end_header").unwrap_or(bytes.len().min(65536));
    let head = String::from_utf8_lossy(&bytes[..head_end]);
    for (i, line) in head.lines().enumerate() {
        // The header grammar of ply-rs-bw unwraps integer parses: refuse numbers too long for u64.
        let longest_digits = line.split(|c: char| !c.is_ascii_digit()).map(str::len).max().unwrap_or(0);
        if longest_digits > 18 {
            return Err(err(format!("header line {}: number too large", i + 1)));
        }
        let mut it = line.split_whitespace();
        if it.next() == Some("element") {
            let _name = it.next();
            if let Some(count) = it.next().and_then(|c| c.parse::<u64>().ok()) {
                if count > bytes.len() as u64 {
                    return Err(err(format!(
                        "header line {}: element count {count} exceeds the file size ({} bytes)",
                        i + 1,
                        bytes.len()
                    )));
                }
            }
        }
    }
    Ok(())
}

/// Reads PLY bytes: vertices from `vertex` (x, y, z), faces from `face` (fanned into triangles).
pub fn read_ply(bytes: &[u8]) -> Result<Soup, MeshError> {
    check_header_counts(bytes)?;
    let parser = Parser::<DefaultElement>::new();
    let mut r = std::io::BufReader::new(bytes);
    let ply = parser.read_ply(&mut r).map_err(|e| err(e.to_string()))?;
    let mut soup = Soup::default();
    let verts = ply.payload.get("vertex").ok_or_else(|| err("no 'vertex' element".into()))?;
    for (i, v) in verts.iter().enumerate() {
        let c = |k: &str| v.get(k).and_then(scalar).ok_or_else(|| err(format!("vertex {i}: no numeric '{k}'")));
        soup.positions.push(DVec3::new(c("x")?, c("y")?, c("z")?));
    }
    let n = soup.positions.len();
    if let Some(faces) = ply.payload.get("face") {
        for (i, f) in faces.iter().enumerate() {
            let idx = f
                .get("vertex_indices")
                .or_else(|| f.get("vertex_index"))
                .and_then(list)
                .ok_or_else(|| err(format!("face {i}: no 'vertex_indices' list")))?;
            let mut poly = Vec::with_capacity(idx.len());
            for &x in &idx {
                if x < 0 || x as usize >= n {
                    return Err(err(format!("face {i}: vertex index {x} out of range (0..{n})")));
                }
                poly.push(x as u32);
            }
            super::fan(&poly, &mut soup.triangles);
        }
    }
    Ok(soup)
}

/// Writes ascii PLY with double-precision vertices.
pub fn write_ply(out: &mut impl Write, soup: &Soup) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "ply\nformat ascii 1.0\ncomment written by towpath")?;
    writeln!(w, "element vertex {}\nproperty double x\nproperty double y\nproperty double z", soup.positions.len())?;
    writeln!(w, "element face {}\nproperty list uchar int vertex_indices\nend_header", soup.triangles.len())?;
    for p in &soup.positions {
        writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
    }
    for t in &soup.triangles {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    w.flush()
}
