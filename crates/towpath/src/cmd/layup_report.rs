//! `towpath layup --report F.html`: one self-contained page with the mold surface and every
//! course in 3D.
//!
//! The page is `assets/layup-report.html` with three things filled in: the summary (the same
//! rows as the command's table, as HTML), the data (one JSON object: mesh and per-course arrays
//! as base64 little-endian typed arrays, per-tow laid intervals, the ply's summary figures) and
//! the viewer script (`assets/layup-report.js`, three.js included, built from
//! `web/src/layup-report.js`). Nothing in the page is fetched, so it opens from a file or a mail
//! attachment. The per-point figures are the ply's own quality maps, not recomputed here.
//!
//! The script lives in this binary crate, not in `towpath-layup`: libraries carry no front-end
//! bundle.

use base64::Engine as _;
use serde::Serialize;
use towpath_layup::course::Course;
use towpath_layup::output;
use towpath_layup::quality::CourseQuality;
use towpath_layup::request::LayupResult;

/// The page around the data (built from `web/src/layup-report.html`).
const TEMPLATE: &str = include_str!("../../assets/layup-report.html");
/// The viewer script with three.js (built from `web/src/layup-report.js`).
const SCRIPT: &str = include_str!("../../assets/layup-report.js");

/// What the page shows besides the courses: its title and the summary rows.
pub struct Page<'a> {
    /// Title (and heading) of the page.
    pub title: &'a str,
    /// The summary as (label, value) rows, in the order the command prints them.
    pub rows: &'a [(&'static str, String)],
    /// Warnings, one message each.
    pub warnings: &'a [String],
    /// Every file the run wrote, with what it is.
    pub files: &'a [(String, &'static str)],
}

/// The whole page.
pub fn html(page: &Page<'_>, result: &LayupResult, tows: usize) -> anyhow::Result<String> {
    let data = data_json(result, tows)?;
    let summary = summary_html(page);
    let title = escape(page.title);
    fill(TEMPLATE, |name| match name {
        "title" | "heading" => Some(title.as_str()),
        "summary" => Some(summary.as_str()),
        "data" => Some(data.as_str()),
        "script" => Some(SCRIPT),
        _ => None,
    })
}

/// Replaces every `<!--towpath:NAME-->` marker of `template` by `value(NAME)`, in one pass (so
/// nothing inserted is read again as a marker).
fn fill<'v>(template: &str, value: impl Fn(&str) -> Option<&'v str>) -> anyhow::Result<String> {
    const OPEN: &str = "<!--towpath:";
    let mut out = String::with_capacity(template.len() + SCRIPT.len());
    let mut rest = template;
    while let Some(at) = rest.find(OPEN) {
        out.push_str(&rest[..at]);
        let after = &rest[at + OPEN.len()..];
        let end = after.find("-->").ok_or_else(|| anyhow::anyhow!("internal: unclosed marker in the report page"))?;
        let name = &after[..end];
        out.push_str(
            value(name).ok_or_else(|| anyhow::anyhow!("internal: unknown marker '{name}' in the report page"))?,
        );
        rest = &after[end + 3..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Text as HTML (element content and attribute values).
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(ch),
        }
    }
    out
}

fn summary_html(page: &Page<'_>) -> String {
    let mut s =
        String::from("  <div class=\"box\" id=\"summary\">\n    <div class=\"lbl\">Summary</div>\n    <table>\n");
    for (label, value) in page.rows {
        s.push_str(&format!("      <tr><td>{}</td><td>{}</td></tr>\n", escape(label), escape(value)));
    }
    s.push_str("    </table>\n  </div>\n");
    s.push_str("  <div class=\"box\" id=\"warnings\">\n");
    if page.warnings.is_empty() {
        s.push_str("    <div class=\"lbl\">Warnings</div>\n    <div class=\"small muted\">none</div>\n");
    } else {
        s.push_str(&format!(
            "    <div class=\"lbl warn\">Warnings ({})</div>\n    <ul class=\"small\">\n",
            page.warnings.len()
        ));
        for w in page.warnings {
            s.push_str(&format!("      <li>{}</li>\n", escape(w)));
        }
        s.push_str("    </ul>\n");
    }
    s.push_str("  </div>\n  <div class=\"box\" id=\"files\">\n    <div class=\"lbl\">Files written</div>\n    <ul class=\"small\">\n");
    for (path, what) in page.files {
        s.push_str(&format!("      <li>{} ({})</li>\n", escape(path), escape(what)));
    }
    s.push_str("    </ul>\n  </div>");
    s
}

/// Little-endian bytes of f32 values as base64.
fn b64_f32(values: impl IntoIterator<Item = f64>) -> String {
    let bytes: Vec<u8> = values.into_iter().flat_map(|v| (v as f32).to_le_bytes()).collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The data block's mesh: vertex positions (f32 × 3) and triangles (u32 × 3), in mm.
#[derive(Serialize)]
struct MeshData {
    vertex_count: usize,
    triangle_count: usize,
    positions: String,
    triangles: String,
}

/// One course in the data block; every array has one entry per centreline point (`gap_to_left`:
/// (arc length, width) pairs, as the ply's quality sampled them).
#[derive(Serialize)]
struct CourseData<'a> {
    id: usize,
    side: i8,
    points: usize,
    position: String,
    normal: String,
    direction: String,
    s: String,
    angle_deviation_deg: String,
    /// Infinity where the course is straight.
    steering_radius: String,
    gap_to_left: String,
    tows: &'a [Vec<[f64; 2]>],
}

#[derive(Serialize)]
struct Data<'a> {
    format: &'static str,
    version: u32,
    units: &'static str,
    tow_width: f64,
    tows: usize,
    summary: serde_json::Value,
    mesh: MeshData,
    courses: Vec<CourseData<'a>>,
}

fn course_data<'a>(c: &'a Course, q: Option<&CourseQuality>) -> CourseData<'a> {
    let n = c.points.len();
    let xyz = |f: &dyn Fn(&towpath_layup::trace::PathPoint) -> [f64; 3]| b64_f32(c.points.iter().flat_map(f));
    let angle = (0..n).map(|i| q.and_then(|q| q.angle_deviation_deg.get(i)).copied().unwrap_or(0.0));
    let radius = (0..n).map(|i| q.and_then(|q| q.steering_radius.get(i).copied().flatten()).unwrap_or(f64::INFINITY));
    CourseData {
        id: c.id,
        side: c.side,
        points: n,
        position: xyz(&|p| p.p.to_array()),
        normal: xyz(&|p| p.n.to_array()),
        direction: xyz(&|p| p.d.to_array()),
        s: b64_f32(c.points.iter().map(|p| p.s)),
        angle_deviation_deg: b64_f32(angle),
        steering_radius: b64_f32(radius),
        gap_to_left: b64_f32(q.map_or(&[][..], |q| &q.gap_to_left[..]).iter().flatten().copied()),
        tows: &c.tows,
    }
}

/// The data block: one JSON object, `<` written as `\u003c` so no string in it can end the
/// script element it sits in.
fn data_json(result: &LayupResult, tows: usize) -> anyhow::Result<String> {
    let mesh = &result.mesh;
    let ply = &result.ply;
    let triangles: Vec<u8> = mesh.triangles().iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    // The ply's figures without its timings: the page holds no clock, so a run gives the same page.
    let mut summary = output::summary(ply);
    if let Some(o) = summary.as_object_mut() {
        o.remove("seconds");
        o.remove("timings");
    }
    let data = Data {
        format: "towpath-layup-report",
        version: 1,
        units: "mm",
        tow_width: result.tow_width_mm,
        tows,
        summary,
        mesh: MeshData {
            vertex_count: mesh.positions().len(),
            triangle_count: mesh.num_faces(),
            positions: b64_f32(mesh.positions().iter().flat_map(|p| p.to_array())),
            triangles: base64::engine::general_purpose::STANDARD.encode(triangles),
        },
        courses: ply.courses.iter().map(|c| course_data(c, ply.quality.courses.get(c.id))).collect(),
    };
    Ok(serde_json::to_string(&data)?.replace('<', "\\u003c"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_has_each_marker_once_and_the_script_cannot_end_early() {
        for m in ["title", "heading", "summary", "data", "script"] {
            assert_eq!(TEMPLATE.matches(&format!("<!--towpath:{m}-->")).count(), 1, "{m}");
        }
        assert_eq!(TEMPLATE.matches("<!--towpath:").count(), 5);
        assert!(!SCRIPT.to_ascii_lowercase().contains("</script"));
    }

    #[test]
    fn fill_replaces_markers_once_and_refuses_unknown_ones() {
        let out = fill("a<!--towpath:x-->b<!--towpath:y-->c", |n| match n {
            "x" => Some("<!--towpath:y-->"),
            "y" => Some("Y"),
            _ => None,
        })
        .unwrap();
        assert_eq!(out, "a<!--towpath:y-->bYc");
        assert!(fill("<!--towpath:z-->", |_| None).is_err());
        assert!(fill("<!--towpath:z", |_| Some("")).is_err());
    }

    #[test]
    fn escape_makes_text_inert() {
        assert_eq!(escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
    }

    #[test]
    fn floats_are_little_endian_f32_in_base64() {
        let s = b64_f32([1.0, -2.5]);
        let bytes = base64::engine::general_purpose::STANDARD.decode(s).unwrap();
        assert_eq!(bytes, [1.0f32.to_le_bytes(), (-2.5f32).to_le_bytes()].concat());
    }
}
