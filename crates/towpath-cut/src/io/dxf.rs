//! DXF in and out, through the `dxf` crate.
//!
//! **Reading.** LINE, LWPOLYLINE, POLYLINE (2D, with bulges), ARC, CIRCLE and SPLINE entities of
//! model space become pieces; each layer is an operation, in the order the layers first appear
//! among the entities. Arcs and bulges are kept as exact circular arcs; a SPLINE (B-spline, with
//! weights if rational) is flattened within the tolerance, or, with only fit points, taken as
//! the polyline through them. Entities drawn with the extrusion direction (0, 0, −1) (mirrored)
//! are mirrored back. Other entities (text, dimensions, hatches, ellipses, blocks) are kept in
//! the output but are not pieces.
//!
//! **Writing.** The header, tables and every entity that is not a piece are kept; the pieces
//! follow in their new order. A piece done as drawn is written as its original entity (same
//! handle, layer, colour); a reversed or restarted one as an LWPOLYLINE (a 2D POLYLINE in R12 files) with bulges (exactly
//! the same lines and arcs) carrying the original's layer, colour and line type. Lead-ins are
//! LWPOLYLINEs on the piece's layer just before it.

use crate::error::CutError;
use crate::geom::{Path, Seg, P2};
use crate::io::json::path_from;
use crate::model::{Drawing, Piece, Placement};

/// What the DXF writer keeps of the input.
#[derive(Clone, Debug)]
pub struct DxfSource {
    base: dxf::Drawing,
    /// The original entity of each piece, and the path as read.
    entities: Vec<dxf::entities::Entity>,
    others: Vec<dxf::entities::Entity>,
    original: Vec<Path>,
}

fn err(name: &str, e: dxf::DxfError) -> CutError {
    CutError::Input(format!("{name}: {e}"))
}

fn bspline_point(degree: usize, knots: &[f64], ctrl: &[P2], w: &[f64], u: f64) -> Option<P2> {
    let n = ctrl.len();
    if n == 0 || knots.len() < n + degree + 1 {
        return None;
    }
    // Knot span k with knots[k] <= u < knots[k+1], clamped to the valid range.
    let mut k = degree;
    while k + 1 < n && knots[k + 1] <= u {
        k += 1;
    }
    let mut d: Vec<[f64; 3]> = (0..=degree)
        .map(|j| {
            let i = (k + j).saturating_sub(degree).min(n - 1);
            let wi = w.get(i).copied().unwrap_or(1.0);
            [ctrl[i][0] * wi, ctrl[i][1] * wi, wi]
        })
        .collect();
    for r in 1..=degree {
        for j in (r..=degree).rev() {
            let i = k + j - degree;
            let den = knots.get(i + degree + 1 - r)? - knots.get(i)?;
            let a = if den.abs() > 0.0 { (u - knots[i]) / den } else { 0.0 };
            for c in 0..3 {
                d[j][c] = (1.0 - a) * d[j - 1][c] + a * d[j][c];
            }
        }
    }
    let p = d[degree];
    (p[2] != 0.0).then(|| [p[0] / p[2], p[1] / p[2]])
}

fn spline_points(s: &dxf::entities::Spline, tol: f64) -> Vec<P2> {
    let ctrl: Vec<P2> = s.control_points.iter().map(|p| [p.x, p.y]).collect();
    let degree = s.degree_of_curve.max(1) as usize;
    if ctrl.len() > degree && s.knot_values.len() > ctrl.len() + degree && ctrl.len() < 100_000 {
        let (u0, u1) = (s.knot_values[degree], s.knot_values[ctrl.len()]);
        // Samples: enough per span for the tolerance on a curve this size.
        let poly_len: f64 = ctrl.windows(2).map(|w| crate::geom::dist(w[0], w[1])).sum();
        let m = ((poly_len / tol.max(1e-9)).sqrt().ceil() as usize).clamp(ctrl.len() * 4, 20_000);
        let mut out = Vec::with_capacity(m + 1);
        for i in 0..=m {
            let u = u0 + (u1 - u0) * i as f64 / m as f64;
            let u = if i == m { u1 - (u1 - u0) * 1e-12 } else { u };
            if let Some(p) = bspline_point(degree, &s.knot_values, &ctrl, &s.weight_values, u) {
                out.push(p);
            }
        }
        if let (Some(last), Some(&c)) = (out.last_mut(), ctrl.last()) {
            if s.knot_values[ctrl.len()] == s.knot_values[ctrl.len() + degree] {
                *last = c; // clamped spline ends at its last control point
            }
        }
        return out;
    }
    s.fit_points.iter().map(|p| [p.x, p.y]).collect()
}

fn mirrored(normal_z: f64, p: P2) -> P2 {
    if normal_z < 0.0 {
        [-p[0], p[1]]
    } else {
        p
    }
}

/// The path of an entity, if it is a piece kind. `what` names it in messages.
fn entity_path(e: &dxf::entities::Entity, tol: f64, what: &str) -> Result<Option<Path>, CutError> {
    use dxf::entities::EntityType as T;
    Ok(Some(match &e.specific {
        T::Line(l) => {
            let (a, b) = ([l.p1.x, l.p1.y], [l.p2.x, l.p2.y]);
            if a == b {
                return Ok(None);
            }
            let z = l.extrusion_direction.z;
            Path { start: mirrored(z, a), segs: vec![Seg::Line(mirrored(z, b))], closed: false }
        }
        T::LwPolyline(p) => {
            let z = p.extrusion_direction.z;
            let pts: Vec<[f64; 2]> = p.vertices.iter().map(|v| mirrored(z, [v.x, v.y])).collect();
            let bul: Vec<f64> = p.vertices.iter().map(|v| if z < 0.0 { -v.bulge } else { v.bulge }).collect();
            path_from(&pts, &bul, p.is_closed(), what)?
        }
        T::Polyline(p) => {
            if p.flags & (16 | 64) != 0 {
                return Ok(None); // polygon and polyface meshes
            }
            let z = p.normal.z;
            let pts: Vec<[f64; 2]> = p.vertices().map(|v| mirrored(z, [v.location.x, v.location.y])).collect();
            let bul: Vec<f64> = p.vertices().map(|v| if z < 0.0 { -v.bulge } else { v.bulge }).collect();
            path_from(&pts, &bul, p.flags & 1 != 0, what)?
        }
        T::Arc(a) => {
            if a.radius.is_nan() || a.radius <= 0.0 || !a.radius.is_finite() {
                return Err(CutError::Input(format!("{what}: arc radius {} is not positive", a.radius)));
            }
            let (s, e) = (a.start_angle.to_radians(), a.end_angle.to_radians());
            let mut sweep = (e - s).rem_euclid(std::f64::consts::TAU);
            if sweep == 0.0 {
                sweep = std::f64::consts::TAU;
            }
            let c = [a.center.x, a.center.y];
            let at = |t: f64| [c[0] + a.radius * t.cos(), c[1] + a.radius * t.sin()];
            let z = a.normal.z;
            let half = (sweep / 2.0 / 4.0).tan();
            let b = if z < 0.0 { -half } else { half };
            // Two halves keep every bulge well below 1 even for near-full arcs.
            let segs = vec![
                Seg::Arc { to: mirrored(z, at(s + sweep / 2.0)), bulge: b },
                Seg::Arc { to: mirrored(z, at(s + sweep)), bulge: b },
            ];
            Path { start: mirrored(z, at(s)), segs, closed: false }
        }
        T::Circle(ci) => {
            if ci.radius.is_nan() || ci.radius <= 0.0 || !ci.radius.is_finite() {
                return Err(CutError::Input(format!("{what}: circle radius {} is not positive", ci.radius)));
            }
            let c = [ci.center.x, ci.center.y];
            let r = ci.radius;
            let z = ci.normal.z;
            let b = if z < 0.0 { -1.0 } else { 1.0 };
            let p0 = mirrored(z, [c[0] + r, c[1]]);
            let p1 = mirrored(z, [c[0] - r, c[1]]);
            Path { start: p0, segs: vec![Seg::Arc { to: p1, bulge: b }, Seg::Arc { to: p0, bulge: b }], closed: true }
        }
        T::Spline(s) => {
            let pts = spline_points(s, tol);
            let closed = s.flags & 1 != 0;
            if pts.len() < 2 {
                return Err(CutError::Input(format!("{what}: spline has no usable control or fit points")));
            }
            path_from(&pts, &[], closed && pts.len() >= 3, what)?
        }
        _ => return Ok(None),
    }))
}

/// Reads a DXF drawing (ASCII or binary).
pub fn read(text: &str, name: &str, tol: f64) -> Result<(Drawing, DxfSource), CutError> {
    let dxf = dxf::Drawing::load(&mut text.as_bytes()).map_err(|e| err(name, e))?;
    let mut drawing = Drawing::default();
    let mut entities = Vec::new();
    let mut others = Vec::new();
    let mut original = Vec::new();
    for (i, e) in dxf.entities().enumerate() {
        let what = format!(
            "{name}: entity {} ({}, handle {:X}, layer {:?})",
            i + 1,
            kind(e),
            e.common.handle.0,
            e.common.layer
        );
        if e.common.is_in_paper_space {
            others.push(e.clone());
            continue;
        }
        match entity_path(e, tol, &what)? {
            Some(path) => {
                let op = drawing.operation_index(&e.common.layer);
                let id = if e.common.handle.0 != 0 {
                    format!("{:X}", e.common.handle.0)
                } else {
                    format!("entity {}", i + 1)
                };
                original.push(path.clone());
                drawing.pieces.push(Piece { id, operation: op, path, reversible: true, fixed: false });
                entities.push(e.clone());
            }
            None => others.push(e.clone()),
        }
    }
    let mut base = dxf;
    let mut count = base.entities().count();
    while count > 0 {
        count -= 1;
        base.remove_entity(count);
    }
    Ok((drawing, DxfSource { base, entities, others, original }))
}

fn kind(e: &dxf::entities::Entity) -> &'static str {
    use dxf::entities::EntityType as T;
    match &e.specific {
        T::Line(_) => "LINE",
        T::LwPolyline(_) => "LWPOLYLINE",
        T::Polyline(_) => "POLYLINE",
        T::Arc(_) => "ARC",
        T::Circle(_) => "CIRCLE",
        T::Spline(_) => "SPLINE",
        _ => "other",
    }
}

/// A path as an LWPOLYLINE (R13 and later) or a 2D POLYLINE (R12, which has no LWPOLYLINE).
fn polyline_entity(out: &mut dxf::Drawing, path: &Path, common: &dxf::entities::EntityCommon) -> dxf::entities::Entity {
    if out.header.version >= dxf::enums::AcadVersion::R13 {
        return lwpolyline(path, common);
    }
    let jp = crate::io::json::path_to(path);
    let mut poly = dxf::entities::Polyline { flags: i32::from(path.closed), ..Default::default() };
    for (i, p) in jp.points.iter().enumerate() {
        let mut v = dxf::entities::Vertex::new(dxf::Point::new(p[0], p[1], 0.0));
        v.bulge = jp.bulges.get(i).copied().unwrap_or(0.0);
        poly.add_vertex(out, v);
    }
    let mut e = dxf::entities::Entity::new(dxf::entities::EntityType::Polyline(poly));
    e.common.layer = common.layer.clone();
    e.common.color = common.color.clone();
    e.common.line_type_name = common.line_type_name.clone();
    e.common.lineweight_enum_value = common.lineweight_enum_value;
    e
}

fn lwpolyline(path: &Path, common: &dxf::entities::EntityCommon) -> dxf::entities::Entity {
    let jp = crate::io::json::path_to(path);
    let mut lw = dxf::entities::LwPolyline::default();
    lw.set_is_closed(path.closed);
    for (i, p) in jp.points.iter().enumerate() {
        lw.vertices.push(dxf::LwPolylineVertex {
            x: p[0],
            y: p[1],
            bulge: jp.bulges.get(i).copied().unwrap_or(0.0),
            ..Default::default()
        });
    }
    let mut e = dxf::entities::Entity::new(dxf::entities::EntityType::LwPolyline(lw));
    e.common.layer = common.layer.clone();
    e.common.color = common.color.clone();
    e.common.line_type_name = common.line_type_name.clone();
    e.common.lineweight_enum_value = common.lineweight_enum_value;
    e
}

/// Writes an ordering as DXF (ASCII).
pub fn write(source: &DxfSource, _drawing: &Drawing, order: &[Placement]) -> Result<String, CutError> {
    let mut out = source.base.clone();
    for e in &source.others {
        out.add_entity(e.clone());
    }
    for pl in order {
        let (Some(orig), Some(path)) = (source.entities.get(pl.piece), source.original.get(pl.piece)) else { continue };
        if let Some(l) = &pl.lead_in {
            let e = polyline_entity(&mut out, l, &orig.common);
            out.add_entity(e);
        }
        if pl.path == *path {
            out.add_entity(orig.clone());
        } else {
            let e = polyline_entity(&mut out, &pl.path, &orig.common);
            out.add_entity(e);
        }
    }
    let mut buf = Vec::new();
    out.save(&mut buf).map_err(|e| CutError::Input(format!("writing DXF: {e}")))?;
    String::from_utf8(buf).map_err(|e| CutError::Input(format!("writing DXF: {e}")))
}
