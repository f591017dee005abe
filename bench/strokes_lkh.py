#!/usr/bin/env python3
"""A near-optimal reference for random-stroke pen-up: LKH-3 (through the `elkai` package) on
the same strokes `bench/order.py` draws (n strokes with uniform random ends in a 1000 mm square,
seed n), so the pen-up targets of `towpath order` can be read against what is reachable.

The stroke problem becomes a symmetric TSP on the 2n stroke ends plus one dummy node: the two
ends of a stroke are joined at cost 0, every other pair at M + 100·distance (M large, so a tour
uses all n stroke edges), and the dummy is joined to everything at M (it cuts the cycle into the
open path the pen draws). Pen-up is then summed from the tour by this script.

    bench/.venv/bin/python bench/strokes_lkh.py 1000 [RUNS]
"""
import math
import random
import sys
import time

import elkai


def main():
    n = int(sys.argv[1])
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    rng = random.Random(n)
    strokes = []
    for _ in range(n):
        x1, y1, x2, y2 = (rng.uniform(0, 1000.0) for _ in range(4))
        strokes.append(((x1, y1), (x2, y2)))
    pts = [p for s in strokes for p in s]
    size = 2 * n + 1
    big = 10 ** 7
    mat = [[0] * size for _ in range(size)]
    for i in range(2 * n):
        for j in range(2 * n):
            if i != j and i // 2 != j // 2:
                mat[i][j] = big + int(round(math.dist(pts[i], pts[j]) * 100))
        mat[i][2 * n] = big
        mat[2 * n][i] = big
    t0 = time.time()
    tour = elkai.DistanceMatrix(mat).solve_tsp(runs=runs)
    elapsed = time.time() - t0
    if tour[0] == tour[-1]:
        tour = tour[:-1]
    k = tour.index(2 * n)
    tour = tour[k + 1:] + tour[:k]
    pen, prev, intact = 0.0, None, True
    for i in range(0, len(tour), 2):
        a, b = tour[i], tour[i + 1]
        intact &= a // 2 == b // 2
        if prev is not None:
            pen += math.dist(pts[prev], pts[a])
        prev = b
    print(f"{n} random strokes: LKH-3 ({runs} runs) pen-up {pen:,.0f} mm, strokes intact: {intact}, {elapsed:.1f} s")


if __name__ == "__main__":
    main()
