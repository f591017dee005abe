//! `towpath serve`: starts on loopback with a workspace, answers its API, refuses bad options.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::Stdio;

use crate::common::{run, scratch, towpath};

#[test]
fn serve_listens_on_loopback_and_keeps_its_workspace() {
    let dir = scratch("serve");
    let ws = dir.join("ws");
    let mut child = towpath()
        .args(["serve", "--port", "0", "--workspace"])
        .arg(&ws)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    let mut first = String::new();
    BufReader::new(child.stdout.take().expect("stdout")).read_line(&mut first).expect("line");
    let addr = first.trim().strip_prefix("towpath serve: http://").and_then(|s| s.strip_suffix('/'));
    let addr = addr.unwrap_or_else(|| panic!("unexpected first line {first:?}")).to_string();
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");
    let mut s = TcpStream::connect(&addr).expect("connect");
    write!(s, "GET /api/status HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").expect("write");
    let mut reply = String::new();
    s.read_to_string(&mut reply).expect("read");
    let _ = child.kill();
    let _ = child.wait();
    assert!(reply.starts_with("HTTP/1.1 200"), "{reply}");
    assert!(reply.contains("\"panel\":\"panel-10000-courses\""), "{reply}");
    for sub in ["machines", "dialects", "programs", "meshes", "results"] {
        assert!(ws.join(sub).is_dir(), "{sub}");
    }
}

#[test]
fn serve_refuses_bad_options() {
    let (code, _, err) = run(towpath().args(["serve", "--jobs", "0"]));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--jobs"), "{err}");
    let (code, _, err) = run(towpath().args(["serve", "--host", "not-an-address", "--port", "0"]));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot serve on not-an-address"), "{err}");
}
