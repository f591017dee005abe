"""Tests of the benchmark's pure pieces (bench/seqlib.py): route checking, the GTSP -> ATSP
transformation, medians, gaps and the table. Run with `python3 -m unittest bench/test_seq.py`
(standard library only; .ci/run runs it)."""

from __future__ import annotations

import itertools
import math
import random
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import seqlib  # noqa: E402
from seqlib import Cell, Infeasible, Model  # noqa: E402


def tsp_model(matrix):
    n = len(matrix)
    return Model(matrix=matrix, modes=[[(i, i, 0.0)] for i in range(n)], ids=[str(i + 1) for i in range(n)])


def brute_force_tsp(matrix):
    n = len(matrix)
    best = None
    for perm in itertools.permutations(range(1, n)):
        tour = (0, *perm)
        c = sum(matrix[tour[i]][tour[(i + 1) % n]] for i in range(n))
        best = c if best is None else min(best, c)
    return best


class CheckRouteTest(unittest.TestCase):
    def test_closed_tour_cost_is_the_cycle_sum_in_any_rotation(self):
        m = [[0, 1, 9, 4], [1, 0, 2, 9], [9, 2, 0, 3], [4, 9, 3, 0]]
        model = tsp_model(m)
        self.assertEqual(seqlib.price_states(model, [0, 1, 2, 3]), 1 + 2 + 3 + 4)
        self.assertEqual(seqlib.price_states(model, [2, 3, 0, 1]), 10)
        self.assertEqual(seqlib.price_states(model, [0, 2, 1, 3]), 9 + 2 + 9 + 4)

    def test_missing_repeated_and_unknown_tasks_are_infeasible(self):
        model = tsp_model([[0, 1, 1], [1, 0, 1], [1, 1, 0]])
        for route in ([0, 1], [0, 1, 1], [0, 1, 7]):
            with self.assertRaises(Infeasible):
                seqlib.price_states(model, route)

    def test_sop_precedence_pins_and_forbidden_moves(self):
        # Path 0 -> ... -> 3; task 1 must precede task 2; the move 2 -> 1 is forbidden.
        m = [[0, 5, 1, 9], [9, 0, 1, 2], [9, None, 0, 7], [9, 9, 9, 0]]
        model = tsp_model(m)
        model.precedence = [(1, 2)]
        model.end, model.first, model.last = "free", 0, 3
        self.assertEqual(seqlib.price_states(model, [0, 1, 2, 3]), 5 + 1 + 7)
        with self.assertRaises(Infeasible):
            seqlib.price_states(model, [0, 2, 1, 3])  # precedence broken
        with self.assertRaises(Infeasible):
            seqlib.price_states(model, [1, 0, 2, 3])  # first pin broken
        with self.assertRaises(Infeasible):
            seqlib.price_states(model, [0, 1, 3, 2])  # last pin broken
        model.precedence = []
        with self.assertRaisesRegex(Infeasible, "forbidden move 2 -> 1"):
            seqlib.price_states(model, [0, 2, 1, 3])

    def test_gtsp_route_through_one_node_per_set(self):
        # Two sets {0, 1} and {2, 3}: the tour 1 -> 2 -> 1 costs c(1,2) + c(2,1).
        m = [[0, 1, 8, 8], [1, 0, 3, 4], [8, 5, 0, 1], [8, 6, 1, 0]]
        model = Model(matrix=m, modes=[[(0, 0, 0.0), (1, 1, 0.0)], [(2, 2, 0.0), (3, 3, 0.0)]])
        self.assertEqual(seqlib.price_states(model, [1, 2]), 3 + 5)
        with self.assertRaises(Infeasible):
            seqlib.price_states(model, [0, 1])  # set 0 twice, set 1 never

    def test_pinned_first_in_a_cycle_is_rotated_before_precedence(self):
        m = [[0, 1, 1], [1, 0, 1], [1, 1, 0]]
        model = tsp_model(m)
        model.first, model.precedence = 0, [(1, 2)]
        self.assertEqual(seqlib.price_states(model, [1, 2, 0]), 3)  # read as 0, 1, 2
        self.assertEqual(seqlib.price_states(model, [2, 0, 1]), 3)  # read as 0, 1, 2 as well
        with self.assertRaises(Infeasible):
            seqlib.price_states(model, [0, 2, 1])  # 2 before 1 after the pinned start

    def test_from_json_reads_converted_problems(self):
        doc = {
            "states": {"matrix": [[0, 2, None], [2, 0, 3], [1, 3, 0]]},
            "tasks": [{"id": "1", "modes": [{"entry": 0}]}, {"id": "2", "modes": [{"entry": 1}]},
                      {"id": "3", "modes": [{"entry": 2}]}],
            "precedence": [["1", "3"]],
            "end": "free", "first": "1", "last": "3",
        }
        model = Model.from_json(doc)
        self.assertEqual((model.first, model.last, model.end, model.precedence), (0, 2, "free", [(0, 2)]))
        self.assertEqual(seqlib.price_states(model, [0, 1, 2]), 5)
        with self.assertRaises(ValueError):
            Model.from_json({"states": {"points": [[0, 0]]}, "tasks": []})

    def test_point_costs_price_tours_as_the_explicit_matrix_does(self):
        rng = random.Random(7)
        pts = [[rng.uniform(0, 1000), rng.uniform(0, 1000)] for _ in range(30)]
        tasks = [{"id": str(i + 1), "modes": [{"entry": i}]} for i in range(30)]
        for metric, rnd in (("euclidean_nint", lambda d: int(d + 0.5)), ("euclidean_ceil", math.ceil)):
            lazy = Model.from_json({"states": {"points": pts, "metric": metric}, "tasks": tasks})
            full = [[float(rnd(math.dist(p, q))) for q in pts] for p in pts]
            explicit = Model.from_json({"states": {"matrix": full}, "tasks": tasks})
            self.assertEqual([list(r) for r in lazy.matrix], full)
            for _ in range(5):
                tour = list(range(30))
                rng.shuffle(tour)
                self.assertEqual(seqlib.price_states(lazy, tour), seqlib.price_states(explicit, tour))
        with self.assertRaises(ValueError):
            Model.from_json({"states": {"points": pts, "metric": "geo"}, "tasks": tasks})
        with self.assertRaises(ValueError):
            Model.from_json({"states": {"points": [[0, 0, 0]], "metric": "euclidean_nint"}, "tasks": tasks[:1]})

    def test_topological_order_is_feasible(self):
        rng = random.Random(3)
        for _ in range(50):
            n = rng.randrange(3, 12)
            m = [[rng.randrange(1, 20) for _ in range(n)] for _ in range(n)]
            model = tsp_model(m)
            model.end, model.first, model.last = "free", 0, n - 1
            model.precedence = [(a, b) for a in range(1, n - 1) for b in range(a + 1, n - 1) if rng.random() < 0.3]
            model.precedence += [(0, b) for b in range(1, n)] + [(a, n - 1) for a in range(n - 1)]
            order = seqlib.topological_tasks(model)
            seqlib.check_route(model, [(t, 0) for t in order])


class NoonBeanTest(unittest.TestCase):
    def test_optimal_atsp_tour_of_the_transform_is_an_optimal_gtsp_tour(self):
        rng = random.Random(11)
        for _ in range(20):
            n = 7
            pts = [(rng.uniform(0, 100), rng.uniform(0, 100)) for _ in range(n)]
            m = [[round(((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5) for b in pts] for a in pts]
            cut = sorted(rng.sample(range(1, n), 2))
            sets = [list(range(0, cut[0])), list(range(cut[0], cut[1])), list(range(cut[1], n))]
            model = Model(matrix=m, modes=[[(v, v, 0.0) for v in s] for s in sets])
            # GTSP optimum by enumeration: one node per set, every order.
            gtsp_best = min(
                seqlib.price_states(model, list(route))
                for choice in itertools.product(*sets)
                for route in itertools.permutations(choice)
            )
            a, penalty = seqlib.noon_bean(m, sets)
            atsp_best, best_tour = None, None
            for perm in itertools.permutations(range(1, n)):
                tour = [0, *perm]
                c = sum(a[tour[i]][tour[(i + 1) % n]] for i in range(n))
                if atsp_best is None or c < atsp_best:
                    atsp_best, best_tour = c, tour
            self.assertEqual(atsp_best, gtsp_best + len(sets) * penalty)
            decoded = seqlib.noon_bean_decode(best_tour, sets)
            self.assertEqual(seqlib.price_states(model, decoded), gtsp_best)

    def test_decode_keeps_one_node_per_set_from_any_tour(self):
        sets = [[0, 1], [2, 3], [4]]
        out = seqlib.noon_bean_decode([1, 2, 0, 4, 3], sets)
        self.assertEqual(sorted(len([v for v in out if v in s]) for s in sets), [1, 1, 1])


class StatsTest(unittest.TestCase):
    def test_median_gap_ratio(self):
        self.assertEqual(seqlib.median([3, 1, 2]), 2)
        self.assertEqual(seqlib.median([4, 1, 2, 3]), 2.5)
        self.assertIsNone(seqlib.median([None]))
        self.assertAlmostEqual(seqlib.gap_percent(101, 100), 1.0)
        self.assertAlmostEqual(seqlib.gap_percent(99, 100), -1.0)
        self.assertIsNone(seqlib.gap_percent(5, None))
        self.assertAlmostEqual(seqlib.ratio(99, 100), 0.99)
        self.assertIsNone(seqlib.ratio(1, None))

    def test_summarize_counts_feasible_runs(self):
        cell = seqlib.summarize([{"cost": 10, "time": 1}, {"cost": None, "time": 3, "status": "infeasible: x"},
                                 {"cost": 14, "time": 2}])
        self.assertEqual((cell.cost, cell.time, cell.feasible, cell.runs), (12, 2, 2, 3))
        self.assertEqual(cell.note, "2/3 feasible")
        self.assertEqual(seqlib.summarize([{"cost": None, "status": "n/a"}]).note, "n/a")
        self.assertEqual(seqlib.summarize([{"cost": None, "time": 1, "status": "no solution"}]).note, "no solution")
        marked = seqlib.summarize([{"cost": 5, "time": 1, "note": "† preprocessing not limited"},
                                   {"cost": 7, "time": 1, "note": "plain"}])
        self.assertEqual((marked.cost, marked.note), (6, "†"))

    def test_brute_force_agrees_with_checker(self):
        m = [[0, 3, 4, 2], [3, 0, 1, 5], [4, 1, 0, 6], [2, 5, 6, 0]]
        model = tsp_model(m)
        best = min(seqlib.price_states(model, [0, *p]) for p in itertools.permutations([1, 2, 3]))
        self.assertEqual(best, brute_force_tsp(m))


class TableTest(unittest.TestCase):
    def test_table_and_markers(self):
        ref = seqlib.Reference("x", "TSP", 3, 100.0, "optimal", "tsplib/tsp/x.tsp")
        rows = [{"name": "x", "kind": "TSP", "n": 3, "ref": ref,
                 "cells": {"towpath": Cell(cost=101, time=1.0, runs=3, feasible=3),
                           "lkh3": Cell(cost=100, time=2.0, runs=3, feasible=3), "fast-tsp": Cell(note="n/a")}}]
        table = seqlib.render_table(rows, ["lkh3", "fast-tsp"])
        self.assertIn("| x | TSP | 3 | 100 (opt) | 101 | 1.00 | 1.0 | 100 | 0.00 | 2.0 | 1.0100 | n/a |", table)
        text = seqlib.replace_between_markers("# Benchmarks\n\n## Other\n\nkept\n", "T1", "## Seq")
        self.assertIn("kept", text)
        self.assertIn(f"{seqlib.MARK_START}\nT1\n{seqlib.MARK_END}", text)
        again = seqlib.replace_between_markers(text, "T2", "## Seq")
        self.assertNotIn("T1", again)
        self.assertEqual(again.count(seqlib.MARK_START), 1)
        self.assertIn("kept", again)

    def test_index_and_instance_list(self):
        with tempfile.TemporaryDirectory() as d:
            p = Path(d) / "index.csv"
            p.write_text("name,type,dimension,value,value_status,path,source_repo,note\n"
                         "a,TSP,5,10,optimal,tsp/a.tsp,x,\nb,GTSP,7,,,gtsp/b.gtsp,y,\n")
            idx = seqlib.load_index(p)
            self.assertEqual(idx["tsp/a.tsp"].value, 10.0)
            self.assertEqual(idx["tsp/a.tsp"].label, "opt")
            self.assertIsNone(idx["gtsp/b.gtsp"].value)
            lst = Path(d) / "list.txt"
            lst.write_text("# comment\n\ntsp/a.tsp  # trailing\ngtsp/b.gtsp\n")
            self.assertEqual(seqlib.read_instance_list(lst), ["tsp/a.tsp", "gtsp/b.gtsp"])


if __name__ == "__main__":
    unittest.main()
