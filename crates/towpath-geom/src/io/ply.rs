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
    let ply = parser.read_ply(&mut r).map_err(|e| err(reword(&e.to_string())))?;
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

/// `ply-rs`'s messages (`Line 12: Couln't read element line.` followed by the line and a debug
/// dump of the inner error) as one line: `line 12: bad element data `0 1`: expected a float,
/// found nothing`.
fn reword(msg: &str) -> String {
    let mut parts = msg.split("\n\t");
    let head = parts.next().unwrap_or("").trim();
    let mut text = None;
    let mut detail = None;
    for p in parts {
        if let Some(t) = p.strip_prefix("String: ") {
            text = Some(t.trim().trim_matches('\'').trim().to_string());
        } else if let Some(d) = p.strip_prefix("Error: ") {
            detail = Some(inner(d));
        }
    }
    let (line, what) = match head.strip_prefix("Line ").and_then(|r| r.split_once(": ")) {
        Some((n, w)) => (Some(n.to_string()), w),
        None => (None, head),
    };
    let what = match what.trim_end_matches('.') {
        "Couln't read element line" | "Couldn't read element line" => "bad element data".to_string(),
        "Couldn't parse line" => "bad header line".to_string(),
        w => tidy(w),
    };
    let mut out = match line {
        Some(n) => format!("line {n}: {what}"),
        None => what,
    };
    if let Some(t) = text.filter(|t| !t.is_empty()) {
        let t: String = t.chars().take(60).collect();
        out.push_str(&format!(" `{t}`"));
    }
    if let Some(d) = detail.filter(|d| !d.is_empty()) {
        out.push_str(": ");
        out.push_str(&d);
    }
    out
}

/// The message inside a debug dump such as `Custom { kind: InvalidInput, error: "…" }`, reworded.
fn inner(dump: &str) -> String {
    let text = match dump.split_once("error: \"") {
        Some((_, rest)) => rest.rsplit_once('"').map_or(rest, |r| r.0),
        None => dump,
    };
    let text = text.replace("\\n", "\n").replace("\\t", "\t").replace("\\'", "'");
    if let Some(rest) = text.strip_prefix("Expected element of type '") {
        let ty = rest.split('\'').next().unwrap_or("");
        return format!("expected {}, found nothing", type_name(ty));
    }
    if let Some((_, value)) = text.split_once("Value: '") {
        let value = value.split('\'').next().unwrap_or("");
        return format!("`{value}` is not a number of the declared type");
    }
    // A nested message: its own innermost error, e.g. the line grammar's `error at 1:3: …`.
    if let Some((_, last)) = text.rsplit_once("Error: ") {
        if let Some(rest) = last.strip_prefix("error at ") {
            let column = rest.split(':').nth(1).unwrap_or("?");
            return format!("not a number at column {column}");
        }
        return inner(last);
    }
    tidy(&text)
}

/// `Scalar(Float)` → `a float`, `List(UChar, Int)` → `a list`.
fn type_name(ty: &str) -> String {
    match ty.strip_prefix("Scalar(").and_then(|t| t.strip_suffix(')')) {
        Some(t) => format!("a {}", t.to_ascii_lowercase()),
        None if ty.starts_with("List") => "a list".into(),
        None => ty.to_string(),
    }
}

/// A message's first line, without a trailing period and with the crate's typo mended.
fn tidy(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().trim_end_matches('.').replace("Couln't", "couldn't").to_string()
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

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n";

    #[test]
    fn reads_a_triangle() {
        let s = read_ply(format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").as_bytes()).unwrap();
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_are_one_clear_line() {
        let e = read_ply(format!("{HEAD}0 0 0\n1 0 0\n0 1\n3 0 1 2\n").as_bytes()).unwrap_err().to_string();
        assert_eq!(e, "PLY: line 12: bad element data `0 1`: expected a float, found nothing");
        let e = read_ply(format!("{HEAD}0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n").as_bytes()).unwrap_err().to_string();
        assert_eq!(e, "PLY: line 11: bad element data `1 x 0`: not a number at column 3");
        for bad in [&format!("{HEAD}0 0 0\n"), "ply\nformat ascii 1.0\nelement vertex\nend_header\n"] {
            let e = read_ply(bad.as_bytes()).unwrap_err().to_string();
            assert!(!e.contains("Couln't") && !e.contains('\n') && !e.contains("Custom {"), "{e}");
        }
    }
}
