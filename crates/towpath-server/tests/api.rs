//! The JSON API, driven through the router as a browser would (no sockets): uploads, solves,
//! progress, cancel, refusals, limits, path traversal and the job bound.

use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::body::Body;
use axum::http::{Request, StatusCode};
use axum::Router;
use http_body_util::BodyExt;
use serde_json::{json, Value};
use tower::ServiceExt;
use towpath_server::{router, AppState, Config};

struct App {
    router: Router,
    state: Arc<AppState>,
    dir: std::path::PathBuf,
}

fn tmpdir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("towpath-api-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn app_with(tag: &str, f: impl FnOnce(&mut Config)) -> App {
    let dir = tmpdir(tag);
    let mut config = Config { workspace: dir.join("ws"), ..Config::default() };
    f(&mut config);
    let state = AppState::new(config).expect("state");
    App { router: router(state.clone()), state, dir }
}

async fn call(app: &App, req: Request<Body>) -> (StatusCode, Vec<u8>) {
    let res = app.router.clone().oneshot(req).await.expect("response");
    let status = res.status();
    let body = res.into_body().collect().await.expect("body").to_bytes().to_vec();
    (status, body)
}

async fn get(app: &App, uri: &str) -> (StatusCode, Vec<u8>) {
    call(app, Request::get(uri).body(Body::empty()).expect("request")).await
}

async fn get_json(app: &App, uri: &str) -> (StatusCode, Value) {
    let (s, b) = get(app, uri).await;
    (s, serde_json::from_slice(&b).unwrap_or(Value::Null))
}

async fn send(app: &App, method: &str, uri: &str, ctype: &str, body: impl Into<Body>) -> (StatusCode, Value) {
    let req = Request::builder().method(method).uri(uri).header("content-type", ctype).body(body.into()).expect("req");
    let (s, b) = call(app, req).await;
    (s, serde_json::from_slice(&b).unwrap_or(Value::Null))
}

async fn post_json(app: &App, uri: &str, v: Value) -> (StatusCode, Value) {
    send(app, "POST", uri, "application/json", v.to_string()).await
}

async fn demo_text(app: &App, id: &str) -> String {
    let (s, b) = get(app, &format!("/api/programs/{id}/text")).await;
    assert_eq!(s, StatusCode::OK);
    String::from_utf8(b).expect("utf8")
}

async fn wait_final(app: &App, id: &str, limit: Duration) -> Value {
    let t0 = Instant::now();
    loop {
        let (_, v) = get_json(app, &format!("/api/jobs/{id}")).await;
        if matches!(v["state"].as_str(), Some("done" | "failed" | "cancelled")) {
            return v;
        }
        assert!(t0.elapsed() < limit, "job {id} did not end: {v}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn uploads_are_parsed_kept_and_survive_a_restart() {
    let app = app_with("upload", |_| {});
    let text = demo_text(&app, "demo-planar-0").await;
    let (s, v) = send(&app, "POST", "/api/programs?name=mine.nc&machine=gantry-afp", "text/plain", text.clone()).await;
    assert_eq!(s, StatusCode::CREATED, "{v}");
    let expected_courses = text.lines().filter(|l| l.trim() == "M20").count();
    assert_eq!(v["summary"]["courses"], json!(expected_courses));
    assert_eq!(v["summary"]["plies"], json!(text.lines().filter(|l| l.starts_with("(PLY")).count()));
    // A new server on the same workspace has it, byte for byte.
    let again = App { router: router(AppState::new(app.state.config.clone()).expect("state")), ..app };
    let (s, b) = get(&again, "/api/programs/mine.nc/text").await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(String::from_utf8(b).expect("utf8"), text);
    let (s, v) = get_json(&again, "/api/programs").await;
    assert_eq!(s, StatusCode::OK);
    assert!(v["programs"].as_array().expect("list").iter().any(|p| p["id"] == "mine.nc" && p["source"] == "upload"));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_inputs_are_refused_with_file_line_and_problem() {
    let app = app_with("bad", |_| {});
    // A program whose fifth line has a word with no number.
    let bad = "%\n(PLY 1)\n(COURSE 1)\nG0 X0 Y0 Z25\nG1 X10 Y QQ F3000\nM20\nG1 X100\nM21\nM30\n%\n";
    let (s, v) = send(&app, "POST", "/api/programs?name=broken.nc", "text/plain", bad).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    assert_eq!(v["file"], "broken.nc");
    assert_eq!(v["line"], 5);
    assert!(v["error"].as_str().expect("msg").starts_with("broken.nc: line 5: "), "{v}");
    // Not UTF-8: the line and byte are named.
    let (s, v) = send(&app, "POST", "/api/programs?name=latin1.nc", "text/plain", b"G0 X0\nG1 X\xe9\n".to_vec()).await;
    assert_eq!(s, StatusCode::BAD_REQUEST);
    assert_eq!(v["line"], 2, "{v}");
    // Nothing refused is kept.
    assert!(!app.dir.join("ws/programs/broken.nc").exists());
    assert!(!app.dir.join("ws/programs/latin1.nc").exists());
    // An unknown machine, a machine file with a syntax error (line 3), a bad job request.
    let (s, v) = send(&app, "POST", "/api/programs?name=x.nc&machine=nope", "text/plain", "G0 X0\n").await;
    assert_eq!(s, StatusCode::BAD_REQUEST);
    assert!(v["error"].as_str().expect("msg").contains("nope"));
    let toml = "name = \"m\"\n[[axis]]\nlabel = = \"X\"\n";
    let (s, v) = send(&app, "PUT", "/api/machines/m", "text/plain", toml).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    assert_eq!((v["file"].as_str(), v["line"].as_u64()), (Some("m.toml"), Some(3)), "{v}");
    for (req, word) in [
        (json!({"program": "demo-planar-0", "cost": "speed"}), "cost"),
        (json!({"program": "demo-planar-0", "precedence": "none"}), "precedence"),
        (json!({"program": "demo-planar-0", "time_limit": -1}), "time_limit"),
        (json!({"program": "demo-planar-0", "time_limit": 10000}), "at most"),
        (json!({"program": "demo-planar-0", "tow_width": 0}), "width"),
        (json!({"program": "demo-planar-0", "colour": 1}), "colour"),
    ] {
        let (s, v) = post_json(&app, "/api/jobs/optimize", req.clone()).await;
        assert_eq!(s, StatusCode::BAD_REQUEST, "{req}: {v}");
        assert!(v["error"].as_str().expect("msg").contains(word), "{req}: {v}");
    }
    let (s, _) = post_json(&app, "/api/jobs/optimize", json!({"program": "no-such"})).await;
    assert_eq!(s, StatusCode::NOT_FOUND);
    let (s, v) = post_json(&app, "/api/jobs/layup", json!({"tows": 0})).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    let (s, v) = send(&app, "POST", "/api/jobs/optimize", "application/json", "{not json").await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn uploads_over_the_limit_are_refused() {
    let app = app_with("limit", |c| c.max_upload = 4096);
    let big = "G0 X0\n".repeat(1000);
    let (s, v) = send(&app, "POST", "/api/programs?name=big.nc", "text/plain", big).await;
    assert_eq!(s, StatusCode::PAYLOAD_TOO_LARGE, "{v}");
    assert!(v["error"].as_str().expect("msg").contains("larger than"), "{v}");
    assert!(!app.dir.join("ws/programs/big.nc").exists());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn no_request_reaches_outside_the_workspace() {
    let app = app_with("traversal", |_| {});
    let outside = app.dir.join("evil.nc");
    for name in ["../evil.nc", "..%2Fevil.nc", "%2E%2E%2Fevil.nc", ".evil", "a%2F..%2F..%2Fevil.nc"] {
        let (s, v) = send(&app, "POST", &format!("/api/programs?name={name}"), "text/plain", "G0 X0\n").await;
        assert_eq!(s, StatusCode::BAD_REQUEST, "{name}: {v}");
        let (s, _) = send(&app, "PUT", &format!("/api/machines/{name}"), "text/plain", "name='x'").await;
        assert!(s == StatusCode::BAD_REQUEST || s == StatusCode::NOT_FOUND, "{name}: {s}");
        let (s, _) = send(&app, "POST", &format!("/api/meshes?name={name}"), "application/octet-stream", "x").await;
        assert_eq!(s, StatusCode::BAD_REQUEST, "{name}");
    }
    assert!(!outside.exists());
    for uri in [
        "/api/programs/..%2F..%2FCargo.toml/text",
        "/api/programs/%2Fetc%2Fpasswd/text",
        "/api/jobs/job-1/files/..%2Fjob.json",
        "/../../Cargo.toml",
        "/%2E%2E/%2E%2E/Cargo.toml",
        "/api/machines/..%2F..%2Fetc",
    ] {
        let (s, b) = get(&app, uri).await;
        assert!(s.is_client_error(), "{uri}: {s} {}", String::from_utf8_lossy(&b));
    }
    // A file beside a job's results that the job does not list is not served either.
    std::fs::create_dir_all(app.dir.join("ws/results/job-1")).expect("dir");
    std::fs::write(app.dir.join("ws/results/job-1/secret.txt"), "x").expect("write");
    let (s, _) = get(&app, "/api/jobs/job-1/files/secret.txt").await;
    assert_eq!(s, StatusCode::NOT_FOUND);
    // Requests that change something from another origin are refused; CORS headers are never sent.
    let req = Request::post("/api/programs?name=x.nc")
        .header("host", "127.0.0.1:8437")
        .header("origin", "http://evil.example")
        .body(Body::from("G0 X0\n"))
        .expect("req");
    let res = app.router.clone().oneshot(req).await.expect("res");
    assert_eq!(res.status(), StatusCode::FORBIDDEN);
    assert!(res.headers().get("access-control-allow-origin").is_none());
}

/// Reads server-sent events until `end`: (event name, data, seconds since the first event).
async fn read_events(app: &App, job: &str) -> Vec<(String, Value, f64)> {
    let res = app
        .router
        .clone()
        .oneshot(Request::get(format!("/api/jobs/{job}/events")).body(Body::empty()).expect("req"))
        .await
        .expect("res");
    assert_eq!(res.status(), StatusCode::OK);
    assert_eq!(res.headers()["content-type"], "text/event-stream");
    let mut body = res.into_body();
    let (mut buf, mut out) = (String::new(), Vec::new());
    let t0 = Instant::now();
    while let Some(frame) = body.frame().await {
        let frame = frame.expect("frame");
        let Some(data) = frame.data_ref() else { continue };
        buf.push_str(&String::from_utf8_lossy(data));
        while let Some(end) = buf.find("\n\n") {
            let block: String = buf.drain(..end + 2).collect();
            let mut name = String::new();
            let mut payload = String::new();
            for line in block.lines() {
                if let Some(n) = line.strip_prefix("event: ") {
                    name = n.to_string();
                } else if let Some(d) = line.strip_prefix("data: ") {
                    payload.push_str(d);
                }
            }
            if !name.is_empty() {
                out.push((
                    name.clone(),
                    serde_json::from_str(&payload).unwrap_or(Value::Null),
                    t0.elapsed().as_secs_f64(),
                ));
            }
            if name == "end" {
                return out;
            }
        }
    }
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_solve_streams_progress_and_its_program_verifies() {
    let app = app_with("solve", |_| {});
    let (s, job) = post_json(&app, "/api/jobs/optimize", json!({"program": "demo-planar-45", "time_limit": 1.5})).await;
    assert_eq!(s, StatusCode::ACCEPTED, "{job}");
    let id = job["id"].as_str().expect("id").to_string();
    let events = read_events(&app, &id).await;
    let (last, v, _) = events.last().expect("events");
    assert_eq!(last, "end");
    assert_eq!(v["state"], "done", "{v}");
    // At least 5 updates a second while it ran.
    let running: Vec<f64> = events.iter().filter(|e| e.1["state"] == "running").map(|e| e.2).collect();
    let span = running.last().copied().unwrap_or(0.0) - running.first().copied().unwrap_or(0.0);
    assert!(span > 1.0, "ran {span} s");
    assert!(running.len() as f64 >= 5.0 * span, "{} updates in {span} s", running.len());
    // Elapsed time rises; best cost never rises; the saving is against the original's cost.
    let el: Vec<f64> = events.iter().filter_map(|e| e.1["elapsed"].as_f64()).collect();
    assert!(el.windows(2).all(|w| w[1] >= w[0]));
    let best: Vec<f64> = events.iter().filter_map(|e| e.1["best_cost"].as_f64()).collect();
    assert!(best.windows(2).all(|w| w[1] <= w[0] + 1e-9), "{best:?}");
    let r = &v["result"];
    assert_eq!(r["verified"], true);
    let (init, fin) = (v["initial_cost"].as_f64().expect("init"), v["best_cost"].as_f64().expect("best"));
    assert!((v["saved_percent"].as_f64().expect("saved") - 100.0 * (init - fin) / init).abs() < 1e-9);
    // The downloaded program verifies independently against the original.
    let (s, b) = get(&app, &format!("/api/jobs/{id}/files/optimized.nc")).await;
    assert_eq!(s, StatusCode::OK);
    let optimized = String::from_utf8(b).expect("utf8");
    let original = demo_text(&app, "demo-planar-45").await;
    assert_ne!(optimized, original);
    let machine = towpath_nc::demo::gantry();
    let opts = towpath_nc::VerifyOptions {
        width: Some(towpath_nc::Width::Tow(towpath_nc::demo::TOW_WIDTH)),
        ..Default::default()
    };
    let ver = towpath_nc::verify(&original, &optimized, &machine, &towpath_nc::Dialect::default(), &opts)
        .expect("the optimized program verifies");
    let (before, after) = ver.motion(towpath_machine::CostKind::Axis).expect("axis motion");
    assert!(after.off_part() < before.off_part(), "{} -> {}", before.off_part(), after.off_part());
    // The result is a program of its own, kept in the workspace, with its geometry.
    let pid = r["program"].as_str().expect("program id");
    assert!(app.dir.join("ws/programs").join(pid).exists());
    let (s, b) = get(&app, &format!("/api/programs/{pid}/geometry")).await;
    assert_eq!(s, StatusCode::OK);
    let (header, _) = towpath_server::geometry::decode(&b).expect("blob");
    assert_eq!(header["program"]["courses"].as_array().map(Vec::len), Some(ver.courses));
    // The report downloads.
    let (s, b) = get(&app, &format!("/api/jobs/{id}/files/report.json")).await;
    assert_eq!(s, StatusCode::OK);
    let rep: Value = serde_json::from_slice(&b).expect("json");
    assert_eq!(rep["verified"], true);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cancelled_solve_stops_and_frees_its_slot() {
    let app = app_with("cancel", |c| c.max_jobs = 1);
    let (_, job) =
        post_json(&app, "/api/jobs/optimize", json!({"program": "demo-cylinder-base-3-pads", "time_limit": 60})).await;
    let id = job["id"].as_str().expect("id").to_string();
    let t0 = Instant::now();
    loop {
        let (_, v) = get_json(&app, &format!("/api/jobs/{id}")).await;
        if v["phase"] == "solving" {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "never started solving: {v}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let (s, v) = post_json(&app, &format!("/api/jobs/{id}/cancel"), json!({})).await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(v["state"], "cancelled");
    // The one slot is free again well before the 60 s limit: the next job runs and finishes.
    let t1 = Instant::now();
    let (_, next) = post_json(&app, "/api/jobs/optimize", json!({"program": "demo-planar-0", "iterations": 50})).await;
    let v = wait_final(&app, next["id"].as_str().expect("id"), Duration::from_secs(30)).await;
    assert_eq!(v["state"], "done", "{v}");
    assert!(t1.elapsed() < Duration::from_secs(30));
    assert!(!app.dir.join("ws/results").join(&id).join("optimized.nc").exists());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn jobs_beyond_the_bound_queue_and_the_queue_is_bounded() {
    let app = app_with("queue", |c| {
        c.max_jobs = 1;
        c.max_queue = 2;
    });
    let mut ids = Vec::new();
    for _ in 0..2 {
        let (s, v) =
            post_json(&app, "/api/jobs/optimize", json!({"program": "demo-planar-0", "time_limit": 1.5})).await;
        assert_eq!(s, StatusCode::ACCEPTED, "{v}");
        ids.push(v["id"].as_str().expect("id").to_string());
    }
    // The queue holds two waiting jobs at most (the first may not have started yet).
    let (s3, v3) = post_json(&app, "/api/jobs/optimize", json!({"program": "demo-planar-0", "time_limit": 1.5})).await;
    if s3 == StatusCode::ACCEPTED {
        ids.push(v3["id"].as_str().expect("id").to_string());
    }
    let mut refused = s3 == StatusCode::TOO_MANY_REQUESTS;
    for _ in 0..3 {
        let (s, _) =
            post_json(&app, "/api/jobs/optimize", json!({"program": "demo-planar-0", "time_limit": 1.5})).await;
        refused |= s == StatusCode::TOO_MANY_REQUESTS;
        if s == StatusCode::ACCEPTED {
            break;
        }
    }
    let (_, all) = get_json(&app, "/api/jobs").await;
    assert!(refused, "a full queue refuses with 429: {all}");
    // Never more than one running; all of them finish.
    let t0 = Instant::now();
    loop {
        let (_, v) = get_json(&app, "/api/jobs").await;
        let jobs = v["jobs"].as_array().expect("jobs").clone();
        let running = jobs.iter().filter(|j| j["state"] == "running").count();
        assert!(running <= 1, "{running} running at once");
        if jobs.iter().all(|j| matches!(j["state"].as_str(), Some("done" | "failed" | "cancelled"))) {
            assert!(jobs.iter().all(|j| j["state"] == "done"), "{jobs:?}");
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(60));
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn machines_are_checked_saved_and_previewed() {
    let app = app_with("machine", |_| {});
    let (s, v) = get_json(&app, "/api/machines/gantry-afp").await;
    assert_eq!(s, StatusCode::OK);
    let mut m = v["machine"].clone();
    m["name"] = json!("my-gantry");
    m["head"] = json!({"radius": 40.0, "bottom": 45.0, "top": 300.0});
    // Preview: a Cartesian gantry's tool point is its X, Y, Z.
    let (s, p) =
        post_json(&app, "/api/machine-preview", json!({"machine": m, "values": [10.0, 20.0, 30.0, 90.0]})).await;
    assert_eq!(s, StatusCode::OK, "{p}");
    assert_eq!(p["tool_point"]["part"], json!([10.0, 20.0, 30.0]));
    // Saved as TOML in the workspace, and read back by a new server.
    let (s, _) = send(&app, "PUT", "/api/machines/my-gantry", "application/json", m.to_string()).await;
    assert_eq!(s, StatusCode::OK);
    assert!(app.dir.join("ws/machines/my-gantry.toml").exists());
    let again = AppState::new(app.state.config.clone()).expect("state");
    assert_eq!(again.machine("my-gantry").expect("saved").head.map(|h| h.top), Some(300.0));
    // A head reaching below the tool point is refused, named by its key.
    let mut low = m.clone();
    low["head"]["bottom"] = json!(10.0);
    let (s, v) = post_json(&app, "/api/machine-preview", json!({"machine": low})).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    assert!(v["error"].as_str().is_some_and(|e| e.contains("head.bottom")), "{v}");
    // A machine with no axes is refused; built-ins cannot be overwritten.
    let mut bad = m.clone();
    bad["axis"] = json!([]);
    let (s, v) = post_json(&app, "/api/machine-preview", json!({"machine": bad})).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    let (s, _) = send(&app, "PUT", "/api/machines/gantry-afp", "application/json", m.to_string()).await;
    assert_eq!(s, StatusCode::BAD_REQUEST);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_front_end_is_embedded() {
    let app = app_with("assets", |_| {});
    let (s, b) = get(&app, "/").await;
    assert_eq!(s, StatusCode::OK);
    let html = String::from_utf8(b).expect("html");
    assert!(html.contains("app.js") && html.contains("towpath"));
    let (s, b) = get(&app, "/app.js").await;
    assert_eq!(s, StatusCode::OK);
    assert!(b.len() > 100_000, "three.js is bundled");
}

/// The demo stringer part's cell, checked by the library directly (the reference the API's
/// answers are compared with).
fn stringer_reference(program: &str) -> towpath_nc::SafetyReport {
    let part = towpath_nc::demo::demo_parts().into_iter().find(|p| p.name == "planar-stringer").expect("demo part");
    let dialect = towpath_nc::Dialect::default();
    let meshes: Vec<(String, towpath_geom::Soup)> = part
        .obstacles
        .iter()
        .map(|o| {
            (
                o.name.clone(),
                towpath_geom::Soup::from_triangles(o.triangles.iter().map(|t| t.map(towpath_geom::DVec3::from_array))),
            )
        })
        .collect();
    let safety = towpath_nc::Safety::from_meshes(&part.machine, &dialect, &meshes, Default::default()).expect("cell");
    let parsed = towpath_nc::parse(program, &part.machine, &dialect).expect("parses");
    towpath_nc::check_program(&parsed, &safety)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cell_is_checked_and_a_solve_in_it_plans_around_it() {
    let app = app_with("cell", |_| {});
    // The demo part in a cell names its built-in meshes, which the mesh list has.
    let (_, list) = get_json(&app, "/api/programs").await;
    let part =
        list["programs"].as_array().expect("programs").iter().find(|p| p["id"] == "demo-planar-stringer").cloned();
    let cell: Vec<String> = part.expect("demo part")["cell"]
        .as_array()
        .expect("cell")
        .iter()
        .map(|v| v.as_str().expect("name").to_string())
        .collect();
    assert_eq!(cell, ["planar-stringer.tool.stl", "planar-stringer.stringer.stl", "planar-stringer.clamp.stl"]);
    let (_, meshes) = get_json(&app, "/api/meshes").await;
    for m in &cell {
        assert!(meshes["meshes"].as_array().expect("meshes").iter().any(|x| x == m), "{m} not listed: {meshes}");
    }
    // The view draws them from their geometry (the stringer is a box: 12 triangles).
    let (s, b) = get(&app, "/api/meshes/planar-stringer.stringer.stl/geometry").await;
    assert_eq!(s, StatusCode::OK);
    let (header, _) = towpath_server::geometry::decode(&b).expect("blob");
    let tri = header["arrays"].as_array().and_then(|a| a.iter().find(|x| x["name"] == "triangles")).cloned();
    assert_eq!(tri.and_then(|t| t["length"].as_u64()), Some(36), "{header}");
    // Its input transits cross the stringer: the check finds what the library finds.
    let original = demo_text(&app, "demo-planar-stringer").await;
    let reference = stringer_reference(&original);
    assert!(!reference.collisions.is_empty());
    let (s, v) = post_json(&app, "/api/programs/demo-planar-stringer/check", json!({"molds": cell})).await;
    assert_eq!(s, StatusCode::OK, "{v}");
    let before = &v["safety"];
    assert_eq!(before["safe"], false);
    assert_eq!(before["collision_count"].as_u64(), Some(reference.collisions.len() as u64));
    let lines: Vec<u64> =
        before["collisions"].as_array().expect("list").iter().filter_map(|c| c["line"].as_u64()).collect();
    assert_eq!(lines, reference.collisions.iter().map(|c| c.line as u64).collect::<Vec<_>>());
    // A solve in the cell writes a program free of collisions, and says so for both programs.
    let req = json!({"program": "demo-planar-stringer", "iterations": 300, "molds": cell, "clearance": 5.0});
    let (s, job) = post_json(&app, "/api/jobs/optimize", req).await;
    assert_eq!(s, StatusCode::ACCEPTED, "{job}");
    let v = wait_final(&app, job["id"].as_str().expect("id"), Duration::from_secs(120)).await;
    assert_eq!(v["state"], "done", "{v}");
    let r = &v["result"];
    assert_eq!(r["verified"], true);
    assert_eq!(r["safety"]["before"]["collision_count"], before["collision_count"]);
    assert_eq!(r["safety"]["after"]["safe"], true, "{}", r["safety"]);
    let pid = r["program"].as_str().expect("program");
    let optimized = String::from_utf8(get(&app, &format!("/api/programs/{pid}/text")).await.1).expect("utf8");
    let after = stringer_reference(&optimized);
    assert!(after.is_safe(), "{}", after.summary());
    // The result keeps its cell, and checking it again finds it safe.
    let (_, info) = get_json(&app, &format!("/api/programs/{pid}")).await;
    assert_eq!(info["listing"]["cell"].as_array().map(Vec::len), Some(3));
    let (s, v) = post_json(&app, &format!("/api/programs/{pid}/check"), json!({"molds": cell})).await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(v["safety"]["safe"], true, "{v}");
    // Optimized without the cell, the same part's transits cross the stringer: the check says so.
    let req = json!({"program": "demo-planar-stringer", "iterations": 300});
    let (_, job) = post_json(&app, "/api/jobs/optimize", req).await;
    let v = wait_final(&app, job["id"].as_str().expect("id"), Duration::from_secs(120)).await;
    assert_eq!(v["result"]["safety"], Value::Null);
    let blind = v["result"]["program"].as_str().expect("program").to_string();
    let (_, v) = post_json(&app, &format!("/api/programs/{blind}/check"), json!({"molds": cell})).await;
    assert!(v["safety"]["collision_count"].as_u64().expect("count") > 0, "{v}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_cells_are_refused() {
    let app = app_with("badcell", |_| {});
    let solve = |extra: Value| {
        let mut r = json!({"program": "demo-planar-stringer", "iterations": 10});
        for (k, v) in extra.as_object().expect("object") {
            r[k] = v.clone();
        }
        r
    };
    let cases = [
        (solve(json!({"clearance": 5.0})), "clearance: give the molds"),
        (solve(json!({"molds": ["nothing.stl"]})), "no mesh \"nothing.stl\""),
        (solve(json!({"molds": ["planar-stringer.tool.stl"], "clearance": -1})), "clearance -1"),
        (solve(json!({"molds": ["../x.stl"]})), "mesh"),
    ];
    for (req, want) in cases {
        let (s, v) = post_json(&app, "/api/jobs/optimize", req.clone()).await;
        assert_eq!(s, StatusCode::BAD_REQUEST, "{req}: {v}");
        assert!(v["error"].as_str().is_some_and(|e| e.contains(want)), "{req}: {v}");
    }
    let (s, v) = post_json(&app, "/api/programs/demo-planar-stringer/check", json!({"molds": []})).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    // A mold that is nowhere near the laid path is a wrong set-up, said before anything runs.
    let far = "solid far\nfacet normal 0 0 1\nouter loop\nvertex 5000 5000 900\nvertex 5100 5000 900\nvertex 5000 5100 900\nendloop\nendfacet\nendsolid far\n";
    let (s, v) = send(&app, "POST", "/api/meshes?name=far.stl", "application/octet-stream", far).await;
    assert_eq!(s, StatusCode::CREATED, "{v}");
    let (s, v) = post_json(&app, "/api/programs/demo-planar-stringer/check", json!({"molds": ["far.stl"]})).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
    assert!(v["error"].as_str().is_some_and(|e| e.starts_with("molds: ")), "{v}");
    // A built-in mesh's name cannot be taken by an upload.
    let (s, v) = send(&app, "POST", "/api/meshes?name=planar-stringer.tool.stl", "application/octet-stream", far).await;
    assert_eq!(s, StatusCode::BAD_REQUEST, "{v}");
}
