//! Surfaces with an exact description: analytic ([`Analytic`]: plane, cylinder, cone, sphere) and
//! tensor-product B-spline/NURBS patches ([`Nurbs`]), all behind the [`Surface`] trait, and their
//! tessellation under a chord tolerance and a maximum edge length ([`tessellate`], seed 001 §2.2).

mod analytic;
mod nurbs;
mod tessellate;

use glam::DVec3;

pub use analytic::{Analytic, ParseError};
pub use nurbs::{Nurbs, NurbsError};
pub use tessellate::{
    tessellate, tessellate_analytic, tessellate_analytic_within, tessellate_within, Tessellation, TessellationError,
    TessellationLimits, MAX_TRIANGLES,
};

/// A parametric surface S(u, v) over a rectangle of parameters.
pub trait Surface: Send + Sync {
    /// Parameter ranges `[[u0, u1], [v0, v1]]`.
    fn domain(&self) -> [[f64; 2]; 2];
    /// The point S(u, v).
    fn eval(&self, u: f64, v: f64) -> DVec3;
    /// The point and the first partial derivatives (S, S_u, S_v).
    fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3);
    /// Unit normal S_u × S_v / |S_u × S_v| (seed 002 eq. 1).
    fn normal(&self, u: f64, v: f64) -> DVec3 {
        let (_, su, sv) = self.derivatives(u, v);
        su.cross(sv).try_normalize().unwrap_or(DVec3::Z)
    }
    /// The closest point of the surface to `p` and the unit normal there, with its parameters.
    fn closest(&self, p: DVec3) -> ClosestPoint;
    /// Whether S(u0, v) = S(u1, v): the surface closes on itself along u (a full tube).
    fn closed_u(&self) -> bool {
        false
    }
}

/// Answer of [`Surface::closest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// The surface point.
    pub point: DVec3,
    /// The unit normal there.
    pub normal: DVec3,
    /// Its parameters (u, v).
    pub uv: [f64; 2],
}
