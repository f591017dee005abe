//! The cases: for each command, an argument vector drawn from its flags (sane, boundary and
//! nonsense values) and input files mutated from the corpus, written into the case's folder.

use std::path::{Path, PathBuf};

use crate::exec::Case;
use crate::mutate::{mutate, NUMBERS};
use crate::rng::Rng;

/// A file of the corpus: its name (the extension matters to the readers) and its bytes.
#[derive(Clone)]
pub struct Seed {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// Example inputs of every kind, from the repository's test data and from the binary itself.
#[derive(Default)]
pub struct Corpus {
    /// Sequencing problems (TSPLIB, GTSP, SOP, PCGLNS, JSON) and tours.
    pub problems: Vec<Seed>,
    /// Travel graphs with required edges.
    pub graphs: Vec<Seed>,
    /// AFP programs, originals and optimized.
    pub programs: Vec<Seed>,
    /// Machine files.
    pub machines: Vec<Seed>,
    /// Dialect files.
    pub dialects: Vec<Seed>,
    /// Meshes (STL, OBJ, PLY).
    pub meshes: Vec<Seed>,
}

/// The commands fuzzed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Solve,
    Convert,
    Route,
    Layup,
    Optimize,
    Verify,
}

impl Target {
    pub const ALL: [Target; 6] =
        [Target::Solve, Target::Convert, Target::Route, Target::Layup, Target::Optimize, Target::Verify];

    pub fn name(self) -> &'static str {
        match self {
            Target::Solve => "solve",
            Target::Convert => "convert",
            Target::Route => "route",
            Target::Layup => "layup",
            Target::Optimize => "optimize",
            Target::Verify => "verify",
        }
    }
}

/// Builds a case's argument vector and files.
struct Builder<'a> {
    rng: &'a mut Rng,
    dir: PathBuf,
    argv: Vec<String>,
    inputs: Vec<PathBuf>,
    /// Only sane flag values and fresh output paths in this case (the files may still be
    /// mutated), so that a fair share of the cases get past the argument checks to the work.
    sane: bool,
}

impl Builder<'_> {
    fn arg(&mut self, a: impl Into<String>) {
        self.argv.push(a.into());
    }

    /// A flag and its value, as `--flag value` or `--flag=value` (always the latter for a
    /// value that starts with `-`, which the parser would otherwise take for a flag).
    fn flag(&mut self, name: &str, value: String) {
        if name.starts_with("--") && (value.starts_with('-') || self.rng.chance(0.3)) {
            self.argv.push(format!("{name}={value}"));
        } else {
            self.argv.push(name.to_string());
            self.argv.push(value);
        }
    }

    fn maybe(&mut self, p: f64) -> bool {
        self.rng.chance(p)
    }

    fn pick(&mut self, values: &[&str]) -> String {
        self.rng.pick(values).copied().unwrap_or("").to_string()
    }

    /// A value of `values`, of its first `sane` ones in a sane case.
    fn choose(&mut self, sane: usize, values: &[&str]) -> String {
        let values = if self.sane { &values[..sane.min(values.len())] } else { values };
        self.pick(values)
    }

    /// Writes an input: a seed of `pool`, mutated most of the time, under its own name (or now
    /// and then another extension). Returns the name.
    fn input(&mut self, pool: &[Seed], fallback: &str) -> String {
        self.input_mutated(pool, fallback, 0.8)
    }

    /// [`Builder::input`], mutated with probability `p` (commands that read several files
    /// mutate one at a time, so that most cases get past the readers to the work).
    fn input_mutated(&mut self, pool: &[Seed], fallback: &str, p: f64) -> String {
        let (name, bytes) = match self.rng.pick(pool) {
            Some(seed) => {
                let other = self.rng.pick(pool).map_or(&[][..], |s| &s.bytes[..]);
                let bytes = if self.rng.chance(p) { mutate(self.rng, &seed.bytes, other) } else { seed.bytes.clone() };
                (seed.name.clone(), bytes)
            }
            None => (fallback.to_string(), Vec::new()),
        };
        let name = if self.rng.chance(0.05) {
            let ext =
                self.rng.pick(&[".json", ".tsp", ".nc", ".stl", ".ply", ".obj", ".txt", ""]).copied().unwrap_or("");
            format!("{}{ext}", name.split('.').next().unwrap_or("in"))
        } else {
            name
        };
        let path = self.dir.join(&name);
        if std::fs::write(&path, bytes).is_ok() && !self.inputs.contains(&path) {
            self.inputs.push(path);
        }
        name
    }

    /// An output path: fresh most of the time, else one that must be refused or handled (the
    /// input itself, links to it, a folder, a folder that is a file, a missing folder, a place
    /// nobody may write).
    fn output(&mut self, input: &str, ext: &str) -> String {
        let k = if self.sane { 23 } else { self.rng.range(0, 24) };
        match k {
            0 => input.to_string(),
            1 => "hard-link".into(),
            2 => "soft-link".into(),
            3 => ".".into(),
            4 => "folder".into(),
            5 => "a-file/out".into(),
            6 => format!("new/deeper/out{ext}"),
            7 => "/proc/towpath-fuzz-out".into(),
            8 => String::new(),
            _ => format!("out{}{ext}", self.rng.range(0, 3)),
        }
    }

    /// Files every case has: a folder, a file, and links to the first input.
    fn furniture(&mut self) {
        let _ = std::fs::create_dir_all(self.dir.join("folder"));
        let file = self.dir.join("a-file");
        let _ = std::fs::write(&file, "not a folder");
        self.inputs.push(file);
        if let Some(first) = self.inputs.first().cloned() {
            let _ = std::fs::hard_link(&first, self.dir.join("hard-link"));
            let _ = std::os::unix::fs::symlink(&first, self.dir.join("soft-link"));
        }
    }

    fn number(&mut self, sane: &[&str]) -> String {
        if self.sane || self.rng.chance(0.7) {
            self.pick(sane)
        } else {
            self.pick(NUMBERS)
        }
    }

    /// The flags of `--solver` and the baselines' parameters. `bounded`: a short time limit
    /// stops the run whatever the parameters ask; otherwise they stay small (a user asking for
    /// a billion generations without a time limit gets them).
    fn solver_flags(&mut self, bounded: bool) {
        if self.maybe(0.4) {
            let s = self.choose(6, &["towpath", "doherty", "castelino", "ga", "aco1", "aco2", "aco", "lkh", ""]);
            self.flag("--solver", s);
        }
        let big: &[&str] = &["1", "2", "100", "0", "4000000000", "18446744073709551615", "-1", "x"];
        let small: &[&str] = &["1", "2", "3", "10", "0", "-1", "x"];
        for f in ["--ga-population", "--ga-generations", "--aco-cycles", "--doherty-n", "--doherty-max-iterations"] {
            if self.maybe(0.15) {
                let v = if bounded || f == "--ga-population" { self.choose(3, big) } else { self.choose(4, small) };
                self.flag(f, v);
            }
        }
    }

    fn threads(&mut self) {
        if self.maybe(0.3) {
            let t = self.choose(2, &["1", "2", "0", "3", "1025", "100000", "-1"]);
            self.flag("--threads", t);
        }
    }

    fn finish(self, close_stdout: bool) -> Case {
        Case { dir: self.dir, argv: self.argv, inputs: self.inputs, close_stdout }
    }
}

/// Short time limits (and nonsense ones).
const SHORT: &[&str] = &["0.01", "0.05", "0.1", "0.2", "0", "-1", "nan", "inf", "1e-300", "x"];

/// Makes a case of `target` in `dir` (an empty folder).
pub fn make(target: Target, rng: &mut Rng, corpus: &Corpus, dir: &Path) -> Case {
    let close_stdout = rng.chance(0.1);
    let sane = rng.chance(0.5);
    let mut b = Builder { rng, dir: dir.to_path_buf(), argv: Vec::new(), inputs: Vec::new(), sane };
    match target {
        Target::Solve => {
            b.arg("solve");
            let file = b.input(&corpus.problems, "problem.tsp");
            b.furniture();
            b.arg(file);
            let bounded = match b.rng.range(0, 3) {
                0 => {
                    let t = b.choose(4, SHORT);
                    b.flag("--time-limit", t);
                    true
                }
                1 => {
                    let n = b.pick(&["0", "1", "10", "100", "500"]);
                    b.flag("--iterations", n);
                    false
                }
                _ => {
                    let t = b.number(&["0.05", "0.2", "1e300", "1e19"]);
                    let n = b.pick(&["0", "1", "10", "100"]);
                    b.flag("--time-limit", t);
                    b.flag("--iterations", n);
                    false
                }
            };
            if b.maybe(0.3) {
                let s = b.choose(4, &["0", "1", "7", "18446744073709551615", "-1"]);
                b.flag("--seed", s);
            }
            b.threads();
            if b.maybe(0.5) {
                b.arg("--json");
            }
            b.solver_flags(bounded);
        }
        Target::Convert => {
            b.arg("convert");
            let file = b.input(&corpus.problems, "problem.tsp");
            b.furniture();
            b.arg(file.clone());
            if b.maybe(0.4) {
                b.arg("--matrix");
            }
            if b.maybe(0.1) {
                let to = b.choose(1, &["json", "xml", ""]);
                b.flag("--to", to);
            }
            if b.maybe(0.6) {
                let out = b.output(&file, ".json");
                b.flag("-o", out);
            }
        }
        Target::Route => {
            b.arg("route");
            let graph = if b.maybe(0.7) {
                let g = b.input(&corpus.graphs, "graph.json");
                b.arg(g.clone());
                g
            } else {
                let r = b.number(&["1", "2", "5", "10", "40", "300", "5001", "4294967296", "0", "-1"]);
                b.flag("--generate", r);
                if b.maybe(0.3) {
                    let s = b.pick(&["0", "1", "2", "18446744073709551615"]);
                    b.flag("--generate-seed", s);
                }
                "generated.json".into()
            };
            b.furniture();
            // The whole command honours its time limit, so every limit given is a short one.
            let t = b.choose(4, SHORT);
            b.flag("--time-limit", t);
            b.threads();
            if b.maybe(0.3) {
                b.arg("--json");
            }
            if b.maybe(0.4) {
                let out = b.output(&graph, ".json");
                b.flag("-o", out);
            }
            if b.maybe(0.3) {
                let out = b.output(&graph, ".json");
                b.flag("--save-instance", out);
            }
            b.solver_flags(true);
        }
        Target::Layup => {
            b.arg("layup");
            let surface = if b.maybe(0.5) {
                b.input(&corpus.meshes, "mesh.stl")
            } else {
                b.pick(&[
                    "plane:a=200,b=100",
                    "plane:a=100,b=100",
                    "cylinder:r=100,l=200",
                    "cone:r0=100,r1=50,l=200",
                    "sphere:r=100",
                    "plane:a=200,a=100",
                    "plane:a=1e300,b=1",
                    "cylinder:r=0.0001,l=1",
                    "torus:r=1",
                    "",
                ])
            };
            b.furniture();
            b.arg(surface.clone());
            let angle = b.number(&["0", "30", "45", "90", "-45"]);
            let width = b.number(&["6.35", "12.7", "25"]);
            let tows = b.number(&["1", "2", "4", "8"]);
            b.flag("--angle", angle);
            b.flag("--tow-width", width);
            b.flag("--tows", tows);
            let out = b.output(&surface, ".json");
            b.flag("-o", out);
            for (f, ext) in [("--gcode", ".nc"), ("--csv", ".csv"), ("--write-mesh", ".stl")] {
                if b.maybe(0.15) {
                    let o = b.output(&surface, ext);
                    b.flag(f, o);
                }
            }
            for (f, sane) in [
                ("--coverage", &["50", "0", "100"][..]),
                ("--min-steering-radius", &["500", "0", "-1"][..]),
                ("--l-seg", &["20", "5", "0"][..]),
                ("--weld-tolerance", &["0.001", "0", "-1"][..]),
                ("--triangles", &["2", "100", "0"][..]),
                ("--ply-number", &["1", "0", "2"][..]),
            ] {
                if b.maybe(0.1) {
                    let v = b.number(sane);
                    b.flag(f, v);
                }
            }
            if b.maybe(0.1) {
                let v = b.choose(1, &["0,0,0", "1e308,0,0", "1,2", "x"]);
                b.flag("--start", v);
            }
            if b.maybe(0.2) {
                b.arg("--json");
            }
        }
        Target::Optimize | Target::Verify => {
            // One file mutated (the program half the time), or none, so that most cases get
            // past the readers to the sequencing and the verification.
            let which = b.rng.range(0, 6);
            let p = |mutated: bool| if mutated { 1.0 } else { 0.0 };
            let original = b.input_mutated(&corpus.programs, "part.nc", p(which < 3));
            // The machine the program was written for, most of the time (the demo's mandrel
            // parts are the cylinders).
            let mandrel = original.contains("cylinder") || original.contains("mandrel");
            let matching: Vec<Seed> =
                corpus.machines.iter().filter(|m| m.name.contains("mandrel") == mandrel).cloned().collect();
            let pool = if b.maybe(0.9) && !matching.is_empty() { &matching[..] } else { &corpus.machines[..] };
            let machine = b.input_mutated(pool, "machine.toml", p(which == 3));
            let dialect = if b.maybe(0.8) {
                Some(b.input_mutated(&corpus.dialects, "dialect.toml", p(which == 4)))
            } else {
                None
            };
            b.furniture();
            if target == Target::Optimize {
                b.arg("optimize");
                b.arg(original.clone());
                let out = b.output(&original, ".nc");
                b.flag("-o", out);
                if b.maybe(0.5) {
                    let t = b.choose(4, SHORT);
                    b.flag("--time-limit", t);
                } else {
                    let n = b.pick(&["0", "1", "50", "200"]);
                    b.flag("--iterations", n);
                }
                if b.maybe(0.2) {
                    let r = b.output(&original, ".json");
                    b.flag("--report", r);
                }
                for f in ["--bidirectional", "--keep-ply-order"] {
                    if b.maybe(0.2) {
                        b.arg(f);
                    }
                }
                if b.maybe(0.2) {
                    let c = b.choose(3, &["axis", "time", "tool", "x"]);
                    b.flag("--cost", c);
                }
                b.threads();
                b.solver_flags(false);
            } else {
                b.arg("verify");
                let optimized = b.input_mutated(&corpus.programs, "part.opt.nc", 0.6);
                b.arg(original);
                b.arg(optimized);
                for f in ["--strict-plies", "--keep-ply-order"] {
                    if b.maybe(0.2) {
                        b.arg(f);
                    }
                }
            }
            b.flag("--machine", machine);
            if let Some(d) = dialect {
                b.flag("--dialect", d);
            }
            if b.maybe(0.3) {
                let w = b.number(&["6.35", "3.175"]);
                let f = b.pick(&["--tow-width", "--course-width"]);
                b.flag(&f, w);
            }
            if b.maybe(0.2) {
                let p = b.choose(3, &["courses", "sets", "plies", "x"]);
                b.flag("--precedence", p);
            }
            if b.maybe(0.3) {
                b.arg("--json");
            }
        }
    }
    // Now and then an unknown flag, a flag given twice or an empty argument.
    if !b.sane && b.maybe(0.03) {
        let junk = b.pick(&["--bogus", "", "-", "--json", "--", "-o"]);
        let k = b.rng.range(1, b.argv.len() + 1);
        b.argv.insert(k, junk);
    }
    b.finish(close_stdout)
}
