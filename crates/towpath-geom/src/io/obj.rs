//! Wavefront OBJ through the `tobj` crate (geometry only; materials are ignored).

use std::io::Write;

use glam::DVec3;

use crate::{MeshError, Soup};

/// Reads OBJ bytes: all objects and groups into one soup; polygons fanned into triangles.
pub fn read_obj(bytes: &[u8]) -> Result<Soup, MeshError> {
    let opts = tobj::LoadOptions { triangulate: false, single_index: false, ..Default::default() };
    let mut reader = std::io::BufReader::new(bytes);
    let (models, _) = tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::GenericFailure))
        .map_err(|e| MeshError::Format { format: "OBJ", message: e.to_string() })?;
    let mut soup = Soup::default();
    for m in models {
        let mesh = m.mesh;
        let base = soup.positions.len();
        let nv = mesh.positions.len() / 3;
        for k in 0..nv {
            let p = &mesh.positions[3 * k..3 * k + 3];
            soup.positions.push(DVec3::new(p[0], p[1], p[2]));
        }
        let check = |i: u32| -> Result<u32, MeshError> {
            if (i as usize) < nv {
                Ok((base + i as usize) as u32)
            } else {
                Err(MeshError::Format {
                    format: "OBJ",
                    message: format!("object '{}': face refers to vertex {} of {nv}", m.name, i as u64 + 1),
                })
            }
        };
        if mesh.face_arities.is_empty() {
            for t in mesh.indices.chunks(3) {
                if t.len() == 3 {
                    soup.triangles.push([check(t[0])?, check(t[1])?, check(t[2])?]);
                }
            }
        } else {
            let mut at = 0usize;
            for &n in &mesh.face_arities {
                let n = n as usize;
                let Some(poly) = mesh.indices.get(at..at + n) else {
                    return Err(MeshError::Format {
                        format: "OBJ",
                        message: "face list shorter than announced".into(),
                    });
                };
                let poly: Vec<u32> = poly.iter().map(|&i| check(i)).collect::<Result<_, _>>()?;
                super::fan(&poly, &mut soup.triangles);
                at += n;
            }
        }
    }
    Ok(soup)
}

/// Writes OBJ (`v` and `f` lines, full f64 precision).
pub fn write_obj(out: &mut impl Write, soup: &Soup) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "# written by towpath")?;
    for p in &soup.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for t in &soup.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}
