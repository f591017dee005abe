//! STL: ascii and binary (a fixed 50-byte record layout) read directly, so a binary file whose
//! header happens to begin with `solid` is not mistaken for ascii, an ascii file whose solid has
//! a name in another encoding than UTF-8 is still read as ascii, and every ascii error names its
//! line. Written through the `stl_io` crate.

use std::io::Write;

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
    read_ascii(bytes)
}

/// The words of an ascii STL with their 1-based lines. Lines are decoded one by one, invalid
/// UTF-8 replaced: only the solid's name may hold any (a byte outside ASCII in a keyword or a
/// number makes that word wrong, and it is refused as such).
fn words(bytes: &[u8]) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let text = String::from_utf8_lossy(line);
        // A solid's name runs to the end of its line, whatever it holds.
        for w in text.split_whitespace() {
            out.push((i + 1, w.to_string()));
            if w.eq_ignore_ascii_case("solid") || w.eq_ignore_ascii_case("endsolid") {
                break;
            }
        }
    }
    out
}

/// Reads an ascii STL: `solid [name]`, then facets `facet normal nx ny nz / outer loop /
/// vertex x y z (three times) / endloop / endfacet`, then `endsolid [name]`; several solids may
/// follow one another. Coordinates are read as `f32`, as the binary format holds them. The
/// facet normals are not used (orientation comes from the vertex order).
fn read_ascii(bytes: &[u8]) -> Result<Soup, MeshError> {
    let words = words(bytes);
    let last_line = words.last().map_or(1, |w| w.0);
    let mut it = words.iter().peekable();
    let mut soup = Soup::default();
    let at = |line: usize, what: String| err(format!("line {line}: {what}"));
    let expect = |it: &mut std::iter::Peekable<std::slice::Iter<'_, (usize, String)>>, word: &str| match it.next() {
        Some((_, w)) if w.eq_ignore_ascii_case(word) => Ok(()),
        Some((line, w)) => Err(at(*line, format!("expected `{word}`, found `{}`", short(w)))),
        None => Err(at(last_line, format!("the file ends where `{word}` was expected"))),
    };
    let mut solids = 0;
    while it.peek().is_some() {
        expect(&mut it, "solid")?;
        solids += 1;
        loop {
            match it.next() {
                Some((_, w)) if w.eq_ignore_ascii_case("endsolid") => break,
                Some((line, w)) if w.eq_ignore_ascii_case("facet") => {
                    // `normal nx ny nz`: not used, so only its words are skipped.
                    if it.peek().is_some_and(|(_, w)| w.eq_ignore_ascii_case("normal")) {
                        for _ in 0..4 {
                            it.next();
                        }
                    }
                    expect(&mut it, "outer")?;
                    expect(&mut it, "loop")?;
                    let base = soup.positions.len();
                    if base + 3 >= (1 << 31) {
                        return Err(MeshError::TooLarge(base));
                    }
                    for _ in 0..3 {
                        expect(&mut it, "vertex")?;
                        let mut p = [0.0f64; 3];
                        for c in &mut p {
                            match it.next() {
                                Some((l, w)) => {
                                    *c = w.parse::<f32>().map_err(|_| {
                                        at(*l, format!("`{}` is not a coordinate (after `vertex`)", short(w)))
                                    })? as f64
                                }
                                None => return Err(at(last_line, "the file ends inside a vertex".into())),
                            }
                        }
                        soup.positions.push(DVec3::new(p[0], p[1], p[2]));
                    }
                    let b = base as u32;
                    soup.triangles.push([b, b + 1, b + 2]);
                    match it.next() {
                        Some((_, w)) if w.eq_ignore_ascii_case("endloop") => {}
                        Some((l, w)) if w.eq_ignore_ascii_case("vertex") => {
                            return Err(at(
                                *l,
                                format!(
                                    "the facet of line {line} has more than three vertices (STL facets are triangles)"
                                ),
                            ))
                        }
                        Some((l, w)) => return Err(at(*l, format!("expected `endloop`, found `{}`", short(w)))),
                        None => return Err(at(last_line, "the file ends where `endloop` was expected".into())),
                    }
                    expect(&mut it, "endfacet")?;
                }
                Some((line, w)) => {
                    return Err(at(*line, format!("expected `facet` or `endsolid`, found `{}`", short(w))))
                }
                None => {
                    return Err(at(last_line, "the file ends without `endsolid`".into()));
                }
            }
        }
    }
    if solids == 0 {
        return Err(err("an empty file".into()));
    }
    Ok(soup)
}

/// A word shortened for a message.
fn short(w: &str) -> String {
    let mut s: String = w.chars().take(24).collect();
    if w.chars().nth(24).is_some() {
        s.push('…');
    }
    s
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

    const ONE: &str =
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n";

    #[test]
    fn ascii_names_need_not_be_utf8_and_errors_name_the_line() {
        // A solid named in Latin-1, with no name, in capitals, two solids in one file.
        let mut latin1 = b"solid Bauteil \xe4\xf6\xfc\n".to_vec();
        latin1.extend_from_slice(ONE.as_bytes());
        latin1.extend_from_slice(b"endsolid Bauteil \xe4\xf6\xfc\n");
        let a = read_stl(&latin1).unwrap();
        assert_eq!(a.triangles.len(), 1);
        assert_eq!(a.positions[2], DVec3::new(0.0, 1.0, 0.0));
        for text in [format!("solid\n{ONE}endsolid\n"), format!("SOLID A\n{ONE}ENDSOLID\nsolid b\n{ONE}endsolid b\n")] {
            let s = read_stl(text.as_bytes()).unwrap();
            assert_eq!(s.positions[..3], a.positions[..], "{text}");
        }
        let e = read_stl(b"solid x\nfacet normal 0 0 1\n outer loop\n vertex 0 0\n endloop\n").unwrap_err().to_string();
        assert_eq!(e, "STL: line 5: `endloop` is not a coordinate (after `vertex`)");
        let e = read_stl(format!("solid x\n{ONE}").as_bytes()).unwrap_err().to_string();
        assert!(e.contains("line 8") && e.contains("without `endsolid`"), "{e}");
        let quad = ONE.replace(" endloop", "  vertex 1 1 0\n endloop");
        let e = read_stl(format!("solid x\n{quad}endsolid\n").as_bytes()).unwrap_err().to_string();
        assert!(e.contains("line 7") && e.contains("facet of line 2 has more than three vertices"), "{e}");
        let e = read_stl(format!("solid x\n{}endsolid\n", ONE.replace("outer", "inner")).as_bytes()).unwrap_err();
        assert!(e.to_string().contains("expected `outer`"), "{e}");
    }

    proptest::proptest! {
        /// On well-formed ascii files the reader agrees with `stl_io`'s (an independent
        /// implementation), whatever the number formatting.
        #[test]
        fn agrees_with_stl_io(coords in proptest::collection::vec(-1e6f32..1e6, 9..90), style in 0usize..3) {
            let mut text = String::from("solid p\n");
            for t in coords.chunks_exact(9) {
                text.push_str("  facet normal 0 0 0\n    outer loop\n");
                for v in t.chunks_exact(3) {
                    let f = |x: f32| match style {
                        0 => format!("{x}"),
                        1 => format!("{x:e}"),
                        _ => format!("{x:.3}"),
                    };
                    text.push_str(&format!("      vertex {} {} {}\n", f(v[0]), f(v[1]), f(v[2])));
                }
                text.push_str("    endloop\n  endfacet\n");
            }
            text.push_str("endsolid p\n");
            let ours = read_stl(text.as_bytes()).unwrap();
            let mut cursor = std::io::Cursor::new(text.as_bytes());
            let theirs: Vec<stl_io::Triangle> =
                stl_io::create_stl_reader(&mut cursor).unwrap().map(|t| t.unwrap()).collect();
            proptest::prop_assert_eq!(ours.triangles.len(), theirs.len());
            for (k, t) in theirs.iter().enumerate() {
                for (j, v) in t.vertices.iter().enumerate() {
                    let p = ours.positions[3 * k + j];
                    proptest::prop_assert_eq!(p, DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
                }
            }
        }
    }

    #[test]
    fn a_file_error_is_said_once() {
        let dir = std::env::temp_dir().join(format!("towpath-stl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.stl");
        std::fs::write(&path, "solid x\nfacet normal 0 0 1\n outer loop\n vertex 0 0\n").unwrap();
        let e = crate::io::read_path(&path).unwrap_err();
        // The whole chain, as the command line prints it, says the problem once.
        let chain = anyhow_like(&e);
        assert_eq!(chain.matches("ends inside a vertex").count(), 1, "{chain}");
        let e = crate::io::read_path(&dir.join("missing.stl")).unwrap_err();
        let chain = anyhow_like(&e);
        assert_eq!(chain.matches("No such file").count(), 1, "{chain}");
    }

    /// An error and its sources joined by ": ", as `anyhow`'s `{:#}` prints them.
    fn anyhow_like(e: &(dyn std::error::Error + 'static)) -> String {
        let mut s = e.to_string();
        let mut src = e.source();
        while let Some(x) = src {
            s.push_str(": ");
            s.push_str(&x.to_string());
            src = x.source();
        }
        s
    }
}
