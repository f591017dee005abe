//! The surface argument of `layup` and `spray`: a mesh file (STL, OBJ, PLY), an analytic
//! description (`plane:a=600,b=400`, `cylinder:…`, `cone:…`, `sphere:…`) or `nurbs:PATCH.json`.

use std::path::Path;

use anyhow::{anyhow, Context};
use towpath_geom::surface::{tessellate, tessellate_analytic, Analytic, Nurbs, Tessellation};
use towpath_geom::{io, Soup};
use towpath_layup::request::SurfaceSource;

use crate::exit;

/// Reads the surface argument: a mesh file's triangles, or an analytic or NURBS surface still
/// to be tessellated. Everything refused is the user's to fix (exit code 2), named.
pub fn surface_source(text: &str) -> anyhow::Result<SurfaceSource> {
    let kind = text.split(':').next().unwrap_or("");
    Ok(match kind {
        "plane" | "cylinder" | "cone" | "sphere" if text.contains(':') => {
            SurfaceSource::Analytic(Analytic::parse(text).map_err(exit::bad_input)?)
        }
        "nurbs" if text.contains(':') => {
            let path = &text["nurbs:".len()..];
            let json = std::fs::read_to_string(path)
                .with_context(|| format!("{path}: cannot read"))
                .map_err(exit::bad_input)?;
            SurfaceSource::Nurbs(Nurbs::from_json(&json).map_err(|e| exit::bad_input(anyhow!("{path}: {e}")))?)
        }
        _ => SurfaceSource::Soup(io::read_path(Path::new(text)).map_err(exit::bad_input)?),
    })
}

/// The triangles of a surface source, tessellating an analytic or NURBS surface with `tess`.
pub fn soup_of(source: SurfaceSource, tess: &Tessellation) -> anyhow::Result<Soup> {
    Ok(match source {
        SurfaceSource::Soup(s) => s,
        SurfaceSource::Analytic(a) => tessellate_analytic(&a, tess).map_err(exit::bad_input)?,
        SurfaceSource::Nurbs(n) => tessellate(&n, tess).map_err(exit::bad_input)?,
    })
}
