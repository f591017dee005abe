//! `Instance::to_json`: every instance kind written as towpath JSON and read back is the same
//! problem: same tasks, modes, precedence, pins and ends, the same cost for every transition, and
//! the same checker verdict and cost for any route.

use std::path::Path;

use proptest::prelude::*;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use towpath_formats::{parse_json, read_tour, with_problem, write_json, CostsAs, Instance, LoadedProblem};
use towpath_seq::{CostModel, StateId, Step, TaskId};

use crate::common::{data, load, published};

/// One fixture of every kind and cost layout.
const FIXTURES: &[&str] = &[
    "burma14.tsp",   // GEO points
    "att48.tsp",     // ATT points
    "berlin52.tsp",  // EUC_2D points
    "gr17.tsp",      // explicit lower-diagonal matrix
    "br17.atsp",     // explicit asymmetric matrix
    "ESC07.sop",     // precedence from -1 entries, open path pinned at both ends
    "br17.12.sop",   // many precedence rules
    "3burma14.gtsp", // sets over points
    "ESC07.pcglns",  // sets with precedence and a start set
    "ESC25.pcglns",  // a larger PCGLNS file
    "linhp318.tsp",  // a fixed edge: open path with pinned ends
    "example.json",  // multi-mode tasks, consecutive group, start state
];

/// Converts and reads back through the JSON text.
fn round_trip(inst: &Instance, costs: CostsAs) -> Instance {
    let text = write_json(&inst.to_json(costs).unwrap());
    parse_json(&text, Path::new("converted.json")).unwrap_or_else(|e| panic!("{}: {e}\n{text}", inst.name))
}

/// The model's structure, comparable across cost models.
fn structure(inst: &Instance) -> String {
    with_problem!(&inst.problem, p => {
        let tasks: Vec<_> = p
            .tasks()
            .map(|t| (p.modes(t).to_vec(), p.precedence().successors(t).to_vec()))
            .collect();
        format!("{tasks:?} {:?} {:?} {:?} {:?} {:?}", p.groups(), p.start(), p.end(), p.first_task(), p.last_task())
    })
}

fn cost(inst: &Instance, i: u32, j: u32) -> f64 {
    with_problem!(&inst.problem, p => p.cost_model().cost(StateId(i), StateId(j)))
}

/// A random route: a permutation of the tasks (a topological order half of the time, so that
/// precedence instances get feasible routes too), each with a random mode.
fn random_route(inst: &Instance, rng: &mut impl Rng) -> Vec<Step> {
    with_problem!(&inst.problem, p => {
        let order: Vec<TaskId> = if rng.gen_bool(0.5) {
            p.precedence().topological().to_vec()
        } else {
            let mut v: Vec<TaskId> = p.tasks().collect();
            v.shuffle(rng);
            v
        };
        order.iter().map(|&t| Step { task: t, mode: rng.gen_range(0..p.modes(t).len() as u32) }).collect()
    })
}

#[test]
fn every_kind_round_trips_with_the_same_structure_and_costs() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    for file in FIXTURES {
        let original = load(file);
        for costs in [CostsAs::Native, CostsAs::Matrix] {
            let back = round_trip(&original, costs);
            let what = format!("{file} ({costs:?})");
            assert_eq!(back.num_tasks(), original.num_tasks(), "{what}");
            assert_eq!(back.dimension, original.problem.num_states(), "{what}");
            assert_eq!(structure(&back), structure(&original), "{what}");
            if costs == CostsAs::Matrix {
                assert!(matches!(back.problem, LoadedProblem::Matrix(_)), "{what}: a matrix was asked for");
            }
            let n = original.problem.num_states() as u32;
            for i in 0..n {
                for j in 0..n {
                    let (a, b) = (cost(&original, i, j), cost(&back, i, j));
                    assert!(a == b || (a.is_infinite() && b.is_infinite()), "{what}: cost {i}->{j} {a} became {b}");
                }
            }
            for _ in 0..50 {
                let route = random_route(&original, &mut rng);
                assert_eq!(
                    back.problem.check(&route).map_err(|v| v.to_string()),
                    original.problem.check(&route).map_err(|v| v.to_string()),
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn published_optimal_tours_keep_their_cost_after_conversion() {
    for (tour_file, file, kind, expected) in [
        ("berlin52.opt.tour", "berlin52.tsp", "TSP", None),
        ("att48.opt.tour", "att48.tsp", "TSP", None),
        ("bays29.opt.tour", "bays29.tsp", "TSP", None),
        ("ESC25.pcglns.opt.tour", "ESC25.pcglns", "PCGTSP", Some(1383.0)),
    ] {
        let original = load(file);
        let value = expected.unwrap_or_else(|| published(file.split('.').next().unwrap_or(file), kind).0);
        let tour = read_tour(&data(tour_file)).unwrap_or_else(|e| panic!("{e}"));
        let steps = original.steps_from_nodes(&tour.nodes).unwrap();
        assert_eq!(original.problem.check(&steps), Ok(value), "{file}");
        for costs in [CostsAs::Native, CostsAs::Matrix] {
            let back = round_trip(&original, costs);
            // The JSON file names tasks by node number (or set), in the original's order.
            let answer = original.answer(&steps);
            let again = back.steps_from_tasks(&json_route(&back, &original, &answer)).unwrap();
            assert_eq!(back.problem.check(&again), Ok(value), "{file} ({costs:?})");
        }
    }
}

/// The answer of `original` re-expressed as `back`'s task ids (node numbers or set names).
fn json_route(
    back: &Instance,
    original: &Instance,
    answer: &towpath_formats::Answer,
) -> Vec<towpath_formats::TaskStep> {
    let towpath_formats::Answer::Nodes(nodes) = answer else { panic!("TSPLIB answers are node numbers") };
    let steps = original.steps_from_nodes(nodes).unwrap();
    let towpath_formats::Answer::Tasks(route) = back.answer(&steps) else { panic!("JSON answers are task ids") };
    route
}

#[test]
fn task_ids_name_nodes_and_sets() {
    let tsp = load("burma14.tsp").to_json(CostsAs::Native).unwrap();
    assert_eq!(tsp.tasks.first().map(|t| t.id.as_str()), Some("1"));
    assert_eq!(tsp.tasks.last().map(|t| t.id.as_str()), Some("14"));
    assert!(tsp.states.points.is_some() && tsp.states.matrix.is_none());
    let gtsp = load("3burma14.gtsp").to_json(CostsAs::Matrix).unwrap();
    assert_eq!(gtsp.tasks.iter().map(|t| t.id.as_str()).collect::<Vec<_>>(), ["set1", "set2", "set3"]);
    assert_eq!(gtsp.tasks.iter().map(|t| t.modes.len()).sum::<usize>(), 14, "every node is a mode of its set");
    let sop = load("ESC07.sop").to_json(CostsAs::Native).unwrap();
    let rows = sop.states.matrix.as_ref().unwrap();
    // ESC07's row 2 starts with -1: node 1 precedes node 2 and the move 2 -> 1 is forbidden.
    assert_eq!(rows[1][0], None);
    assert!(sop.precedence.contains(&("1".to_string(), "2".to_string())));
    assert_eq!((sop.first.as_deref(), sop.last.as_deref()), (Some("1"), Some("9")));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Random point sets of every metric: the matrix written for them holds exactly the costs
    /// the point model computes.
    #[test]
    fn random_point_instances_keep_their_costs(
        pts in prop::collection::vec((0.0f64..1000.0, 0.0f64..1000.0), 3..20),
        metric in 0usize..4,
    ) {
        let kind = ["EUC_2D", "CEIL_2D", "ATT", "MAN_2D"][metric];
        let mut text = format!("NAME: r\nTYPE: TSP\nDIMENSION: {}\nEDGE_WEIGHT_TYPE: {kind}\nNODE_COORD_SECTION\n", pts.len());
        for (i, (x, y)) in pts.iter().enumerate() {
            text += &format!("{} {x} {y}\n", i + 1);
        }
        let original = towpath_formats::parse_instance(&text, Path::new("r.tsp")).unwrap();
        for costs in [CostsAs::Native, CostsAs::Matrix] {
            let back = round_trip(&original, costs);
            for i in 0..pts.len() as u32 {
                for j in 0..pts.len() as u32 {
                    prop_assert_eq!(cost(&back, i, j), cost(&original, i, j));
                }
            }
        }
    }
}
