//! Tessellation of parametric surfaces under a chord tolerance D_l2s and a maximum edge length
//! L_seg (seed 001 §2.2): a parameter grid refined until every edge (including cell diagonals)
//! is at most L_seg long and deviates from the surface by at most D_l2s at its parameter midpoint.
//! Whole spheres are tessellated as geodesic icospheres (no pole singularity).

use glam::DVec3;

use super::{Analytic, Surface};
use crate::Soup;

/// How finely to tessellate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tessellation {
    /// Chord tolerance D_l2s and maximum edge length L_seg (seed 001); whichever is tighter wins.
    Chord {
        /// Maximum distance from an edge to the surface.
        d_l2s: f64,
        /// Maximum edge length.
        l_seg: f64,
    },
    /// About this many triangles, as evenly sized as the parameterization allows.
    Triangles(usize),
}

/// A tessellation that cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TessellationError {
    /// Tolerances not positive and finite.
    #[error("tessellation: D_l2s and L_seg must be positive and finite (got {0}, {1})")]
    BadTolerance(f64, f64),
    /// The tolerances would need more triangles than the limit.
    #[error("tessellation: more than {0} triangles would be needed; loosen D_l2s or L_seg")]
    TooFine(usize),
    /// A triangle count asked for is above the limit.
    #[error("tessellation: {0} triangles asked for, more than the limit of {1}")]
    TooMany(usize, usize),
    /// A triangle count asked for is below two (one parameter cell).
    #[error("tessellation: at least 2 triangles are needed, {0} asked for")]
    TooFew(usize),
    /// The deadline passed before the tessellation was finished.
    #[error("tessellation: the time limit was reached before the surface was tessellated")]
    TimeLimit,
}

/// Largest tessellation towpath will make.
pub const MAX_TRIANGLES: usize = 50_000_000;

/// Bounds on the work of a tessellation, checked before anything is allocated and during it.
#[derive(Debug, Clone, Copy)]
pub struct TessellationLimits {
    /// Most triangles to make (at most [`MAX_TRIANGLES`]).
    pub max_triangles: usize,
    /// Give up (with [`TessellationError::TimeLimit`]) after this instant.
    pub deadline: Option<std::time::Instant>,
}

impl Default for TessellationLimits {
    fn default() -> Self {
        TessellationLimits { max_triangles: MAX_TRIANGLES, deadline: None }
    }
}

impl TessellationLimits {
    fn check_time(&self) -> Result<(), TessellationError> {
        match self.deadline {
            Some(d) if std::time::Instant::now() >= d => Err(TessellationError::TimeLimit),
            _ => Ok(()),
        }
    }
}

/// Tessellates an analytic surface (icosphere for a whole sphere, parameter grid otherwise).
pub fn tessellate_analytic(s: &Analytic, t: &Tessellation) -> Result<Soup, TessellationError> {
    tessellate_analytic_within(s, t, &TessellationLimits::default())
}

/// [`tessellate_analytic`] within limits of size and time.
pub fn tessellate_analytic_within(
    s: &Analytic,
    t: &Tessellation,
    limits: &TessellationLimits,
) -> Result<Soup, TessellationError> {
    if let Analytic::Sphere { r, lat0, lat1 } = *s {
        if lat0 <= -std::f64::consts::FRAC_PI_2 + 1e-12 && lat1 >= std::f64::consts::FRAC_PI_2 - 1e-12 {
            return icosphere(r, t, limits);
        }
    }
    tessellate_within(s, t, limits)
}

/// Tessellates a parametric surface on a refined parameter grid.
pub fn tessellate(s: &dyn Surface, t: &Tessellation) -> Result<Soup, TessellationError> {
    tessellate_within(s, t, &TessellationLimits::default())
}

/// [`tessellate`] within limits of size and time: the refinement stops with
/// [`TessellationError::TooFine`] as soon as its next grid would exceed the triangle limit, so
/// nothing larger than the limit is ever allocated.
pub fn tessellate_within(
    s: &dyn Surface,
    t: &Tessellation,
    limits: &TessellationLimits,
) -> Result<Soup, TessellationError> {
    let max_triangles = limits.max_triangles.min(MAX_TRIANGLES);
    let [[u0, u1], [v0, v1]] = s.domain();
    let (mut nu, mut nv);
    match *t {
        Tessellation::Chord { d_l2s, l_seg } => {
            if !(d_l2s > 0.0 && l_seg > 0.0 && d_l2s.is_finite() && l_seg.is_finite()) {
                return Err(TessellationError::BadTolerance(d_l2s, l_seg));
            }
            (nu, nv) = (4usize, 4usize);
            for _ in 0..40 {
                limits.check_time()?;
                let m = measure(s, nu, nv, [u0, u1], [v0, v1]);
                let f = |len: f64, dev: f64| (len / l_seg).max((dev / d_l2s).sqrt());
                let (fu, fv, fd) = (f(m.len[0], m.dev[0]), f(m.len[1], m.dev[1]), f(m.len[2], m.dev[2]));
                if fu <= 1.0 && fv <= 1.0 && fd <= 1.0 {
                    break;
                }
                let grow = |n: usize, f: f64| if f > 1.0 { ((n as f64) * f * 1.01).ceil() as usize } else { n };
                let (mut gu, mut gv) = (grow(nu, fu), grow(nv, fv));
                if fd > 1.0 && gu == nu && gv == nv {
                    // Only the diagonals are too long: refine the coarser direction.
                    if m.len[0] >= m.len[1] {
                        gu = grow(nu, fd);
                    } else {
                        gv = grow(nv, fd);
                    }
                }
                (nu, nv) = (gu.max(nu + 1), gv.max(nv + 1));
                if nu.saturating_mul(nv).saturating_mul(2) > max_triangles {
                    return Err(TessellationError::TooFine(max_triangles));
                }
            }
        }
        Tessellation::Triangles(n) => {
            if n > max_triangles {
                return Err(TessellationError::TooMany(n, max_triangles));
            }
            if n < 2 {
                return Err(TessellationError::TooFew(n));
            }
            // Split n/2 cells in proportion to the mean isoline lengths.
            let m = measure(s, 16, 16, [u0, u1], [v0, v1]);
            let (lu, lv) = (m.mean_len[0].max(1e-300), m.mean_len[1].max(1e-300));
            let cells = (n as f64 / 2.0).max(1.0);
            let ratio = lu / lv; // cell count along u over along v for square cells
            nu = ((cells * ratio).sqrt()).round().max(1.0) as usize;
            if s.closed_u() {
                // A tube needs at least three cells around to close on itself.
                nu = nu.max(3);
            }
            nv = ((cells / nu as f64).round().max(1.0)) as usize;
        }
    }
    limits.check_time()?;
    grid(s, nu, nv, limits)
}

struct Measure {
    /// Max length of u-edges, v-edges, diagonals.
    len: [f64; 3],
    /// Max midpoint deviation of u-edges, v-edges, diagonals.
    dev: [f64; 3],
    /// Mean total isoline length along u and v (at the 16×16 probe).
    mean_len: [f64; 2],
}

fn measure(s: &dyn Surface, nu: usize, nv: usize, ur: [f64; 2], vr: [f64; 2]) -> Measure {
    let uu = |i: f64| ur[0] + (ur[1] - ur[0]) * i / nu as f64;
    let vv = |j: f64| vr[0] + (vr[1] - vr[0]) * j / nv as f64;
    let mut m = Measure { len: [0.0; 3], dev: [0.0; 3], mean_len: [0.0; 2] };
    let mut rows: Vec<Vec<DVec3>> = Vec::with_capacity(nu + 1);
    for i in 0..=nu {
        rows.push((0..=nv).map(|j| s.eval(uu(i as f64), vv(j as f64))).collect());
    }
    let mut check = |k: usize, a: DVec3, b: DVec3, mid: DVec3| {
        m.len[k] = m.len[k].max(a.distance(b));
        m.dev[k] = m.dev[k].max(mid.distance((a + b) * 0.5));
    };
    for i in 0..=nu {
        for j in 0..=nv {
            let (fi, fj) = (i as f64, j as f64);
            if i < nu {
                check(0, rows[i][j], rows[i + 1][j], s.eval(uu(fi + 0.5), vv(fj)));
            }
            if j < nv {
                check(1, rows[i][j], rows[i][j + 1], s.eval(uu(fi), vv(fj + 0.5)));
            }
            if i < nu && j < nv {
                let c = s.eval(uu(fi + 0.5), vv(fj + 0.5));
                let (d1, d2) = (rows[i][j].distance(rows[i + 1][j + 1]), rows[i + 1][j].distance(rows[i][j + 1]));
                if d1 <= d2 {
                    check(2, rows[i][j], rows[i + 1][j + 1], c);
                } else {
                    check(2, rows[i + 1][j], rows[i][j + 1], c);
                }
            }
        }
    }
    let mut su = 0.0;
    for j in 0..=nv {
        su += (0..nu).map(|i| rows[i][j].distance(rows[i + 1][j])).sum::<f64>();
    }
    let mut sv = 0.0;
    for row in &rows {
        sv += (0..nv).map(|j| row[j].distance(row[j + 1])).sum::<f64>();
    }
    m.mean_len = [su / (nv + 1) as f64, sv / (nu + 1) as f64];
    m
}

/// Triangulates an (nu × nv)-cell parameter grid, each cell split along its shorter diagonal.
/// A surface closed along u reuses its first column as its last.
fn grid(s: &dyn Surface, nu: usize, nv: usize, limits: &TessellationLimits) -> Result<Soup, TessellationError> {
    let [[u0, u1], [v0, v1]] = s.domain();
    let closed = s.closed_u();
    let cols = if closed { nu } else { nu + 1 };
    let mut soup = Soup::default();
    soup.positions.reserve(cols * (nv + 1));
    for i in 0..cols {
        if i % 64 == 0 {
            limits.check_time()?;
        }
        let u = u0 + (u1 - u0) * i as f64 / nu as f64;
        for j in 0..=nv {
            soup.positions.push(s.eval(u, v0 + (v1 - v0) * j as f64 / nv as f64));
        }
    }
    let id = |i: usize, j: usize| ((i % cols) * (nv + 1) + j) as u32;
    soup.triangles.reserve(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let p = |k: u32| soup.positions[k as usize];
            // Orientation: u then v gives the normal S_u × S_v.
            if p(a).distance(p(c)) <= p(b).distance(p(d)) {
                soup.triangles.push([a, b, c]);
                soup.triangles.push([a, c, d]);
            } else {
                soup.triangles.push([a, b, d]);
                soup.triangles.push([b, c, d]);
            }
        }
    }
    Ok(soup)
}

/// A geodesic icosphere (class I, frequency n: 20 n² triangles) of radius r.
fn icosphere(r: f64, t: &Tessellation, limits: &TessellationLimits) -> Result<Soup, TessellationError> {
    let max_triangles = limits.max_triangles.min(MAX_TRIANGLES);
    let n = match *t {
        Tessellation::Triangles(count) => {
            if count > max_triangles {
                return Err(TessellationError::TooMany(count, max_triangles));
            }
            ((count as f64 / 20.0).sqrt().round() as usize).max(1)
        }
        Tessellation::Chord { d_l2s, l_seg } => {
            if !(d_l2s > 0.0 && l_seg > 0.0 && d_l2s.is_finite() && l_seg.is_finite()) {
                return Err(TessellationError::BadTolerance(d_l2s, l_seg));
            }
            // Longest edge of a frequency-n icosphere is below 1.2 × (icosahedron edge)/n; chord
            // deviation of an edge of length e is r − sqrt(r² − e²/4).
            let edge0 = r * 1.0515;
            let mut n = 1usize;
            loop {
                let e = 1.2 * edge0 / n as f64;
                let dev = r - (r * r - e * e / 4.0).max(0.0).sqrt();
                if e <= l_seg && dev <= d_l2s {
                    break n;
                }
                n += 1.max(n / 8);
                if 20 * n * n > max_triangles {
                    return Err(TessellationError::TooFine(max_triangles));
                }
            }
        }
    };
    if 20usize.saturating_mul(n).saturating_mul(n) > max_triangles {
        return Err(TessellationError::TooFine(max_triangles));
    }
    limits.check_time()?;
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let v = [
        DVec3::new(-1.0, g, 0.0),
        DVec3::new(1.0, g, 0.0),
        DVec3::new(-1.0, -g, 0.0),
        DVec3::new(1.0, -g, 0.0),
        DVec3::new(0.0, -1.0, g),
        DVec3::new(0.0, 1.0, g),
        DVec3::new(0.0, -1.0, -g),
        DVec3::new(0.0, 1.0, -g),
        DVec3::new(g, 0.0, -1.0),
        DVec3::new(g, 0.0, 1.0),
        DVec3::new(-g, 0.0, -1.0),
        DVec3::new(-g, 0.0, 1.0),
    ];
    let faces: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    // Each face subdivided on its own; shared edges produce identical points (same formula from
    // the same two corners) up to rounding, which welding removes.
    let mut tris = Vec::with_capacity(20 * n * n);
    for f in faces {
        limits.check_time()?;
        let (a, b, c) = (v[f[0]], v[f[1]], v[f[2]]);
        let pt = |i: usize, j: usize| {
            // i along a→b, j along a→c.
            let p = a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64);
            p.normalize() * r
        };
        for i in 0..n {
            for j in 0..(n - i) {
                tris.push([pt(i, j), pt(i + 1, j), pt(i, j + 1)]);
                if i + j + 1 < n {
                    tris.push([pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1)]);
                }
            }
        }
    }
    Ok(Soup::from_triangles(tris))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BuildOptions, Mesh};

    #[test]
    fn cylinder_meets_both_tolerances_and_closes() {
        let cyl = Analytic::parse("cylinder:r=300,l=1000").unwrap();
        let (d, l) = (0.2, 65.0);
        let soup = tessellate_analytic(&cyl, &Tessellation::Chord { d_l2s: d, l_seg: l }).unwrap();
        let (mesh, rep) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
        assert_eq!(rep.degenerate_removed, 0);
        // Closed tube: exactly two boundary loops (the ends).
        assert_eq!(mesh.boundary_loops().len(), 2);
        for f in 0..mesh.num_faces() as u32 {
            let c = mesh.corners(f);
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                assert!(a.distance(b) <= l + 1e-9);
                // Midpoint of a chord of the tube: distance to the surface.
                let m = (a + b) * 0.5;
                let dev = 300.0 - (m.x * m.x + m.y * m.y).sqrt();
                assert!(dev <= d + 1e-9, "deviation {dev}");
            }
        }
        assert!((mesh.area() - cyl.area()).abs() / cyl.area() < 2e-3);
    }

    #[test]
    fn whole_sphere_is_a_closed_icosphere() {
        let s = Analytic::parse("sphere:r=500").unwrap();
        let soup = tessellate_analytic(&s, &Tessellation::Triangles(20 * 30 * 30)).unwrap();
        let (mesh, rep) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
        assert_eq!(mesh.num_faces(), 18000);
        assert_eq!(rep.degenerate_removed, 0);
        assert!(mesh.boundary_loops().is_empty());
        // Euler characteristic of a sphere.
        let chi = mesh.positions().len() as i64 - mesh.num_edges() as i64 + mesh.num_faces() as i64;
        assert_eq!(chi, 2);
        // Outward orientation kept.
        let c = mesh.corners(0);
        assert!(mesh.face_normal(0).dot((c[0] + c[1] + c[2]) / 3.0) > 0.0);
    }

    #[test]
    fn limits_refuse_before_allocating_and_a_passed_deadline_stops() {
        let plane = Analytic::parse("plane:a=1000000,b=1000000").unwrap();
        let limits = TessellationLimits { max_triangles: 100_000, deadline: None };
        let fine = Tessellation::Chord { d_l2s: 0.05, l_seg: 1.0 };
        assert_eq!(tessellate_analytic_within(&plane, &fine, &limits), Err(TessellationError::TooFine(100_000)));
        let many = Tessellation::Triangles(200_000);
        assert_eq!(
            tessellate_analytic_within(&plane, &many, &limits),
            Err(TessellationError::TooMany(200_000, 100_000))
        );
        let sphere = Analytic::parse("sphere:r=500").unwrap();
        assert!(tessellate_analytic_within(&sphere, &many, &limits).is_err());
        assert_eq!(tessellate_analytic(&plane, &Tessellation::Triangles(1)), Err(TessellationError::TooFew(1)));
        let past = TessellationLimits { max_triangles: MAX_TRIANGLES, deadline: Some(std::time::Instant::now()) };
        let coarse = Tessellation::Triangles(1000);
        assert_eq!(tessellate_analytic_within(&plane, &coarse, &past), Err(TessellationError::TimeLimit));
        assert_eq!(tessellate_analytic_within(&sphere, &coarse, &past), Err(TessellationError::TimeLimit));
    }

    #[test]
    fn a_tube_of_two_triangles_still_closes() {
        let cyl = Analytic::parse("cylinder:r=300,l=1000").unwrap();
        let soup = tessellate_analytic(&cyl, &Tessellation::Triangles(2)).unwrap();
        let (mesh, _) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
        assert_eq!(mesh.num_faces(), 6);
        assert_eq!(mesh.boundary_loops().len(), 2);
    }

    #[test]
    fn target_triangle_count_is_met_roughly() {
        let cyl = Analytic::parse("cylinder:r=300,l=1000").unwrap();
        let soup = tessellate_analytic(&cyl, &Tessellation::Triangles(20_000)).unwrap();
        let n = soup.triangles.len() as f64;
        assert!((n - 20_000.0).abs() / 20_000.0 < 0.05, "{n}");
    }
}
