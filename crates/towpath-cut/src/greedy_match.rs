//! The greedy-edge start tour for stroke tours without precedence: the shortest links between
//! the ends of different pieces are taken first (each open end takes one link, a closed
//! contour's entry point two, no cycle), then the fragments are chained nearest end first.
//!
//! For the travelling salesman problem the greedy edge construction is the usual start for 2-opt
//! and 3-opt local search (Johnson & McGeoch 1997, "The traveling salesman problem: a case study
//! in local optimization"): shorter than nearest neighbour and, more to the point here, with
//! fewer long links, so the local search needs fewer long segment reversals. Here it runs on the
//! pieces' ends: an open stroke is an edge between its two ends that must be in the tour, a
//! closed contour one point (its first entry candidate; the local search then moves the entry).

use rstar::primitives::GeomWithData;
use rstar::RTree;

use crate::geom::P2;
use crate::point_grid::PointGrid;

/// Links considered per end: its nearest ends of other pieces.
const CANDIDATES: usize = 10;

/// How a piece takes part: an open stroke reversible by its mode `reverse` of mode 0, or a
/// closed contour (every mode starts where it ends).
#[derive(Clone, Copy)]
enum Kind {
    Open { reverse: u32 },
    Closed,
}

/// A start tour `(piece, mode)` from `start` (or free), or `None` when a piece is neither a
/// reversible open stroke (two modes, one the other run backwards) nor a closed contour, or when
/// there are no pieces.
pub fn greedy_matching(ends: &[Vec<(P2, P2)>], start: Option<P2>) -> Option<Vec<(usize, u32)>> {
    let n = ends.len();
    if n == 0 {
        return None;
    }
    let mut kind = Vec::with_capacity(n);
    for ms in ends {
        let &(e, x) = ms.first()?;
        if ms.iter().all(|&(a, b)| a == b) {
            kind.push(Kind::Closed);
        } else if e != x {
            let r = ms.iter().position(|&(a, b)| a == x && b == e)?;
            kind.push(Kind::Open { reverse: r as u32 });
        } else {
            return None;
        }
    }
    // Nodes: 2t is piece t's entry of mode 0, 2t+1 its exit (unused for closed contours); the
    // start, if any, is node 2n with one free slot.
    let point = |v: usize| -> P2 {
        if v == 2 * n {
            start.unwrap_or([0.0, 0.0])
        } else if v % 2 == 0 {
            ends[v / 2][0].0
        } else {
            ends[v / 2][0].1
        }
    };
    let piece = |v: usize| v / 2; // the start is "piece" n
    let mut slots: Vec<u8> = (0..2 * n + 1)
        .map(|v| {
            if v == 2 * n {
                u8::from(start.is_some())
            } else {
                match kind[v / 2] {
                    Kind::Closed if v % 2 == 0 => 2,
                    Kind::Closed => 0,
                    Kind::Open { .. } => 1,
                }
            }
        })
        .collect();
    let nodes: Vec<usize> = (0..2 * n + 1).filter(|&v| slots[v] > 0).collect();
    let grid = PointGrid::new(nodes.iter().map(|&v| point(v)).collect());
    let mut cand: Vec<(f64, u32, u32)> = Vec::with_capacity(nodes.len() * CANDIDATES);
    let mut found = Vec::new();
    for &v in &nodes {
        grid.nearest(point(v), CANDIDATES + 2, &mut found);
        for &(d2, i) in &found {
            let u = nodes[i as usize];
            if piece(u) != piece(v) && v < u {
                cand.push((d2, v as u32, u as u32));
            }
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    cand.dedup_by(|b, a| a.1 == b.1 && a.2 == b.2);
    // Union-find over pieces (and the start) against cycles.
    let mut parent: Vec<u32> = (0..=n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let g = parent[parent[x as usize] as usize];
            parent[x as usize] = g;
            x = g;
        }
        x
    }
    let mut links: Vec<[u32; 2]> = vec![[u32::MAX; 2]; 2 * n + 1];
    let link = |links: &mut Vec<[u32; 2]>, a: usize, b: usize| {
        let s = &mut links[a];
        if s[0] == u32::MAX {
            s[0] = b as u32;
        } else {
            s[1] = b as u32;
        }
    };
    for &(_, a, b) in &cand {
        let (a, b) = (a as usize, b as usize);
        if slots[a] == 0 || slots[b] == 0 {
            continue;
        }
        let (ra, rb) = (find(&mut parent, piece(a) as u32), find(&mut parent, piece(b) as u32));
        if ra == rb {
            continue;
        }
        parent[ra as usize] = rb;
        slots[a] -= 1;
        slots[b] -= 1;
        link(&mut links, a, b);
        link(&mut links, b, a);
    }
    // Walk a fragment from a free port: the pieces in order with their modes, and where it ends.
    let other_end = |v: usize| -> usize {
        match kind[v / 2] {
            Kind::Closed => v,
            Kind::Open { .. } => v ^ 1,
        }
    };
    let mode_entering = |v: usize| -> u32 {
        match kind[v / 2] {
            Kind::Open { reverse } if v % 2 == 1 => reverse,
            _ => 0,
        }
    };
    let mut done = vec![false; n];
    let mut tour: Vec<(usize, u32)> = Vec::with_capacity(n);
    // Walks from node `v` (entering its piece there, `from` the node we came from).
    let walk = |mut v: usize, mut from: u32, tour: &mut Vec<(usize, u32)>, done: &mut Vec<bool>| -> usize {
        loop {
            let t = v / 2;
            done[t] = true;
            tour.push((t, mode_entering(v)));
            let x = other_end(v);
            // (a closed contour's point holds both links: the way out is the one not come in by;
            // an open stroke's exit end holds at most one, never the way in)
            let out = links[x].iter().copied().find(|&u| u != u32::MAX && u != from);
            match out {
                Some(u) if (u as usize) != 2 * n && !done[(u as usize) / 2] => {
                    from = x as u32;
                    v = u as usize;
                }
                _ => return x,
            }
        }
    };
    // Free ports: the entry nodes a fragment can be entered by (a node with a free slot, or a
    // closed contour with fewer than two links).
    let ports: Vec<GeomWithData<P2, u32>> =
        (0..2 * n).filter(|&v| slots[v] > 0).map(|v| GeomWithData::new(point(v), v as u32)).collect();
    let mut free = RTree::bulk_load(ports);
    let mut at: Option<P2> = None;
    if start.is_some() {
        if let Some(u) = links[2 * n].iter().copied().find(|&u| u != u32::MAX) {
            let last = walk(u as usize, (2 * n) as u32, &mut tour, &mut done);
            at = Some(point(last));
        } else {
            at = start;
        }
    }
    while tour.len() < n {
        let next = match at {
            Some(p) => loop {
                let Some(item) = free.nearest_neighbor(&p).copied() else { break None };
                free.remove(&item);
                if !done[item.data as usize / 2] {
                    break Some(item.data as usize);
                }
            },
            None => (0..2 * n).find(|&v| slots[v] > 0 && !done[v / 2]),
        };
        let Some(v) = next.or_else(|| (0..n).find(|&t| !done[t]).map(|t| 2 * t)) else { break };
        let last = walk(v, u32::MAX, &mut tour, &mut done);
        at = Some(point(last));
    }
    (tour.len() == n).then_some(tour)
}

/// Pen-up length of a tour `(piece, mode)` from `start` (free when `None`): the links from each
/// piece's exit to the next one's entry.
pub fn pen_up(ends: &[Vec<(P2, P2)>], start: Option<P2>, tour: &[(usize, u32)]) -> f64 {
    let mut at = start;
    let mut total = 0.0;
    for &(t, m) in tour {
        let (e, x) = ends[t][m as usize];
        if let Some(a) = at {
            total += ((a[0] - e[0]) * (a[0] - e[0]) + (a[1] - e[1]) * (a[1] - e[1])).sqrt();
        }
        at = Some(x);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    fn strokes(n: usize, closed_every: usize, seed: u64) -> Vec<Vec<(P2, P2)>> {
        let mut s = seed;
        (0..n)
            .map(|i| {
                let a = [rng(&mut s) * 1000.0, rng(&mut s) * 1000.0];
                if closed_every > 0 && i % closed_every == 0 {
                    let b = [a[0] + 5.0, a[1]];
                    vec![(a, a), (b, b)]
                } else {
                    let b = [rng(&mut s) * 1000.0, rng(&mut s) * 1000.0];
                    vec![(a, b), (b, a)]
                }
            })
            .collect()
    }

    #[test]
    fn every_piece_once_and_shorter_than_nearest_neighbour() {
        for (closed_every, start) in [(0, None), (3, None), (0, Some([0.0, 0.0])), (4, Some([500.0, 500.0]))] {
            let ends = strokes(2000, closed_every, 7 + closed_every as u64);
            let tour = greedy_matching(&ends, start).unwrap();
            let mut seen = vec![false; ends.len()];
            for &(t, m) in &tour {
                assert!(!seen[t], "piece {t} twice");
                seen[t] = true;
                assert!((m as usize) < ends[t].len());
            }
            assert!(seen.iter().all(|&s| s));
            let nn = crate::order::greedy(&ends, &[], start);
            let nn: Vec<(usize, u32)> = nn.iter().map(|s| (s.task.index(), s.mode)).collect();
            let (g, b) = (pen_up(&ends, start, &tour), pen_up(&ends, start, &nn));
            assert!(g < b, "greedy matching {g} vs nearest neighbour {b}");
        }
    }

    #[test]
    fn refuses_pieces_it_cannot_model() {
        // a one-way stroke (no reverse mode)
        let ends = vec![vec![([0.0, 0.0], [1.0, 0.0])], vec![([2.0, 0.0], [3.0, 0.0]), ([3.0, 0.0], [2.0, 0.0])]];
        assert!(greedy_matching(&ends, None).is_none());
        assert!(greedy_matching(&[], None).is_none());
        let one = vec![vec![([0.0, 0.0], [1.0, 0.0]), ([1.0, 0.0], [0.0, 0.0])]];
        assert_eq!(greedy_matching(&one, None), Some(vec![(0, 0)]));
    }
}
