//! `towpath layup` end to end: analytic and mesh surfaces, every direction source, outputs, and
//! errors that name the input and the problem.

use super::common::*;

#[test]
fn cylinder_helix_ply_with_gcode_and_csv() {
    let d = scratch("cyl");
    let out = towpath_in(
        &d,
        &[
            "layup",
            "cylinder:r=300,l=1000",
            "--angle",
            "45",
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
            "--gcode",
            "c.nc",
            "--csv",
            "c.csv",
            "--json",
        ],
    );
    let s = json_of(&out);
    // 45° courses of 101.6 mm on a tube of circumference 1885 mm: 1885 cos 45° / 101.6 = 13.1:
    // 13 whole courses and a closing course laying the tows that fill the 12 mm strip left.
    assert_eq!(s["courses"], 14);
    assert!(s["coverage_percent"].as_f64().unwrap() > 99.5, "{s}");
    assert!(s["max_angle_deviation_deg"].as_f64().unwrap() < 0.05);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("c.json")).unwrap()).unwrap();
    assert_eq!(doc["format"], "towpath-courses");
    assert_eq!(doc["courses"].as_array().unwrap().len(), 14);
    let g = std::fs::read_to_string(d.join("c.nc")).unwrap();
    assert!(g.starts_with("(towpath layup"));
    assert_eq!(g.matches("(COURSE ").count(), 14);
    assert!(std::fs::read_to_string(d.join("c.csv")).unwrap().starts_with("course,point,s,x,y,z"));
}

#[test]
fn mesh_file_with_guides_boundary_and_orientation_samples() {
    let d = scratch("mesh");
    // A shallow cylindrical panel written as a mesh first.
    let out = towpath_in(
        &d,
        &[
            "layup",
            "cylinder:r=800,l=600,a0=60,a1=120",
            "--angle",
            "0",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "-o",
            "first.json",
            "--write-mesh",
            "panel.stl",
            "--json",
        ],
    );
    json_of(&out);
    // Two guide curves along the panel (in z), at two angles.
    let guide = |phi: f64| -> String {
        let (c, s) = (phi.to_radians().cos() * 800.0, phi.to_radians().sin() * 800.0);
        (0..=12).map(|i| format!("{c},{s},{}\n", i as f64 * 50.0)).collect()
    };
    std::fs::write(d.join("g1.csv"), format!("x,y,z\n{}", guide(75.0))).unwrap();
    std::fs::write(d.join("g2.csv"), guide(105.0)).unwrap();
    let boundary: String = [(70.0, 50.0), (110.0, 50.0), (110.0, 550.0), (70.0, 550.0)]
        .iter()
        .map(|&(phi, z): &(f64, f64)| {
            format!("{} {} {z}\n", phi.to_radians().cos() * 800.0, phi.to_radians().sin() * 800.0)
        })
        .collect();
    std::fs::write(d.join("ply.csv"), boundary).unwrap();
    let out = towpath_in(
        &d,
        &[
            "layup",
            "panel.stl",
            "--angle",
            "30",
            "--guide",
            "g1.csv",
            "--guide",
            "g2.csv",
            "--boundary",
            "ply.csv",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "--coverage",
            "100",
            "-o",
            "g.json",
            "--json",
        ],
    );
    let s = json_of(&out);
    assert!(s["courses"].as_u64().unwrap() >= 5);
    assert!(s["coverage_percent"].as_f64().unwrap() > 99.0, "{s}");
    // Orientation samples: all along z except one corner region.
    let mut samples = String::from("x,y,z,dx,dy,dz\n");
    for i in 0..10 {
        let phi = (72.0 + 4.0 * i as f64).to_radians();
        for j in 0..10 {
            samples.push_str(&format!(
                "{},{},{},0,0,1\n",
                phi.cos() * 800.0,
                phi.sin() * 800.0,
                60.0 + 50.0 * j as f64
            ));
        }
    }
    std::fs::write(d.join("field.csv"), samples).unwrap();
    let out = towpath_in(
        &d,
        &[
            "layup",
            "panel.stl",
            "--angle",
            "0",
            "--orientations",
            "field.csv",
            "--boundary",
            "ply.csv",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "--method",
            "natural",
            "-o",
            "f.json",
            "--json",
        ],
    );
    let s = json_of(&out);
    assert!(s["courses"].as_u64().unwrap() >= 5);
    assert!(s["max_angle_deviation_deg"].as_f64().unwrap() < 0.5, "{s}");
}

#[test]
fn errors_name_the_input_and_the_problem() {
    let d = scratch("err");
    let run = |args: &[&str]| {
        let out = towpath_in(&d, args);
        (out.status.code(), String::from_utf8_lossy(&out.stderr).to_string())
    };
    let base = ["--angle", "0", "--tow-width", "6.35", "--tows", "8", "-o", "x.json"];
    let with = |first: &[&str], extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = vec!["layup".into()];
        v.extend(first.iter().map(|s| s.to_string()));
        v.extend(base.iter().map(|s| s.to_string()));
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let call = |v: Vec<String>| run(&v.iter().map(String::as_str).collect::<Vec<_>>());

    let (code, err) = call(with(&["missing.stl"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("missing.stl"), "{err}");

    std::fs::write(d.join("bad.stl"), b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n").unwrap();
    let (code, err) = call(with(&["bad.stl"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("bad.stl") && err.contains("STL"), "{err}");

    let (code, err) = call(with(&["cylinder:r=300"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("missing l="), "{err}");

    std::fs::write(d.join("g.csv"), "0,0,0\n1,2,oops\n").unwrap();
    let (code, err) = call(with(&["plane:a=100,b=100"], &["--guide", "g.csv"]));
    assert_eq!(code, Some(2));
    assert!(err.contains("g.csv") && err.contains("line 2"), "{err}");

    let (code, err) = call(with(&["plane:a=100,b=100"], &["--coverage", "30"]));
    assert_eq!(code, Some(2));
    assert!(err.contains("--coverage"), "{err}");

    let (code, err) = call(with(&["plane:a=100,b=100"], &["--axis", "0,0,1"]));
    assert_eq!(code, Some(2));
    assert!(err.contains("undefined"), "{err}");
}

#[test]
fn nurbs_patch_surface_is_tessellated_and_covered() {
    let d = scratch("nurbs");
    // A 400 × 300 mm bilinear-in-x, quadratic-in-y patch (a shallow trough).
    let patch = serde_json::json!({
        "degree_u": 1, "degree_v": 2,
        "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 0, 1, 1, 1],
        "count_u": 2, "count_v": 3,
        "control": [[0, 0, 40], [0, 150, -40], [0, 300, 40], [400, 0, 40], [400, 150, -40], [400, 300, 40]]
    });
    std::fs::write(d.join("patch.json"), patch.to_string()).unwrap();
    let out = towpath_in(
        &d,
        &[
            "layup",
            "nurbs:patch.json",
            "--angle",
            "0",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "--d-l2s",
            "0.05",
            "--l-seg",
            "10",
            "-o",
            "n.json",
            "--json",
        ],
    );
    let s = json_of(&out);
    // The trough's cross section is about 320 mm long: 7 courses of 50.8 mm.
    let n = s["courses"].as_u64().unwrap();
    assert!((6..=8).contains(&n), "{s}");
    assert!(s["coverage_percent"].as_f64().unwrap() > 99.0, "{s}");
    std::fs::write(d.join("bad.json"), r#"{"degree_u": 1}"#).unwrap();
    let out = towpath_in(
        &d,
        &["layup", "nurbs:bad.json", "--angle", "0", "--tow-width", "6.35", "--tows", "8", "-o", "b.json"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.json"));
}

const SIX_AXIS: &str = r#"name = "six-axis"
[[axis]]
label = "X"
kind = "linear"
[[axis]]
label = "Y"
kind = "linear"
[[axis]]
label = "Z"
kind = "linear"
[[axis]]
label = "A"
kind = "rotary"
[[axis]]
label = "B"
kind = "rotary"
[[axis]]
label = "C"
kind = "continuous"
heading = true
"#;

/// Every laying move of a program runs along the head's fiber axis (x of R = Rx(A)·Ry(B)·Rz(C))
/// with the tool axis (z) across it; returns the number of moves checked.
fn moves_follow_the_head_frame(text: &str, machine: &towpath_machine::Machine) -> usize {
    let p = towpath_nc::parse(text, machine, &towpath_nc::Dialect::default()).expect("program parses");
    let mut checked = 0;
    for s in p.segments.iter().filter(|s| s.on_part) {
        let (a, b) = (p.point(s.from), p.point(s.to));
        let chord = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let len = (chord[0] * chord[0] + chord[1] * chord[1] + chord[2] * chord[2]).sqrt();
        if len < 0.5 {
            continue; // rounding dominates short moves
        }
        let (sa, ca) = b[3].to_radians().sin_cos();
        let (sb, cb) = b[4].to_radians().sin_cos();
        let (sc, cc) = b[5].to_radians().sin_cos();
        // Columns of Rx(A)·Ry(B)·Rz(C): x (fiber) and z (tool axis).
        let x = [cb * cc, ca * sc + sa * sb * cc, sa * sc - ca * sb * cc];
        let z = [sb, -sa * cb, ca * cb];
        let dot = |u: [f64; 3]| (u[0] * chord[0] + u[1] * chord[1] + u[2] * chord[2]) / len;
        assert!(dot(x) > 0.99, "line {}: fiber axis {x:?} against the move {chord:?}", s.line + 1);
        assert!(dot(z).abs() < 0.05, "line {}: tool axis {z:?} not across the move {chord:?}", s.line + 1);
        checked += 1;
    }
    checked
}

#[test]
fn layup_gcode_is_optimized_bidirectionally_and_verified() {
    let d = scratch("gcode");
    std::fs::write(d.join("six-axis.toml"), SIX_AXIS).unwrap();
    let machine = towpath_machine::Machine::from_toml_str(SIX_AXIS).unwrap();
    let out = towpath_in(
        &d,
        &[
            "layup",
            "cylinder:r=300,l=400,a0=30,a1=150",
            "--angle",
            "-45",
            "--axis",
            "0,0,1",
            "--tow-width",
            "6.35",
            "--tows",
            "8",
            "--triangles",
            "8000",
            "--ply-number",
            "2",
            "-o",
            "ply.json",
            "--gcode",
            "ply.nc",
            "--json",
        ],
    );
    let s = json_of(&out);
    let courses = s["courses"].as_u64().unwrap();
    assert!(courses >= 10, "{s}");
    let original = std::fs::read_to_string(d.join("ply.nc")).unwrap();
    assert!(moves_follow_the_head_frame(&original, &machine) > 100);
    let common = ["--machine", "six-axis.toml", "--tow-width", "6.35"];
    let mut args = vec!["optimize", "ply.nc", "--bidirectional", "--time-limit", "1", "-o", "opt.nc", "--json"];
    args.extend(common);
    let r = json_of(&towpath_in(&d, &args));
    assert_eq!(r["courses"].as_u64(), Some(courses), "{r}");
    assert!(r["reversed"].as_u64().unwrap() > 0, "a ply laid all one way has courses to reverse: {r}");
    // The optimized program lays the same courses, some reversed (heading C ± 180°): the head
    // still points along every laying move.
    let optimized = std::fs::read_to_string(d.join("opt.nc")).unwrap();
    assert!(moves_follow_the_head_frame(&optimized, &machine) > 100);
    let mut args = vec!["verify", "ply.nc", "opt.nc", "--json"];
    args.extend(common);
    let v = json_of(&towpath_in(&d, &args));
    assert_eq!(v["verified"], true, "{v}");
    assert_eq!(v["courses"].as_u64(), Some(courses));
}
