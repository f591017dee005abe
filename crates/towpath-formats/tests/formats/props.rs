//! Property tests: the readers never panic, JSON round-trips, every matrix layout reads alike.

use std::path::Path;

use proptest::prelude::*;
use towpath_formats::{
    parse_instance, parse_json, parse_json_problem, parse_tour, write_json, JsonEnd, JsonMetric, JsonMode, JsonProblem,
    JsonStates, JsonTask, LoadedProblem, WeightFormat,
};
use towpath_seq::{CostModel, StateId};

use crate::common::data;

/// Small valid files of every kind, to mutate.
const SEEDS: &[&str] = &[
    "burma14.tsp",
    "gr17.tsp",
    "bayg29.tsp",
    "br17.atsp",
    "ESC07.sop",
    "3burma14.gtsp",
    "4br17.gtsp",
    "ESC07.pcglns",
    "ulysses16.opt.tour",
    "example.json",
    "layouts/gr17.upper_diag_col.tsp",
];

/// Tokens that tend to break parsers.
const NASTY: &[&str] = &[
    "-1",
    "0",
    "1",
    "-0",
    "4294967296",
    "99999999999999999999",
    "1e999",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "EOF",
    "\n",
    " ",
    ":",
    "DIMENSION: 0",
    "DIMENSION: 1",
    "DIMENSION: 99999999999",
    "NODE_COORD_SECTION",
    "EDGE_WEIGHT_SECTION",
    "GTSP_SET_SECTION",
    "GTSP_SET_ORDERING",
    "START_GROUP_SECTION",
    "TOUR_SECTION",
    "TYPE: SOP",
    "TYPE: GTSP",
    "EDGE_WEIGHT_FORMAT: UPPER_ROW",
    "{",
    "}",
    "[",
    "]",
    "\"",
    ",",
    "null",
    "\u{feff}",
    "é",
];

fn read(name: &str) -> String {
    std::fs::read_to_string(data(name)).unwrap()
}

/// Parses `text` with every reader; none may panic.
fn parse_all(text: &str) {
    let _ = parse_instance(text, Path::new("fuzz.tsp"));
    let _ = parse_instance(text, Path::new("fuzz.json"));
    let _ = parse_tour(text, Path::new("fuzz.tour"));
    if let Ok(inst) = parse_instance(text, Path::new("fuzz")) {
        // The problem is usable: pricing a route and mapping it back must not panic either.
        let steps: Vec<towpath_seq::Step> =
            (0..inst.num_tasks() as u32).map(|t| towpath_seq::Step { task: towpath_seq::TaskId(t), mode: 0 }).collect();
        let _ = inst.problem.check(&steps);
        let _ = inst.answer(&steps);
    }
}

#[derive(Clone, Debug)]
enum Edit {
    Delete(usize, usize),
    Insert(usize, usize),
    DuplicateLine(usize),
    Truncate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 1..40usize).prop_map(|(a, l)| Edit::Delete(a, l)),
        (any::<usize>(), 0..NASTY.len()).prop_map(|(a, k)| Edit::Insert(a, k)),
        any::<usize>().prop_map(Edit::DuplicateLine),
        any::<usize>().prop_map(Edit::Truncate),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut b: Vec<u8> = text.as_bytes().to_vec();
    for e in edits {
        let len = b.len().max(1);
        match *e {
            Edit::Delete(a, l) => {
                let a = a % len;
                let end = (a + l).min(b.len());
                if a < end {
                    b.drain(a..end);
                }
            }
            Edit::Insert(a, k) => {
                let a = (a % len).min(b.len());
                b.splice(a..a, NASTY[k].bytes());
            }
            Edit::DuplicateLine(a) => {
                let s = String::from_utf8_lossy(&b).into_owned();
                let mut lines: Vec<&str> = s.lines().collect();
                if !lines.is_empty() {
                    let i = a % lines.len();
                    lines.insert(i, lines[i]);
                }
                b = lines.join("\n").into_bytes();
            }
            Edit::Truncate(a) => b.truncate(a % len),
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        parse_all(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn mutated_valid_files_never_panic(seed in 0..SEEDS.len(), edits in proptest::collection::vec(edit(), 1..5)) {
        parse_all(&apply(&read(SEEDS[seed]), &edits));
    }

    #[test]
    fn every_layout_of_a_symmetric_matrix_reads_the_same(
        n in 1usize..8,
        values in proptest::collection::vec(0u32..1000, 64),
        per_line in 1usize..7,
    ) {
        let m = |i: usize, j: usize| if i == j { 0 } else { values[i.min(j) * 8 + i.max(j)] };
        for format in WeightFormat::ALL {
            let nums: Vec<String> = format.positions(n).map(|(i, j)| m(i, j).to_string()).collect();
            let body: Vec<String> = nums.chunks(per_line).map(|c| c.join(" ")).collect();
            let text = format!(
                "NAME : r\nTYPE : TSP\nDIMENSION : {n}\nEDGE_WEIGHT_TYPE : EXPLICIT\nEDGE_WEIGHT_FORMAT : {}\nEDGE_WEIGHT_SECTION\n{}\nEOF\n",
                format.name(),
                body.join("\n")
            );
            let inst = parse_instance(&text, Path::new("r.tsp")).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let LoadedProblem::Matrix(p) = &inst.problem else { return Err(TestCaseError::fail("explicit")) };
            for i in 0..n {
                for j in 0..n {
                    prop_assert_eq!(p.cost_model().cost(StateId(i as u32), StateId(j as u32)), m(i, j) as f64);
                }
            }
        }
    }

    #[test]
    fn full_matrix_keeps_asymmetry(n in 1usize..7, values in proptest::collection::vec(-50i32..1000, 49)) {
        let nums: Vec<String> = (0..n * n).map(|k| values[k].to_string()).collect();
        let text = format!(
            "TYPE: ATSP\nDIMENSION: {n}\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n{}\n",
            nums.join(" ")
        );
        let inst = parse_instance(&text, Path::new("a.atsp")).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let LoadedProblem::Matrix(p) = &inst.problem else { return Err(TestCaseError::fail("explicit")) };
        for i in 0..n {
            for j in 0..n {
                prop_assert_eq!(p.cost_model().cost(StateId(i as u32), StateId(j as u32)), values[i * n + j] as f64);
            }
        }
    }

    #[test]
    fn json_round_trips(problem in json_problem()) {
        let text = write_json(&problem);
        let back = parse_json_problem(&text, Path::new("r.json")).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(&back, &problem);
        // Both validate alike, and an accepted problem prices routes alike.
        let a = problem.to_instance("", Path::new("r.json"));
        let b = parse_json(&text, Path::new("r.json"));
        match (a, b) {
            (Ok(a), Ok(b)) => {
                let steps: Vec<towpath_seq::Step> = (0..a.num_tasks() as u32)
                    .map(|t| towpath_seq::Step { task: towpath_seq::TaskId(t), mode: 0 })
                    .collect();
                prop_assert_eq!(a.problem.check(&steps), b.problem.check(&steps));
                prop_assert_eq!(a.answer(&steps), b.answer(&steps));
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.kind().to_string(), b.kind().to_string()),
            (a, b) => return Err(TestCaseError::fail(format!("{:?} vs {:?}", a.err(), b.err()))),
        }
    }
}

fn json_problem() -> impl Strategy<Value = JsonProblem> {
    let states = (1usize..6).prop_flat_map(|n| {
        prop_oneof![
            (
                proptest::collection::vec(proptest::collection::vec(-1e6f64..1e6, 2..=3), n),
                proptest::option::of(prop_oneof![
                    Just(JsonMetric::Euclidean),
                    Just(JsonMetric::EuclideanNint),
                    Just(JsonMetric::Manhattan),
                    Just(JsonMetric::Geo)
                ])
            )
                .prop_map(|(points, metric)| JsonStates { points: Some(points), metric, matrix: None }),
            proptest::collection::vec(proptest::collection::vec(proptest::option::weighted(0.9, 0.0f64..100.0), n), n)
                .prop_map(|m| JsonStates { points: None, metric: None, matrix: Some(m) }),
        ]
        .prop_map(move |s| (n, s))
    });
    (states, 1usize..6).prop_flat_map(|((n, states), t)| {
        let s = n as u32;
        let mode = (0..s, proptest::option::of(0..s), prop_oneof![Just(0.0), 0.0f64..50.0])
            .prop_map(|(entry, exit, cost)| JsonMode { entry, exit, cost });
        let ids = proptest::collection::hash_set("[a-z0-9 \"\\\\é_-]{1,6}", t);
        (
            ids,
            proptest::collection::vec(proptest::collection::vec(mode, 1..4), t),
            proptest::collection::vec((0..t, 0..t), 0..4),
            proptest::option::of(0..s),
            prop_oneof![Just(JsonEnd::Closed), Just(JsonEnd::Free), (0..s).prop_map(JsonEnd::At)],
            proptest::option::of(0..t),
            proptest::option::of(0..t),
            proptest::option::of("[A-Za-z ]{0,8}"),
            any::<bool>(),
        )
            .prop_map(move |(ids, modes, prec, start, end, first, last, name, group)| {
                let ids: Vec<String> = ids.into_iter().collect();
                let tasks: Vec<JsonTask> =
                    ids.iter().zip(modes).map(|(id, modes)| JsonTask { id: id.clone(), modes }).collect();
                let precedence = prec.iter().map(|&(a, b)| (ids[a].clone(), ids[b].clone())).collect();
                let consecutive =
                    if group && ids.len() >= 2 { vec![vec![ids[0].clone(), ids[1].clone()]] } else { vec![] };
                JsonProblem {
                    name: name.clone(),
                    states: states.clone(),
                    tasks,
                    precedence,
                    consecutive,
                    start,
                    end,
                    first: first.map(|k| ids[k].clone()),
                    last: last.map(|k| ids[k].clone()),
                }
            })
    })
}
