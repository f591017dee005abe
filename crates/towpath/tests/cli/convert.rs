//! `towpath convert` end to end: a converted file solves to answers that price the same in the
//! original file.

use super::common::*;

use towpath_formats::read_instance;

/// Converts `file`, solves the JSON with a fixed budget, and prices the answer in the original
/// file: the cost the solver reports for the JSON must be the original's cost of that route.
fn converted_answer_prices_the_same(file: &str, matrix: bool) {
    let dir = scratch(&format!("{}-{matrix}", file.replace('.', "_")));
    let json = dir.join("problem.json");
    let input = data(file);
    let mut args = vec!["convert", input.to_str().unwrap(), "--to", "json", "-o", json.to_str().unwrap()];
    if matrix {
        args.push("--matrix");
    }
    let out = towpath_out(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&json).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["states"]["matrix"].is_array(), matrix || !v["states"]["points"].is_array());

    let out = towpath_out(&["solve", json.to_str().unwrap(), "--json", "--iterations", "300", "--threads", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let answer: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let original = read_instance(&input).unwrap();
    let steps = match original.kind {
        towpath_formats::Kind::Gtsp | towpath_formats::Kind::Pcgtsp => {
            // A set's mode is one of its nodes: the mode's entry state is the node number - 1.
            let nodes: Vec<u32> = answer["tour"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| {
                    let set: usize = s["task"].as_str().unwrap().trim_start_matches("set").parse().unwrap();
                    let mode = s["mode"].as_u64().unwrap() as usize;
                    v["tasks"][set - 1]["modes"][mode]["entry"].as_u64().unwrap() as u32 + 1
                })
                .collect();
            original.steps_from_nodes(&nodes).unwrap()
        }
        _ => {
            let nodes: Vec<u32> = answer["tour"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s["task"].as_str().unwrap().parse().unwrap())
                .collect();
            original.steps_from_nodes(&nodes).unwrap()
        }
    };
    let reported = answer["cost"].as_f64().unwrap();
    assert_eq!(original.problem.check(&steps), Ok(reported), "{file} (matrix: {matrix})");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn converted_tsp_answers_price_the_same_in_the_original() {
    converted_answer_prices_the_same("berlin52.tsp", false);
    converted_answer_prices_the_same("berlin52.tsp", true);
}

#[test]
fn converted_sop_gtsp_and_pcglns_answers_price_the_same_in_the_original() {
    converted_answer_prices_the_same("br17.12.sop", false);
    converted_answer_prices_the_same("11berlin52.gtsp", true);
    converted_answer_prices_the_same("ESC07.pcglns", false);
}

#[test]
fn stdout_output_is_one_json_problem() {
    let input = data("br17.atsp");
    let out = towpath_out(&["convert", input.to_str().unwrap()]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["name"], "br17");
    assert_eq!(v["tasks"].as_array().unwrap().len(), 17);
    assert_eq!(v["states"]["matrix"].as_array().unwrap().len(), 17);
}

#[test]
fn refuses_to_overwrite_the_input_and_bad_files() {
    let dir = scratch("refuse");
    let copy = dir.join("burma14.tsp");
    std::fs::copy(data("burma14.tsp"), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    let out = towpath_out(&["convert", copy.to_str().unwrap(), "-o", copy.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("would overwrite the input"));
    assert_eq!(std::fs::read(&copy).unwrap(), before, "the input is untouched");

    let bad = dir.join("bad.tsp");
    std::fs::write(&bad, "NAME: bad\nTYPE: TSP\nDIMENSION: 2\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 x\n")
        .unwrap();
    let out = towpath_out(&["convert", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.tsp:6"), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stdout.is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_matrix_too_large_to_write_and_distances_too_large_to_add_are_refused() {
    // 5001 points: 25,010,001 costs as a matrix, more than is written (points are fine).
    let mut text =
        String::from("NAME: big\nTYPE: TSP\nDIMENSION: 5001\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n");
    for i in 1..=5001 {
        text.push_str(&format!("{i} {} {}\n", i % 71, i / 71));
    }
    let path = scratch_file("big5001.tsp");
    std::fs::write(&path, &text).unwrap();
    let (code, _, err) = run(towpath().arg("convert").arg(&path).arg("--matrix"));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("5001 × 5001") && err.contains("too large"), "{err}");
    let (code, out, err) = run(towpath().arg("convert").arg(&path));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"points\""));
    // "9.223372036854776e+18 everywhere" before: refused at reading now.
    let far = scratch_file("far-convert.tsp");
    std::fs::write(
        &far,
        "NAME: far\nTYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n2 3e19 0\n3 1e19 0\n",
    )
    .unwrap();
    let (code, out, err) = run(towpath().arg("convert").arg(&far).arg("--matrix"));
    assert_eq!(code, 2, "{err}");
    assert!(!out.contains("9.223372036854776e18") && err.contains("apart"), "{err}");
}
