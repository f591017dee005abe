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
    // Nothing looks wrong: no warning (the sections round the tube count its courses once).
    assert_eq!(s["warnings"].as_array().map(Vec::len), Some(0), "{s}");
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

/// Runs `towpath layup ARGS` in `dir`: exit code, stdout, stderr.
fn layup_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let mut c = towpath();
    c.current_dir(dir).arg("layup").args(args);
    run(&mut c)
}

#[test]
fn bad_numbers_sizes_and_descriptions_are_refused_quickly_and_nothing_is_written() {
    let d = scratch("refuse");
    std::fs::write(
        d.join("typo.json"),
        "{\"degree_u\": 1, \"degree_v\": 1, \"knots_u\": [0, 0, 1, 1], \"knots_v\": [0, 0, 1, 1],\n\
         \"count_u\": 2, \"count_v\": 2, \"control\": [[0, 0, 0], [0, 100, 0], [100, 0, 0], [100, 100, 0]],\n\
         \"weight\": [1, 1, 1, 1]}",
    )
    .unwrap();
    // A 10 × 10 grid of 1 km cells: 10 km across.
    let mut grid = String::new();
    for j in 0..=10 {
        for i in 0..=10 {
            grid.push_str(&format!("v {} {} 0\n", i as f64 * 1e6, j as f64 * 1e6));
        }
    }
    for j in 0..10 {
        for i in 0..10 {
            let a = j * 11 + i + 1;
            grid.push_str(&format!("f {a} {} {}\nf {a} {} {}\n", a + 1, a + 12, a + 12, a + 11));
        }
    }
    std::fs::write(d.join("grid.obj"), grid).unwrap();
    let plate = ["plane:a=200,b=100", "--tows", "4"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--tow-width", "6.35", "--weld-tolerance", "-1"], "weld tolerance must not be negative"),
        (vec!["--tow-width", "6.35", "--weld-tolerance", "NaN"], "weld tolerance must be a finite number"),
        (vec!["--tow-width", "6.35", "--min-steering-radius", "NaN"], "minimum steering radius must be a finite"),
        (vec!["--tow-width", "6.35", "--min-steering-radius", "-5"], "minimum steering radius must be positive"),
        (vec!["--tow-width", "6.35", "--d-l2s", "inf"], "D_l2s must be a finite"),
        (vec!["--tow-width", "6.35", "--l-seg", "0"], "L_seg must be positive"),
        (vec!["--tow-width", "6.35", "--angle", "1e300"], "ply angle"),
        (vec!["--tow-width", "6.35", "--start", "1e308,0,0"], "start point lies"),
        (vec!["--tow-width", "6.35", "--start", "1e5,0,0"], "start point is"),
        (vec!["--tow-width", "6.35", "--axis", "0,0,0"], "reference axis"),
        (vec!["--tow-width", "NaN"], "tow width must be a finite"),
        (vec!["--tow-width", "-6.35"], "tow width must be positive"),
        (vec!["--tow-width", "1e9"], "outside 0.01 to 1000 mm"),
        (vec!["--tow-width", "1e-9"], "outside 0.01 to 1000 mm"),
        (vec!["--tow-width", "1e-3"], "outside 0.01 to 1000 mm"),
        (vec!["--tow-width", "6.35", "--time-limit", "0"], "--time-limit"),
        (vec!["--tow-width", "6.35", "--time-limit", "NaN"], "--time-limit"),
        (vec!["--tow-width", "6.35", "--triangles", "100000000"], "more than the limit of 4000000"),
        (vec!["--tow-width", "6.35", "--d-l2s", "1e-9", "--l-seg", "1e-6"], "more than 4000000 triangles"),
    ];
    for (extra, expected) in cases {
        let mut args: Vec<&str> = plate.to_vec();
        args.extend(&extra);
        if !extra.contains(&"--angle") {
            args.extend(["--angle", "30"]);
        }
        args.extend(["-o", "out.json", "--gcode", "out.nc"]);
        let t = std::time::Instant::now();
        let (code, _, err) = layup_in(&d, &args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(expected), "{extra:?}: expected '{expected}' in: {err}");
        assert!(t.elapsed().as_secs_f64() < 20.0, "{extra:?} took {:?}", t.elapsed());
        assert!(!d.join("out.json").exists() && !d.join("out.nc").exists(), "{extra:?} wrote files");
    }
    let others: Vec<(Vec<&str>, &str)> = vec![
        (vec!["plane:a=200,b=100,a=300"], "a is given twice"),
        (vec!["nurbs:typo.json"], "typo.json: NURBS patch: line 3"),
        (vec!["grid.obj"], "courses, more than the limit"),
    ];
    for (surface, expected) in others {
        let mut args = surface.clone();
        args.extend(["--angle", "30", "--tows", "16", "--tow-width", "6.35", "-o", "out.json"]);
        let (code, _, err) = layup_in(&d, &args);
        assert_eq!(code, 2, "{surface:?}: {err}");
        assert!(err.contains(expected), "{surface:?}: expected '{expected}' in: {err}");
        assert!(!d.join("out.json").exists());
    }
    // The courses file is JSON: a name for another format is a slip.
    let (code, _, err) =
        layup_in(&d, &["plane:a=200,b=100", "--angle", "0", "--tow-width", "6.35", "--tows", "4", "-o", "p.nc"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("-o writes the courses as JSON"), "{err}");
}

#[test]
fn the_time_limit_stops_the_whole_run_and_nothing_is_written() {
    let d = scratch("time");
    // About a thousand courses of 0.2 mm: tens of seconds of work, stopped at a quarter second.
    let t = std::time::Instant::now();
    let (code, _, err) = layup_in(
        &d,
        &[
            "plane:a=200,b=100",
            "--angle",
            "30",
            "--tows",
            "4",
            "--tow-width",
            "0.05",
            "--time-limit",
            "0.25",
            "-o",
            "p.json",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("time limit was reached") && err.contains("--time-limit"), "{err}");
    assert!(t.elapsed().as_secs_f64() < 10.0, "stopped after {:?}", t.elapsed());
    assert!(!d.join("p.json").exists());
}

#[test]
fn units_convert_the_inputs_and_implausible_sizes_are_warned_about() {
    let d = scratch("units");
    let json = |args: &[&str]| {
        let (code, out, err) = layup_in(&d, args);
        assert_eq!(code, 0, "{err}");
        (serde_json::from_str::<serde_json::Value>(&out).expect("one JSON object"), err)
    };
    let common = ["--angle", "30", "--tows", "4", "--json"];
    // The same plate and tows in mm, in inches, and in inches with a tow width in mm.
    let (mm, _) = json(&[&["plane:a=254,b=127", "--tow-width", "6.35", "-o", "mm.json"][..], &common].concat());
    let (inch, _) =
        json(&[&["plane:a=10,b=5", "--units", "in", "--tow-width", "0.25", "-o", "in.json"][..], &common].concat());
    let (mixed, _) =
        json(&[&["plane:a=10,b=5", "--units", "in", "--tow-width", "6.35mm", "-o", "mx.json"][..], &common].concat());
    for s in [&inch, &mixed] {
        assert_eq!(s["units"], "in");
        assert!((s["tow_width_mm"].as_f64().unwrap() - 6.35).abs() < 1e-9, "{s}");
        assert_eq!(s["courses"], mm["courses"]);
        let (a, b) = (s["ply_area"].as_f64().unwrap(), mm["ply_area"].as_f64().unwrap());
        assert!((a - 254.0 * 127.0).abs() < 1e-6 * a && (a - b).abs() < 1e-6 * a, "{a} vs {b}");
        let (a, b) = (s["course_length"].as_f64().unwrap(), mm["course_length"].as_f64().unwrap());
        assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
        assert_eq!(s["warnings"].as_array().unwrap().len(), 0, "{s}");
    }
    // The inch plate read as millimetres with an inch tow width: a 11 mm plate, 0.25 mm tows.
    let (s, err) = json(&[&["plane:a=10,b=5", "--tow-width", "0.25", "-o", "bad.json"][..], &common].concat());
    let kinds: Vec<&str> = s["warnings"].as_array().unwrap().iter().map(|w| w["kind"].as_str().unwrap()).collect();
    assert!(kinds.contains(&"surface_size") && kinds.contains(&"tow_width"), "{kinds:?}");
    assert!(err.contains("warning: the surface is 11.18 mm across") && err.contains("in: 284 mm"), "{err}");
    // A plate narrower than one course.
    let (s, _) = json(&[&["plane:a=300,b=10", "--tow-width", "6.35", "-o", "n.json"][..], &common].concat());
    let kinds: Vec<&str> = s["warnings"].as_array().unwrap().iter().map(|w| w["kind"].as_str().unwrap()).collect();
    assert!(kinds.contains(&"course_wider_than_ply"), "{kinds:?}");
}

#[test]
fn the_summary_names_units_welding_every_file_and_small_areas() {
    let d = scratch("summary");
    // An unwelded STL (every triangle its own three vertices) of a small plate.
    let (code, _, err) = layup_in(
        &d,
        &[
            "plane:a=6,b=4",
            "--angle",
            "0",
            "--tows",
            "2",
            "--tow-width",
            "1",
            "--triangles",
            "8",
            "-o",
            "a.json",
            "--write-mesh",
            "plate.stl",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = layup_in(
        &d,
        &[
            "plate.stl",
            "--angle",
            "0",
            "--tows",
            "2",
            "--tow-width",
            "1",
            "-o",
            "b.txt",
            "--gcode",
            "b.nc",
            "--csv",
            "b.csv",
            "--write-mesh",
            "b.obj",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("units           : surface and lengths in mm; outputs in mm"), "{out}");
    assert!(out.contains("welding         : 24 → 9 vertices"), "{out}");
    // 24 mm² is not "0 mm2".
    assert!(out.contains("% of 24 mm²"), "{out}");
    assert!(
        out.contains("wrote           : b.txt (courses JSON), b.nc (G-code), b.csv (CSV), b.obj (mesh, mm)"),
        "{out}"
    );
    for f in ["b.txt", "b.nc", "b.csv", "b.obj"] {
        assert!(d.join(f).exists(), "{f}");
    }
    // A plate one course wide: one course, said so.
    let (code, out, _) =
        layup_in(&d, &["plane:a=6,b=2", "--angle", "0", "--tows", "2", "--tow-width", "1", "-o", "c.json"]);
    assert_eq!(code, 0);
    assert!(out.contains("courses         : 1 ("), "{out}");
    // Every example in --help runs as written: each names the required --tow-width and --tows.
    let (code, help, _) = run(towpath().args(["layup", "--help"]));
    assert_eq!(code, 0);
    let examples: Vec<&str> = help.lines().filter(|l| l.trim_start().starts_with("towpath layup ")).collect();
    assert!(examples.len() >= 3, "{help}");
    for e in examples {
        assert!(e.contains("--tow-width") && e.contains("--tows") && e.contains("--angle") && e.contains("-o "), "{e}");
    }
}

#[test]
fn a_plate_of_two_triangles_is_covered_like_a_fine_one() {
    let d = scratch("coarse");
    let ply = |triangles: &str, out: &str| {
        let (code, out, err) = layup_in(
            &d,
            &[
                "plane:a=100,b=100",
                "--triangles",
                triangles,
                "--angle",
                "30",
                "--tow-width",
                "6.35",
                "--tows",
                "4",
                "--coverage",
                "100",
                "--start",
                "50,50,0",
                "-o",
                out,
                "--gcode",
                &format!("{out}.nc"),
                "--json",
            ],
        );
        assert_eq!(code, 0, "{err}");
        serde_json::from_str::<serde_json::Value>(&out).unwrap()
    };
    let (coarse, fine) = (ply("2", "c.json"), ply("20000", "f.json"));
    assert_eq!(coarse["mesh_triangles"], 2);
    assert_eq!(coarse["courses"], fine["courses"]);
    assert!(coarse["coverage_percent"].as_f64().unwrap() > 99.0, "{coarse}");
    let (a, b) = (coarse["tow_length"].as_f64().unwrap(), fine["tow_length"].as_f64().unwrap());
    assert!((a - b).abs() < 0.01, "laid tow length {a} vs {b}");
    // No course of the program is a point.
    let g = std::fs::read_to_string(d.join("c.json.nc")).unwrap();
    for line in g.lines().filter(|l| l.starts_with("(COURSE ")) {
        let len: f64 = line.split("LENGTH=").nth(1).unwrap().trim_end_matches(')').parse().unwrap();
        assert!(len > 25.0, "{line}");
    }
}
