#!/usr/bin/env python3
"""Clustered TSP instances for bench/seq.py: what AFP parts, cut sheets and drawings look like
(tight groups far apart), in TSPLIB EUC_2D files with an index.csv beside them.

    python3 bench/gen_clustered.py                      # default set into bench/out/clustered/
    python3 bench/seq.py --data bench/out/clustered --instances bench/out/clustered/list.txt \\
        --peers fast-tsp,lkh3 --no-scale --output bench/out/clustered/table.md

Two families, both seeded (Python's `random.Random(seed)`), integer coordinates:
- `gauss-N-K-sS`: K cluster centres uniform in a 40,000 square, N points each drawn from a
  centre chosen uniformly at random plus a normal offset with sigma = 40,000 / (8 sqrt(K))
  per axis (clusters a few percent of the square across, well apart);
- `portc-N-sS`: after the DIMACS TSP Challenge's `portcgen` (Johnson & McGeoch 2002): N/10
  centres uniform in the square, each point a random centre plus a normal offset with
  sigma = side / sqrt(N) per axis. The Challenge uses a 1,000,000 square; the shape is the
  same. (The idea, not the generator's random numbers: these are not the Challenge's files.)

No optimum is known for these: index.csv leaves `value` empty, and the benchmark compares the
solvers with each other (`tp/X` columns).
"""

from __future__ import annotations

import argparse
import math
import random
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Side of the square. Small enough that every distance fits fast-tsp's 16-bit matrix (the
#: diagonal is 56,569 ≤ 65,535), large enough that rounding to integers hardly matters.
SIDE = 40_000.0

#: (family, n, clusters, seed) of the default set; clusters is ignored by `portc`.
DEFAULT = [
    ("gauss", 2000, 40, 1),
    ("gauss", 5000, 60, 1),
    ("gauss", 10000, 100, 1),
    ("portc", 2000, 0, 1),
    ("portc", 5000, 0, 1),
    ("portc", 10000, 0, 1),
]


def gauss(n: int, k: int, seed: int) -> list[tuple[int, int]]:
    """N points around K uniform centres with sigma = SIDE / (8 sqrt K)."""
    rng = random.Random(seed)
    centres = [(rng.uniform(0, SIDE), rng.uniform(0, SIDE)) for _ in range(k)]
    sigma = SIDE / (8 * math.sqrt(k))
    return [clamp(c[0] + rng.gauss(0, sigma), c[1] + rng.gauss(0, sigma)) for c in (rng.choice(centres) for _ in range(n))]


def portc(n: int, seed: int) -> list[tuple[int, int]]:
    """portcgen-like: N/10 uniform centres, sigma = SIDE / sqrt(N)."""
    rng = random.Random(seed)
    centres = [(rng.uniform(0, SIDE), rng.uniform(0, SIDE)) for _ in range(max(1, n // 10))]
    sigma = SIDE / math.sqrt(n)
    return [clamp(c[0] + rng.gauss(0, sigma), c[1] + rng.gauss(0, sigma)) for c in (rng.choice(centres) for _ in range(n))]


def clamp(x: float, y: float) -> tuple[int, int]:
    """Rounded to integers (TSPLIB files here hold integer coordinates), kept inside the square."""
    return (min(int(SIDE), max(0, round(x))), min(int(SIDE), max(0, round(y))))


def write_tsp(path: Path, name: str, comment: str, pts: list[tuple[int, int]]) -> None:
    lines = [f"NAME : {name}", f"COMMENT : {comment}", "TYPE : TSP", f"DIMENSION : {len(pts)}",
             "EDGE_WEIGHT_TYPE : EUC_2D", "NODE_COORD_SECTION"]
    lines += [f"{i + 1} {x} {y}" for i, (x, y) in enumerate(pts)]
    lines.append("EOF")
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=ROOT / "bench" / "out" / "clustered")
    ap.add_argument("--seeds", type=int, default=1, help="instances per (family, size): seeds 1..S")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows, names = [], []
    for family, n, k, _ in DEFAULT:
        for seed in range(1, args.seeds + 1):
            if family == "gauss":
                name = f"gauss-{n}-{k}-s{seed}"
                pts, comment = gauss(n, k, seed), f"{n} points in {k} Gaussian clusters (bench/gen_clustered.py)"
            else:
                name = f"portc-{n}-s{seed}"
                pts, comment = portc(n, seed), f"{n} points, portcgen-like clusters (bench/gen_clustered.py)"
            write_tsp(args.out / f"{name}.tsp", name, comment, pts)
            rows.append(f"{name},TSP,{n},,none,{name}.tsp,bench/gen_clustered.py,")
            names.append(f"{name}.tsp")
    (args.out / "index.csv").write_text(
        "name,type,dimension,value,value_status,path,source_repo,note\n" + "\n".join(rows) + "\n")
    (args.out / "list.txt").write_text("# clustered instances (bench/gen_clustered.py)\n" + "\n".join(names) + "\n")
    print(f"wrote {len(names)} instances to {args.out}")


if __name__ == "__main__":
    main()
