//! `towpath spray` end to end: a plate and a box, the path file, CSV and thickness map, the
//! papers' solvers, and refused input.

use super::common::*;

/// A box [0,a]×[0,b]×[0,c] as an ASCII STL of 12 triangles.
fn box_stl(a: f64, b: f64, c: f64) -> String {
    let p = |i: usize| [(i & 1) as f64 * a, ((i >> 1) & 1) as f64 * b, ((i >> 2) & 1) as f64 * c];
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut s = String::from("solid box\n");
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s += "facet normal 0 0 0\nouter loop\n";
            for v in t {
                let x = p(v);
                s += &format!("vertex {} {} {}\n", x[0], x[1], x[2]);
            }
            s += "endloop\nendfacet\n";
        }
    }
    s + "endsolid box\n"
}

#[test]
fn plate_end_to_end() {
    let d = scratch("spray-plate");
    let out = towpath_in(
        &d,
        &[
            "spray",
            "plane:a=600,b=400",
            "--standoff",
            "200",
            "--spray-radius",
            "50",
            "--target-thickness",
            "20",
            "--spacing",
            "40",
            "--iterations",
            "200",
            "-o",
            "path.json",
            "--csv",
            "poses.csv",
            "--thickness-map",
            "t.ply",
            "--json",
        ],
    );
    let s = json_of(&out);
    assert_eq!(s["patches"], 1);
    // Lines (k + ½)·40 within 50 mm of the 400 mm wide plate: k = -1 … 10.
    assert_eq!(s["passes"], 12);
    assert_eq!(s["turns"], 11);
    for key in ["spray_length_mm", "travel_mm", "cycle_time_s"] {
        assert!(s[key].as_f64().unwrap() > 0.0, "{key}: {s}");
    }
    let t = &s["thickness"];
    // 40 mm is not the optimal spacing (0.8 R: about 2 % ripple); the mean is the target.
    assert!((t["mean"].as_f64().unwrap() - 20.0).abs() < 0.5, "{t}");
    assert!(t["rms_rel"].as_f64().unwrap() < 0.03, "{t}");
    assert!(t["min"].as_f64().unwrap() <= t["max"].as_f64().unwrap());
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(d.join("path.json")).unwrap()).unwrap();
    assert_eq!(doc["format"], "towpath-spray-path/1");
    let poses = doc["poses"].as_array().unwrap();
    let mut last = -1.0;
    for p in poses {
        let time = p["time"].as_f64().unwrap();
        assert!(time > last);
        last = time;
        assert_eq!(p["position"].as_array().unwrap().len(), 3);
        let a: Vec<f64> = p["axis"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        assert!(((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt() - 1.0).abs() < 1e-9);
        assert!(p["spray"].is_boolean());
        assert!(p.get("patch").is_some() && p.get("pass").is_some());
    }
    assert_eq!(doc["passes"].as_array().unwrap().len(), 12);
    assert_eq!(doc["patches"][0]["pattern"], "zigzag");
    let csv = std::fs::read_to_string(d.join("poses.csv")).unwrap();
    assert!(csv.starts_with("index,time,x,y,z,ax,ay,az,spray,patch,pass\n"));
    assert_eq!(csv.lines().count(), poses.len() + 1);
    let ply = std::fs::read_to_string(d.join("t.ply")).unwrap();
    assert!(ply.starts_with("ply\nformat ascii 1.0\n"));
    assert!(ply.contains("property double thickness") && ply.contains("property uchar red"));
    let nv = doc["thickness"]["vertex_um"].as_array().unwrap().len();
    assert!(ply.contains(&format!("element vertex {nv}\n")));
}

#[test]
fn box_mesh_gives_six_patches_and_the_papers_solvers_run() {
    let d = scratch("spray-box");
    std::fs::write(d.join("box.stl"), box_stl(300.0, 200.0, 150.0)).unwrap();
    let args = |solver: &str| -> Vec<String> {
        [
            "spray",
            "box.stl",
            "--standoff",
            "120",
            "--spray-radius",
            "40",
            "--target-thickness",
            "25",
            "--home",
            "150,100,600",
            "--iterations",
            "100",
            "--solver",
            solver,
            "--ga-generations",
            "20",
            "--aco-cycles",
            "2",
            "-o",
            &format!("{solver}.json"),
            "--json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let mut travel = Vec::new();
    for solver in ["towpath", "ga", "aco1"] {
        let a = args(solver);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let s = json_of(&towpath_in(&d, &a));
        assert_eq!(s["patches"], 6, "{s}");
        assert_eq!(s["solver"], solver);
        assert_eq!(s["unchecked_transits"], 0);
        assert!(s["lifted_transits"].as_u64().unwrap() > 0);
        assert_eq!(s["thickness"]["uncovered_triangles"], 0, "{s}");
        travel.push(s["travel_mm"].as_f64().unwrap());
    }
    assert!(travel.iter().all(|&t| t > 0.0));
    // towpath's search (100 kicks) is no longer than the paper's solvers on the same passes.
    assert!(travel[0] <= travel[1].min(travel[2]) + 1e-6, "travel towpath, GA, ACO1: {travel:?}");
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let d = scratch("spray-bad");
    std::fs::write(d.join("empty.stl"), "solid empty\nendsolid empty\n").unwrap();
    // Every triangle degenerate: no area.
    std::fs::write(
        d.join("flat.stl"),
        "solid f\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 1\nvertex 2 2 2\nendloop\nendfacet\nendsolid f\n",
    )
    .unwrap();
    let base = |surface: &str, h: &str, r: &str, t: &str| -> (i32, String) {
        let (code, _, err) = run(towpath().current_dir(&d).args([
            "spray",
            surface,
            "--standoff",
            h,
            "--spray-radius",
            r,
            "--target-thickness",
            t,
            "-o",
            "x.json",
        ]));
        (code, err)
    };
    let cases = [
        (base("empty.stl", "200", "50", "20"), "empty.stl"),
        (base("flat.stl", "200", "50", "20"), "no triangle of non-zero area"),
        (base("plane:a=100,b=100", "200", "0", "20"), "--spray-radius"),
        (base("plane:a=100,b=100", "0", "50", "20"), "--standoff"),
        (base("plane:a=100,b=100", "-5", "50", "20"), "--standoff"),
        (base("plane:a=100,b=100", "200", "50", "0"), "--target-thickness"),
        (base("plane:a=100,b=100", "200", "50", "-3"), "--target-thickness"),
        (base("missing.stl", "200", "50", "20"), "missing.stl"),
        (base("plane:a=0,b=100", "200", "50", "20"), "positive"),
    ];
    for ((code, err), needle) in cases {
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(needle), "expected '{needle}' in: {err}");
        assert!(!err.contains("panicked") && !err.contains("bug"), "{err}");
    }
    let (code, _, err) = run(towpath().current_dir(&d).args([
        "spray",
        "plane:a=100,b=100",
        "--standoff",
        "200",
        "--spray-radius",
        "50",
        "--target-thickness",
        "20",
        "--profile",
        "beta:0",
        "-o",
        "x.json",
    ]));
    assert_eq!(code, 2);
    assert!(err.contains("--profile") && err.contains("β"), "{err}");
    assert!(!d.join("x.json").exists(), "nothing written on a refused run");
}
