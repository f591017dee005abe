//! `towpath layup --report F.html`: one self-contained page holding the mesh and every course
//! (checked against the courses JSON of the same run), the summary with its units, and the
//! refusals of a report name that is not a page or names another file.

use base64::Engine as _;

use super::common::*;

/// Runs `towpath layup ARGS` in `dir`: exit code, stdout, stderr.
fn layup_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let mut c = towpath();
    c.current_dir(dir).arg("layup").args(args);
    run(&mut c)
}

/// The JSON data block the page inlines.
fn data_of(html: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"layup-data\">";
    let start = html.find(open).expect("a data block") + open.len();
    let len = html[start..].find("</script>").expect("the data block ends");
    serde_json::from_str(&html[start..start + len]).expect("the data block is JSON")
}

fn f32s(v: &serde_json::Value) -> Vec<f32> {
    let bytes = base64::engine::general_purpose::STANDARD.decode(v.as_str().expect("base64 text")).unwrap();
    assert_eq!(bytes.len() % 4, 0);
    bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

fn u32s(v: &serde_json::Value) -> Vec<u32> {
    let bytes = base64::engine::general_purpose::STANDARD.decode(v.as_str().expect("base64 text")).unwrap();
    bytes.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

/// Nothing in the page is loaded from elsewhere: no external script, style sheet, image or frame.
fn assert_self_contained(html: &str) {
    let lower = html.to_ascii_lowercase();
    for attr in ["src=", "href="] {
        for (at, _) in lower.match_indices(attr) {
            let value = lower[at + attr.len()..].trim_start_matches(['"', '\'', ' ']);
            assert!(
                !(value.starts_with("http:") || value.starts_with("https:") || value.starts_with("//")),
                "the page loads {}",
                &html[at..(at + 80).min(html.len())]
            );
        }
    }
    assert!(!lower.contains("<script src") && !lower.contains("<link"), "external script or style sheet");
    assert!(!lower.contains("url(http") && !lower.contains("@import"), "external CSS");
    // Exactly the two inline scripts: data and viewer.
    assert_eq!(lower.matches("<script").count(), 2);
}

#[test]
fn the_report_holds_the_mesh_and_every_course_of_the_run_and_needs_no_network() {
    let d = scratch("report-cyl");
    let out = layup_in(
        &d,
        &[
            "cylinder:r=300,l=1000",
            "--angle",
            "-45",
            "--axis",
            "0,0,1",
            "--tow-width",
            "6.35",
            "--tows",
            "16",
            "--triangles",
            "20000",
            "-o",
            "c.json",
            "--report",
            "c.html",
            "--json",
        ],
    );
    assert_eq!(out.0, 0, "{}", out.2);
    let s: serde_json::Value = serde_json::from_str(&out.1).unwrap();
    let kinds: Vec<(String, String)> = s["written"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| (w["path"].as_str().unwrap().to_string(), w["kind"].as_str().unwrap().to_string()))
        .collect();
    assert!(kinds.contains(&("c.html".into(), "HTML report".into())), "{kinds:?}");
    let html = std::fs::read_to_string(d.join("c.html")).unwrap();
    assert!(html.starts_with("<!doctype html>"));
    assert_self_contained(&html);
    // three.js travels inside the page, with its licence line.
    assert!(html.contains("Three.js Authors") && html.contains("WebGLRenderer"));
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("c.json")).unwrap()).unwrap();
    let data = data_of(&html);
    assert_eq!(data["units"], "mm");
    let courses = doc["courses"].as_array().unwrap();
    let shown = data["courses"].as_array().unwrap();
    assert_eq!(shown.len(), s["courses"].as_u64().unwrap() as usize);
    assert_eq!(shown.len(), courses.len());
    for (c, r) in courses.iter().zip(shown) {
        assert_eq!(c["id"], r["id"]);
        let pts = c["points"].as_array().unwrap();
        let pos = f32s(&r["position"]);
        assert_eq!(pos.len(), 3 * pts.len());
        for (i, p) in pts.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (p[k].as_f64().unwrap(), pos[3 * i + k] as f64);
                assert!((a - b).abs() <= 1e-3 * (1.0 + a.abs()), "course {} point {i}: {a} vs {b}", c["id"]);
            }
        }
        // The quality maps are the ply's own, per point.
        let dev = f32s(&r["angle_deviation_deg"]);
        let want: Vec<f64> = c["angle_deviation_deg"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        assert_eq!(dev.len(), want.len());
        assert!(dev.iter().zip(&want).all(|(a, b)| (*a as f64 - b).abs() < 1e-4));
        let radius = f32s(&r["steering_radius"]);
        for (a, b) in radius.iter().zip(c["steering_radius"].as_array().unwrap()) {
            match b.as_f64() {
                None => assert!(a.is_infinite(), "straight is infinite: {a}"),
                Some(b) => assert!((*a as f64 - b).abs() <= 1e-5 * b, "{a} vs {b}"),
            }
        }
        let gaps = f32s(&r["gap_to_left"]);
        assert_eq!(gaps.len(), 2 * c["gap_to_left"].as_array().unwrap().len());
        let laid: Vec<&serde_json::Value> = c["tows"].as_array().unwrap().iter().map(|t| &t["laid"]).collect();
        let shown_tows: Vec<&serde_json::Value> = r["tows"].as_array().unwrap().iter().collect();
        assert_eq!(laid, shown_tows);
    }
    let mesh = &data["mesh"];
    let (nv, nt) = (mesh["vertex_count"].as_u64().unwrap() as usize, mesh["triangle_count"].as_u64().unwrap());
    assert_eq!(nt, s["mesh_triangles"].as_u64().unwrap());
    assert_eq!(f32s(&mesh["positions"]).len(), 3 * nv);
    let tri = u32s(&mesh["triangles"]);
    assert_eq!(tri.len() as u64, 3 * nt);
    assert!(tri.iter().all(|&i| (i as usize) < nv));
    // Every vertex of a cylinder r=300 lies at radius 300 (f32).
    let p = f32s(&mesh["positions"]);
    assert!(p.chunks_exact(3).all(|v| ((v[0] as f64).hypot(v[1] as f64) - 300.0).abs() < 0.01));
    // The summary beside the view names its units.
    assert!(html.contains("surface and lengths in mm; outputs in mm"), "units line");
    assert!(html.contains("mm²") && html.contains(" deg"));
    assert!(html.contains(&format!("<tr><td>courses</td><td>{} (", courses.len())));
}

#[test]
fn the_report_is_listed_deterministic_and_refused_under_a_wrong_name() {
    let d = scratch("report-plate");
    let args = |dir: &str| -> Vec<String> {
        [
            "plane:a=300,b=200",
            "--angle",
            "30",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "--triangles",
            "200",
            "-o",
            &format!("{dir}/p.json"),
            "--gcode",
            &format!("{dir}/p.nc"),
            "--csv",
            &format!("{dir}/p.csv"),
            "--write-mesh",
            &format!("{dir}/p.stl"),
            "--report",
            &format!("{dir}/p.html"),
        ]
        .map(String::from)
        .to_vec()
    };
    for dir in ["a", "b"] {
        let a = args(dir);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let (code, out, err) = layup_in(&d, &a);
        assert_eq!(code, 0, "{err}");
        // The "wrote" line lists every file, the report last.
        assert!(
            out.contains(&format!(
                "wrote           : {dir}/p.json (courses JSON), {dir}/p.nc (G-code), {dir}/p.csv (CSV), {dir}/p.stl (mesh, mm), {dir}/p.html (HTML report)"
            )),
            "{out}"
        );
    }
    // Same input, same page (no clock in it): the two differ only in the folder names they list.
    let a = std::fs::read_to_string(d.join("a/p.html")).unwrap();
    let b = std::fs::read_to_string(d.join("b/p.html")).unwrap();
    assert_eq!(a.replace("a/p.", "X/p."), b.replace("b/p.", "X/p."));
    assert_self_contained(&a);
    for f in ["p.json", "p.nc", "p.csv", "p.stl", "p.html"] {
        assert!(a.contains(&format!("a/{f}")), "the page lists {f}");
    }
    // A report name that is not a page, or names another file, is refused before any work.
    let refuse = |extra: &[&str], expected: &str| {
        let mut a = vec!["plane:a=300,b=200", "--angle", "30", "--tow-width", "6.35", "--tows", "8", "-o", "r.json"];
        a.extend(extra);
        let (code, _, err) = layup_in(&d, &a);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(expected), "{extra:?}: expected '{expected}' in {err}");
        assert!(!d.join("r.json").exists(), "{extra:?} wrote the courses");
    };
    refuse(&["--report", "r.txt"], "r.txt: --report writes an HTML page; name it .html");
    refuse(&["--report", "r.json"], "r.json: --report writes an HTML page");
    refuse(&["--gcode", "x.html", "--report", "x.html"], "would be the same file");
    std::fs::copy(d.join("a/p.stl"), d.join("m.html")).unwrap();
    let (code, _, err) = layup_in(
        &d,
        &["m.html", "--angle", "30", "--tow-width", "6.35", "--tows", "8", "-o", "r.json", "--report", "m.html"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would overwrite the mesh"), "{err}");
    // -o with a page's name points to --report.
    let (code, _, err) =
        layup_in(&d, &["plane:a=300,b=200", "--angle", "30", "--tow-width", "6.35", "--tows", "8", "-o", "r.html"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("3D page: --report"), "{err}");
}
