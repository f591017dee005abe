//! The fuzz targets of `fuzz/bodies/` on the stable toolchain. cargo-fuzz (coverage-guided,
//! nightly) runs them from `fuzz/fuzz_targets/`; here each body runs on its seed inputs and on
//! inputs mutated from them (byte edits, numbers replaced by boundary values, lines spliced in:
//! the mutators of the command-line fuzzer, `fuzz/cli/src/mutate.rs`), with a fixed seed and a
//! bounded number of cases, so `cargo test` keeps every target passing. A finding is written to
//! `target/fuzz-findings/` and fails the test.
//!
//! `FUZZ_CASES` (default 300 per target) and `FUZZ_SEED` (default 1) change the run; see
//! `fuzz/README.md` for longer runs.

#![allow(dead_code)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

#[path = "../../../fuzz/cli/src/mutate.rs"]
mod mutate;
#[path = "../../../fuzz/cli/src/rng.rs"]
mod rng;

#[path = "../../../fuzz/bodies/afp_config.rs"]
mod afp_config;
#[path = "../../../fuzz/bodies/afp_program.rs"]
mod afp_program;
#[path = "../../../fuzz/bodies/convert.rs"]
mod convert;
#[path = "../../../fuzz/bodies/json.rs"]
mod json;
#[path = "../../../fuzz/bodies/layup_inputs.rs"]
mod layup_inputs;
#[path = "../../../fuzz/bodies/mesh_obj.rs"]
mod mesh_obj;
#[path = "../../../fuzz/bodies/mesh_ply.rs"]
mod mesh_ply;
#[path = "../../../fuzz/bodies/mesh_stl.rs"]
mod mesh_stl;
#[path = "../../../fuzz/bodies/rpp_json.rs"]
mod rpp_json;
#[path = "../../../fuzz/bodies/tsplib.rs"]
mod tsplib;

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Runs `body` on every seed and on `FUZZ_CASES` mutated inputs; fails on the first panic,
/// keeping the input.
fn fuzz(name: &str, seeds: &[Vec<u8>], body: fn(&[u8])) {
    assert!(!seeds.is_empty(), "{name}: no seed inputs");
    let cases = env_number("FUZZ_CASES", 300);
    let mut rng =
        rng::Rng::new(env_number("FUZZ_SEED", 1) ^ name.bytes().fold(0u64, |h, b| h.wrapping_mul(31) ^ b as u64));
    let inputs = seeds.iter().cloned().chain((0..cases).map(|_| {
        let seed = rng.pick(seeds).cloned().unwrap_or_default();
        let other = rng.pick(seeds).cloned().unwrap_or_default();
        mutate::mutate(&mut rng, &seed, &other)
    }));
    for (i, input) in inputs.enumerate() {
        if let Err(panic) = catch_unwind(AssertUnwindSafe(|| body(&input))) {
            let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-findings");
            let _ = std::fs::create_dir_all(&dir);
            let file = dir.join(format!("{name}-{i}"));
            let _ = std::fs::write(&file, &input);
            let msg =
                panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()));
            panic!("{name}: case {i} panicked ({}); input kept in {}", msg.unwrap_or_default(), file.display());
        }
    }
}

fn files(dir: &Path, exts: &[&str]) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> =
        std::fs::read_dir(dir).map(|d| d.flatten().map(|e| e.path()).collect()).unwrap_or_default();
    paths.retain(|p| p.extension().is_some_and(|e| exts.iter().any(|x| e == *x)));
    paths.sort();
    paths.iter().filter_map(|p| std::fs::read(p).ok()).filter(|b| b.len() <= 200_000).collect()
}

fn problems(exts: &[&str]) -> Vec<Vec<u8>> {
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../towpath-formats/tests/data");
    let mut v = files(&data, exts);
    v.extend(files(&data.join("layouts"), exts));
    v
}

/// A unit square as two triangles, in a mesh format.
fn square(format: towpath_geom::io::Format) -> Vec<u8> {
    use towpath_geom::DVec3;
    let soup = towpath_geom::Soup {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    towpath_geom::io::write_bytes(&soup, format).unwrap()
}

#[test]
fn problem_readers() {
    fuzz("tsplib", &problems(&["tsp", "atsp", "sop", "gtsp", "pcglns", "tour"]), tsplib::run);
    fuzz("json", &problems(&["json"]), json::run);
    fuzz("convert", &problems(&["tsp", "atsp", "sop", "gtsp", "pcglns", "json"]), convert::run);
}

#[test]
fn mesh_readers() {
    use towpath_geom::io::Format;
    let ascii = b"solid s\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n\
endfacet\nendsolid s\n"
        .to_vec();
    fuzz("mesh_stl", &[square(Format::Stl), ascii], mesh_stl::run);
    fuzz("mesh_obj", &[square(Format::Obj)], mesh_obj::run);
    fuzz("mesh_ply", &[square(Format::Ply)], mesh_ply::run);
}

#[test]
fn travel_graphs() {
    let mut seeds = files(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures"), &["json"]);
    seeds.push(towpath_coverage::write_instance(&towpath_coverage::tewolde_sheng_like(5, 1).unwrap()).into_bytes());
    fuzz("rpp_json", &seeds, rpp_json::run);
}

#[test]
fn layup_inputs() {
    let nurbs = towpath_geom::surface::Nurbs::clamped(
        1,
        1,
        &[
            vec![towpath_geom::DVec3::ZERO, towpath_geom::DVec3::Y],
            vec![towpath_geom::DVec3::X, towpath_geom::DVec3::new(1.0, 1.0, 0.5)],
        ],
    )
    .unwrap();
    let seeds: Vec<Vec<u8>> = [
        "plane:a=200,b=100".to_string(),
        "cylinder:r=300,l=1000".into(),
        "cone:r0=300,r1=150,l=600".into(),
        "sphere:r=500".into(),
        "x,y,z\n0,0,0\n10,0,0\n20,5,0\n".into(),
        "0,0,0,1,0,0\n10,0,0,1,1,0\n".into(),
        serde_json::to_string(&nurbs).unwrap(),
    ]
    .into_iter()
    .map(String::into_bytes)
    .collect();
    fuzz("layup_inputs", &seeds, layup_inputs::run);
}

#[test]
fn afp_inputs() {
    let parts = towpath_nc::demo::demo_parts();
    let programs: Vec<Vec<u8>> = parts.iter().map(|p| p.program.clone().into_bytes()).collect();
    fuzz("afp_program", &programs, afp_program::run);
    let configs = vec![
        towpath_nc::demo::gantry().to_toml_string().into_bytes(),
        towpath_nc::demo::mandrel_machine().to_toml_string().into_bytes(),
        towpath_nc::Dialect::default().to_toml_string().into_bytes(),
    ];
    fuzz("afp_config", &configs, afp_config::run);
}
