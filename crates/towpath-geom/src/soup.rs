//! [`Soup`]: vertices and triangles as read, before welding and repair.

use glam::DVec3;

use crate::MeshError;

/// Vertices and triangles as read from a file or generated: possibly with duplicate vertices
/// (unwelded STL), degenerate or inconsistently oriented triangles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Soup {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl Soup {
    /// A soup with one vertex per triangle corner (as STL stores it).
    pub fn from_triangles(tris: impl IntoIterator<Item = [DVec3; 3]>) -> Soup {
        let mut s = Soup::default();
        for t in tris {
            let i = s.positions.len() as u32;
            s.positions.extend_from_slice(&t);
            s.triangles.push([i, i + 1, i + 2]);
        }
        s
    }

    /// Checks indices and coordinates: every index in range, every coordinate finite, sizes within
    /// 32-bit indices.
    pub fn validate(&self) -> Result<(), MeshError> {
        let n = self.positions.len();
        if n >= (1 << 31) || self.triangles.len() >= (1 << 31) {
            return Err(MeshError::TooLarge(n.max(self.triangles.len())));
        }
        if let Some(index) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { index });
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                if v as usize >= n {
                    return Err(MeshError::BadIndex { triangle: t, vertex: v as usize, count: n });
                }
            }
        }
        Ok(())
    }

    /// Total area of the triangles.
    pub fn area(&self) -> f64 {
        self.triangles.iter().map(|t| tri_area(self.corner(t))).sum()
    }

    fn corner(&self, t: &[u32; 3]) -> [DVec3; 3] {
        [self.positions[t[0] as usize], self.positions[t[1] as usize], self.positions[t[2] as usize]]
    }

    /// Axis-aligned bounding box (min, max); zeros for an empty soup.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds(&self.positions)
    }
}

pub(crate) fn tri_area(c: [DVec3; 3]) -> f64 {
    0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length()
}

pub(crate) fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    let mut it = points.iter();
    let Some(&first) = it.next() else { return (DVec3::ZERO, DVec3::ZERO) };
    it.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}
