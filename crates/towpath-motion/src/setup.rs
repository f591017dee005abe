//! Degenerate set-ups, refused before anything is checked or planned.

use towpath_geom::DVec3;

use crate::cell::Cell;
use crate::error::SetupError;
use crate::rig::Rig;

/// Checks that every laid point (part frame) lies within `max_gap` mm of an obstacle triangle,
/// so that the mold under the laid path is the mesh given, in the right frame and units.
pub fn check_laid_points(cell: &Cell, points: &[[f64; 3]], max_gap: f64) -> Result<(), SetupError> {
    if points.is_empty() {
        return Ok(());
    }
    if cell.num_triangles() == 0 {
        return Err(SetupError::EmptyMold);
    }
    for (index, p) in points.iter().enumerate() {
        let d = cell.point_distance(DVec3::new(p[0], p[1], p[2]), max_gap);
        if !(d < max_gap) {
            let distance = cell.point_distance(DVec3::new(p[0], p[1], p[2]), f64::INFINITY);
            return Err(SetupError::OffMold { index, point: *p, distance, max_gap });
        }
    }
    Ok(())
}

/// Checks that no laid point (part frame) lies within `min_radius` mm of the mandrel's axis (a
/// machine without a mandrel passes).
pub fn check_mandrel_radius(rig: &Rig, points: &[[f64; 3]], min_radius: f64) -> Result<(), SetupError> {
    let Some((_, o, k)) = rig.mandrel() else { return Ok(()) };
    for (index, p) in points.iter().enumerate() {
        let v = DVec3::new(p[0], p[1], p[2]) - o;
        let radius = (v - k * v.dot(k)).length();
        if !(radius >= min_radius) {
            return Err(SetupError::OnMandrelAxis { index, radius, min_radius });
        }
    }
    Ok(())
}

/// Checks every state against the machine's axes and travel limits (with 1e-9 of slack),
/// reporting the first state outside them.
pub fn check_states<'a>(rig: &Rig, states: impl IntoIterator<Item = &'a [f64]>) -> Result<(), SetupError> {
    for s in states {
        rig.check_limits(s, 1e-9)?;
    }
    Ok(())
}
