//! The ordering against independent checks: brute force over every order and entry on small
//! drawings, analytic entry points, nesting, and the verifier on every answer.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use towpath_cut::geom::{dist, Path, P2};
use towpath_cut::verify::Rules;
use towpath_cut::{order, verify, Drawing, EntryMode, OrderOptions, Piece, Placement};
use towpath_seq::SolveOptions;

fn square(c: P2, h: f64) -> Path {
    Path::polyline(&[[c[0] - h, c[1] - h], [c[0] + h, c[1] - h], [c[0] + h, c[1] + h], [c[0] - h, c[1] + h]], true)
        .unwrap()
}

fn piece(id: &str, path: Path) -> Piece {
    Piece { id: id.into(), operation: 0, path, reversible: true, fixed: false }
}

fn opts() -> OrderOptions {
    OrderOptions {
        solve: SolveOptions { time_limit: None, iterations: Some(150), threads: 1, ..SolveOptions::default() },
        ..OrderOptions::default()
    }
}

fn rules(o: &OrderOptions) -> Rules {
    Rules {
        inner_first: o.inner_first,
        mix_operations: o.mix_operations,
        reverse: o.reverse,
        tolerance: o.tolerance,
        start: o.start,
    }
}

fn drawing(pieces: Vec<Piece>) -> Drawing {
    Drawing { operations: vec!["cut".into()], pieces, hierarchy: vec![] }
}

#[test]
fn nested_squares_come_inner_first() {
    // Listed outermost first; the start is next to the outer square.
    let pieces = (0..5).map(|k| piece(&format!("s{k}"), square([0.0, 0.0], 50.0 - 10.0 * k as f64))).collect();
    let d = drawing(pieces);
    let o = OrderOptions { start: Some([-60.0, -60.0]), ..opts() };
    let r = order(&d, &o).unwrap();
    let ids: Vec<&str> = r.placements.iter().map(|p| d.pieces[p.piece].id.as_str()).collect();
    assert_eq!(ids, ["s4", "s3", "s2", "s1", "s0"]);
    let v = verify(&d, &r.placements, &rules(&o));
    assert!(v.ok(), "{}", v.problems());
    // Without inner-first the nearest (outer) square may come first, and the verifier then
    // finds the containment broken when asked to check it.
    let o2 = OrderOptions { inner_first: false, ..o.clone() };
    let r2 = order(&d, &o2).unwrap();
    assert_eq!(d.pieces[r2.placements[0].piece].id, "s0");
    assert!(!verify(&d, &r2.placements, &rules(&o)).ok());
}

/// Every order and every direction of a few open strokes: the least travel from the start.
fn brute_force(start: P2, strokes: &[(P2, P2)]) -> f64 {
    fn rec(at: P2, left: &mut Vec<(P2, P2)>, acc: f64, best: &mut f64) {
        if acc >= *best {
            return;
        }
        if left.is_empty() {
            *best = acc;
            return;
        }
        for i in 0..left.len() {
            let s = left.remove(i);
            rec(s.1, left, acc + dist(at, s.0), best);
            rec(s.0, left, acc + dist(at, s.1), best);
            left.insert(i, s);
        }
    }
    let mut best = f64::INFINITY;
    rec(start, &mut strokes.to_vec(), 0.0, &mut best);
    best
}

#[test]
fn strokes_match_brute_force() {
    let mut rng = Pcg64::seed_from_u64(7);
    for _case in 0..20 {
        let n = rng.gen_range(2..=7);
        let strokes: Vec<(P2, P2)> = (0..n)
            .map(|_| {
                (
                    [rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0)],
                    [rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0)],
                )
            })
            .collect();
        let d = drawing(
            strokes
                .iter()
                .enumerate()
                .map(|(i, s)| piece(&format!("p{i}"), Path::polyline(&[s.0, s.1], false).unwrap()))
                .collect(),
        );
        let o = opts();
        let r = order(&d, &o).unwrap();
        let best = brute_force([0.0, 0.0], &strokes);
        assert!((r.travel_after - best).abs() < 1e-6, "{} vs brute force {best}", r.travel_after);
        let v = verify(&d, &r.placements, &rules(&o));
        assert!(v.ok(), "{}", v.problems());
        assert!((v.travel - r.travel_after).abs() < 1e-9);
    }
}

#[test]
fn refined_entry_reaches_the_analytic_optimum() {
    // From (0, 5) to a square [10, 20]², then on to (30, 5): the best entry on the left side
    // (a closed contour is left where it was entered) is where |(0,5)-e| + |e-(30,5)| is least:
    // on the bottom side at y = 10 it is the point x = 15 (by symmetry), cost 2·hypot(15, 5).
    let sq = Path::polyline(&[[10.0, 10.0], [20.0, 10.0], [20.0, 20.0], [10.0, 20.0]], true).unwrap();
    let end = Path::polyline(&[[30.0, 5.0], [40.0, 5.0]], false).unwrap();
    let mut d = drawing(vec![piece("sq", sq), piece("end", end)]);
    d.hierarchy.push((0, 1));
    let o = OrderOptions { start: Some([0.0, 5.0]), reverse: false, ..opts() };
    let r = order(&d, &o).unwrap();
    let e = r.placements[0].path.start;
    assert!(dist(e, [15.0, 10.0]) < 1e-4, "entry {e:?}");
    assert!((r.travel_after - 2.0 * 15f64.hypot(5.0)).abs() < 1e-6, "{}", r.travel_after);
    assert!(r.travel_after <= r.travel_solved + 1e-12);
    // Vertex entries only: the best vertex is a corner of the bottom side.
    let r2 = order(&d, &OrderOptions { entry: EntryMode::Vertex, ..o.clone() }).unwrap();
    let corner = 10f64.hypot(5.0) + 10.0f64.hypot(5.0).max(20f64.hypot(5.0)); // (10,10): 10√… to (30,5)
    let at_10 = 10f64.hypot(5.0) + 20f64.hypot(5.0);
    let at_20 = 20f64.hypot(5.0) + 10f64.hypot(5.0);
    let _ = corner;
    assert!((r2.travel_after - at_10.min(at_20)).abs() < 1e-9, "{}", r2.travel_after);
}

fn random_drawing(seed: u64, n: usize) -> Drawing {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut pieces = Vec::new();
    for i in 0..n {
        let c = [rng.gen_range(0.0..200.0), rng.gen_range(0.0..200.0)];
        match i % 3 {
            0 => {
                // A part with a hole.
                pieces.push(piece(&format!("outer{i}"), square(c, 8.0)));
                pieces.push(piece(&format!("hole{i}"), square(c, 3.0).reversed()));
            }
            1 => pieces.push(piece(
                &format!("stroke{i}"),
                Path::polyline(&[c, [c[0] + 5.0, c[1] + 3.0], [c[0] + 9.0, c[1]]], false).unwrap(),
            )),
            _ => {
                let mut p = Path::polyline(&[c, [c[0] + 6.0, c[1]]], false).unwrap();
                p.segs[0] = towpath_cut::Seg::Arc { to: [c[0] + 6.0, c[1]], bulge: 0.6 };
                pieces.push(piece(&format!("arc{i}"), p));
            }
        }
    }
    drawing(pieces)
}

#[test]
fn every_piece_once_with_its_geometry() {
    for seed in 0..2 {
        let d = random_drawing(seed, 45);
        for lead in [None, Some(towpath_cut::lead::LeadIn { length: 1.0, kind: towpath_cut::lead::LeadKind::Arc })] {
            let o = OrderOptions { lead_in: lead, ..opts() };
            let r = order(&d, &o).unwrap();
            // Independent of the verifier: each index once, same length, same point set ends.
            let mut seen = vec![0; d.pieces.len()];
            for p in &r.placements {
                seen[p.piece] += 1;
                let orig = &d.pieces[p.piece].path;
                assert!((p.path.length() - orig.length()).abs() < 1e-9 * (1.0 + orig.length()));
                if !orig.closed {
                    let same = p.path.start == orig.start && p.path.end() == orig.end();
                    let back = p.path.start == orig.end() && p.path.end() == orig.start;
                    assert!(same || back);
                }
            }
            assert!(seen.iter().all(|&k| k == 1));
            let v = verify(&d, &r.placements, &rules(&o));
            assert!(v.ok(), "{}", v.problems());
            assert!(r.travel_after <= r.travel_before + 1e-9);
            // Every hole before its part.
            let pos = |id: &str| r.placements.iter().position(|p: &Placement| d.pieces[p.piece].id == id).unwrap();
            for p in &d.pieces {
                if let Some(k) = p.id.strip_prefix("hole") {
                    assert!(pos(&p.id) < pos(&format!("outer{k}")));
                }
            }
        }
    }
}

#[test]
fn operations_keep_their_order() {
    let mut d = random_drawing(3, 30);
    d.operations = vec!["engrave".into(), "cut".into()];
    for (i, p) in d.pieces.iter_mut().enumerate() {
        p.operation = if p.path.closed { 1 } else { usize::from(i % 2 == 0) };
    }
    let o = opts();
    let r = order(&d, &o).unwrap();
    let ops: Vec<usize> = r.placements.iter().map(|p| d.pieces[p.piece].operation).collect();
    assert!(ops.windows(2).all(|w| w[0] <= w[1]));
    assert!(verify(&d, &r.placements, &rules(&o)).ok());
}

#[test]
fn merged_strokes_are_drawn_head_to_tail() {
    // A zigzag cut into 6 strokes, listed shuffled and some reversed: merged, they are drawn as
    // one chain (each stroke starts where the one before ended).
    let pts: Vec<P2> = (0..7).map(|i| [i as f64 * 10.0, if i % 2 == 0 { 0.0 } else { 10.0 }]).collect();
    let mut pieces: Vec<Piece> =
        (0..6).map(|i| piece(&format!("z{i}"), Path::polyline(&[pts[i], pts[i + 1]], false).unwrap())).collect();
    pieces.swap(0, 4);
    pieces[2].path = pieces[2].path.reversed();
    pieces.push(piece("far", Path::polyline(&[[200.0, 200.0], [210.0, 200.0]], false).unwrap()));
    let d = drawing(pieces);
    let o = opts();
    let chains = towpath_cut::order::merge_chains(&d, 1e-6);
    assert_eq!(chains.len(), 1);
    assert_eq!(chains[0].len(), 6);
    let r = towpath_cut::order::order_merged(&d, &o, 1e-6).unwrap();
    assert!(verify(&d, &r.placements, &rules(&o)).ok());
    let zig: Vec<&Placement> = r.placements.iter().filter(|p| d.pieces[p.piece].id.starts_with('z')).collect();
    let first = r.placements.iter().position(|p| d.pieces[p.piece].id.starts_with('z')).unwrap();
    assert!(r.placements[first..first + 6].iter().all(|p| d.pieces[p.piece].id.starts_with('z')));
    for w in zig.windows(2) {
        assert!(dist(w[0].path.end(), w[1].path.start) < 1e-9);
    }
    // Merged travel: from the origin to the chain's nearer end (0,0) then to "far".
    assert!((r.travel_after - (0.0 + dist([60.0, 0.0], [200.0, 200.0]))).abs() < 1e-9, "{}", r.travel_after);
}

/// Open strokes without nesting go to towpath's solver on their ends (see
/// `SolveOptions::two_way_ends`): every piece once with its geometry, and less pen-up than the
/// stroke search at the same number of kicks.
#[test]
fn strokes_through_their_ends_beat_the_stroke_search() {
    let mut rng = Pcg64::seed_from_u64(11);
    let (mut ends_total, mut strokes_total) = (0.0, 0.0);
    for case in 0..3u64 {
        let d = drawing(
            (0..400)
                .map(|i| {
                    let a = [rng.gen_range(0.0..500.0), rng.gen_range(0.0..500.0)];
                    let b = [rng.gen_range(0.0..500.0), rng.gen_range(0.0..500.0)];
                    piece(&format!("p{i}"), Path::polyline(&[a, b], false).unwrap())
                })
                .collect(),
        );
        let solve = SolveOptions {
            time_limit: None,
            iterations: Some(2000),
            seed: case + 1,
            threads: 1,
            ..SolveOptions::default()
        };
        let o = OrderOptions { start: Some([0.0, 0.0]), solve, ..opts() };
        let r = order(&d, &o).unwrap();
        let v = verify(&d, &r.placements, &rules(&o));
        assert!(v.ok(), "{}", v.problems());
        assert!((v.travel - r.travel_after).abs() < 1e-6 * v.travel);
        let mut seen: Vec<usize> = r.placements.iter().map(|p| p.piece).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..400).collect::<Vec<_>>());
        let o2 = OrderOptions { solve: SolveOptions { two_way_ends: false, ..o.solve.clone() }, ..o.clone() };
        let r2 = order(&d, &o2).unwrap();
        assert!(verify(&d, &r2.placements, &rules(&o2)).ok());
        ends_total += r.travel_after;
        strokes_total += r2.travel_after;
    }
    assert!(ends_total < strokes_total, "through the ends {ends_total}, stroke search {strokes_total}");
}
