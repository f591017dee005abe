//! STL: ascii through the `stl_io` crate; binary (a fixed 50-byte record layout) read directly so a
//! binary file whose header happens to begin with `solid` is not mistaken for ascii.

use std::io::{Cursor, Write};

use glam::DVec3;

use crate::{MeshError, Soup};

fn err(message: String) -> MeshError {
    MeshError::Format { format: "STL", message }
}

/// Reads STL bytes (ascii or binary) into a soup with three vertices per triangle (welding is
/// [`crate::Mesh::build`]'s job). The stored facet normals are ignored: orientation comes from the
/// vertex order, as the format specifies.
pub fn read_stl(bytes: &[u8]) -> Result<Soup, MeshError> {
    let looks_ascii = bytes.len() >= 5 && bytes[..5].eq_ignore_ascii_case(b"solid");
    let looks_binary = bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        84 + 50 * n == bytes.len() as u64
    };
    // Binary files may begin with "solid" too: trust the size check first.
    if !looks_binary && !looks_ascii {
        if bytes.len() < 84 {
            return Err(err(format!("{} bytes: too short for a binary STL and no 'solid' header", bytes.len())));
        }
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return Err(err(format!(
            "binary header announces {n} triangles ({} bytes expected) but the file has {} bytes",
            84 + 50 * n,
            bytes.len()
        )));
    }
    if looks_binary {
        // 80-byte header, count, then 50 bytes per facet: normal, three vertices, attribute.
        let mut soup = Soup::default();
        for rec in bytes[84..].chunks_exact(50) {
            let f = |o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64;
            let b = soup.positions.len();
            if b + 3 >= (1 << 31) {
                return Err(MeshError::TooLarge(b));
            }
            for k in 0..3 {
                let o = 12 + 12 * k;
                soup.positions.push(DVec3::new(f(o), f(o + 4), f(o + 8)));
            }
            let b = b as u32;
            soup.triangles.push([b, b + 1, b + 2]);
        }
        return Ok(soup);
    }
    let mut cursor = Cursor::new(bytes);
    let iter = stl_io::create_stl_reader(&mut cursor).map_err(|e| err(format!("ascii STL: {e}")))?;
    let mut soup = Soup::default();
    collect(iter, &mut soup)?;
    Ok(soup)
}

fn collect(
    iter: Box<dyn stl_io::TriangleIterator<Item = std::io::Result<stl_io::Triangle>> + '_>,
    soup: &mut Soup,
) -> Result<(), MeshError> {
    for (i, t) in iter.enumerate() {
        let t = t.map_err(|e| err(format!("facet {}: {e}", i + 1)))?;
        let base = soup.positions.len();
        if base + 3 >= (1 << 31) {
            return Err(MeshError::TooLarge(base));
        }
        for v in t.vertices {
            soup.positions.push(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
        }
        let b = base as u32;
        soup.triangles.push([b, b + 1, b + 2]);
    }
    Ok(())
}

/// Writes binary STL (coordinates rounded to f32 as the format requires).
pub fn write_stl(out: &mut impl Write, soup: &Soup) -> std::io::Result<()> {
    let tris: Vec<stl_io::Triangle> = soup
        .triangles
        .iter()
        .map(|t| {
            let c = [soup.positions[t[0] as usize], soup.positions[t[1] as usize], soup.positions[t[2] as usize]];
            let n = (c[1] - c[0]).cross(c[2] - c[0]).try_normalize().unwrap_or(DVec3::ZERO);
            let v = |p: DVec3| stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32]);
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: [v(c[0]), v(c[1]), v(c[2])],
            }
        })
        .collect();
    stl_io::write_stl(out, tris.iter())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_read_the_same_triangle() {
        let ascii = b"solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n";
        let a = read_stl(ascii).unwrap();
        let mut bin = Vec::new();
        write_stl(&mut bin, &a).unwrap();
        let b = read_stl(&bin).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.triangles.len(), 1);
        assert_eq!(a.positions[1], DVec3::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn refuses_truncated_binary_and_garbage() {
        assert!(read_stl(b"hello").is_err());
        let mut bin = vec![0u8; 84];
        bin[80] = 2; // two triangles announced, none present
        let e = read_stl(&bin).unwrap_err().to_string();
        assert!(e.contains("announces 2 triangles"), "{e}");
        assert!(read_stl(b"solid x\nfacet normal 0 0 1\n outer loop\n vertex 0 0\n").is_err());
    }
}
