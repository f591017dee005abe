//! Reads every instance of the shared benchmark data (`/work/shared/data`, or `$TOWPATH_DATA`),
//! which is not in the repository: run by hand with `cargo test -p towpath-formats --test
//! shared_data -- --ignored --nocapture`.

use std::path::PathBuf;

fn data_dir() -> Option<PathBuf> {
    let d = std::env::var_os("TOWPATH_DATA").map(PathBuf::from).unwrap_or_else(|| PathBuf::from("/work/shared/data"));
    d.join("index.csv").exists().then_some(d)
}

/// Every file of index.csv parses (or is refused with a clear message for a known reason), and
/// every `.opt.tour` next to a TSP file prices at the optimum in index.csv.
#[test]
#[ignore]
fn every_shared_instance_parses_and_optimal_tours_price_right() {
    let Some(dir) = data_dir() else {
        eprintln!("no shared data; skipped");
        return;
    };
    let index = std::fs::read_to_string(dir.join("index.csv")).unwrap();
    let (mut ok, mut refused, mut tours) = (0, 0, 0);
    for row in index.lines().skip(1) {
        let cols = split_csv(row);
        let (name, kind, dim, value, path) = (&cols[0], &cols[1], &cols[2], &cols[3], &cols[5]);
        let file = dir.join(path);
        match towpath_formats::read_instance(&file) {
            Ok(inst) => {
                ok += 1;
                assert_eq!(inst.kind.as_str(), kind.as_str(), "{name}");
                assert_eq!(&inst.dimension.to_string(), dim, "{name}");
                let tour_path = PathBuf::from(file.to_string_lossy().replace(".tsp", ".opt.tour"));
                if tour_path.exists() && file.extension().is_some_and(|e| e == "tsp") {
                    let tour = towpath_formats::read_tour(&tour_path).unwrap();
                    let steps = inst.steps_from_nodes(&tour.nodes).unwrap();
                    let cost = inst.problem.check(&steps).unwrap();
                    println!("{name}: opt tour {cost} (index {value})");
                    assert_eq!(&cost.to_string(), value, "{name}: optimal tour priced wrong");
                    tours += 1;
                }
            }
            Err(e) => {
                refused += 1;
                println!("refused: {e}");
                assert!(e.to_string().contains("GEOM"), "unexpected refusal: {e}");
            }
        }
    }
    println!("{ok} read, {refused} refused, {tours} optimal tours priced");
}

/// MIP-proven optimal PCGTSP tours (one node per set, from the start set) published in
/// ukoloff/PCGTSP-BnB `Salman/output/*.result.txt`, priced by our model of the PCGLNS files.
#[test]
#[ignore]
fn published_pcgtsp_optima_price_exactly() {
    let Some(dir) = data_dir() else {
        eprintln!("no shared data; skipped");
        return;
    };
    let tours: [(&str, f64, &[u32]); 2] = [
        (
            "ESC47",
            1063.0,
            &[
                1, 2, 70, 133, 9, 162, 84, 127, 146, 216, 163, 27, 99, 181, 244, 15, 173, 156, 24, 96, 114, 107, 221,
                41, 125, 119, 183, 68, 74, 111, 224, 179, 199, 189, 30, 57, 130, 53, 194, 169, 231, 34, 90, 48, 144,
                72, 153, 209,
            ],
        ),
        (
            "prob.42",
            202.0,
            &[
                1, 63, 18, 78, 35, 148, 181, 29, 119, 108, 178, 93, 140, 128, 195, 2, 187, 177, 103, 193, 20, 4, 39,
                122, 14, 185, 89, 45, 85, 60, 110, 68, 169, 175, 142, 94, 157, 114, 205, 167, 191,
            ],
        ),
    ];
    for (name, cost, nodes) in tours {
        let inst = towpath_formats::read_instance(&dir.join(format!("pcgtsp/{name}.pcglns"))).unwrap();
        let steps = inst.steps_from_nodes(nodes).unwrap();
        assert_eq!(inst.problem.check(&steps).unwrap(), cost, "{name}");
        println!("{name}: published optimal tour priced {cost}");
    }
}

/// Splits one CSV row, honouring double quotes.
fn split_csv(row: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    for c in row.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    out
}
