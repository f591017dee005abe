#!/usr/bin/env python3
"""One-thread kick rate on a TSPLIB instance: towpath against fast-tsp, same instance, same run.

    python3 bench/kick_rate.py                        # fnl4461, 10 s, seeds 1..5
    python3 bench/kick_rate.py --runs 8 --towpath target/release/towpath

A kick is one perturbation followed by the local search that repairs it: towpath's double
bridge + Lin-Kernighan chains, fast-tsp's segment double bridge + its LK/Or-opt descent.
towpath reports its kicks and the wall time of its kick phase (`towpath solve --json`:
`iterations`, `search_seconds`). fast-tsp's Python API reports neither, so this script fetches
the fast-tsp 0.2.2 source distribution from PyPI (the version bench/seq.py pins), adds one
line that prints the kick count and the wall time of its kick loop, and builds its own
benchmark example (`cargo build --release --example bench`, its own release profile). The
instance goes to fast-tsp in its case format (coordinates; distances rounded as TSPLIB's
EUC_2D). Runs alternate between the two solvers; the table gives every run and the medians.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tarfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out", "kick_rate")
FAST_TSP = "fast_tsp-0.2.2"

# Where the kick loop of fast-tsp 0.2.2's `search_with_slack` starts and ends: the timer goes
# before the loop and the report after it (found by text, so a different version fails loudly).
LOOP_START = "    while !budget.is_exceeded() && num_iter_no_improvement < max_fails {"
LOOP_END = "    (cur_cost, kicks)\n}"


def fast_tsp_bench():
    """Builds the instrumented fast-tsp benchmark example; returns its path."""
    src = os.path.join(OUT, FAST_TSP)
    exe = os.path.join(src, "target", "release", "examples", "bench")
    if os.path.exists(exe):
        return exe
    os.makedirs(OUT, exist_ok=True)
    subprocess.run([sys.executable, "-m", "pip", "download", "fast-tsp==0.2.2", "--no-deps",
                    "--no-binary", ":all:", "-d", OUT], check=True)
    with tarfile.open(os.path.join(OUT, FAST_TSP + ".tar.gz")) as tar:
        tar.extractall(OUT)
    path = os.path.join(src, "src", "tsp", "local_search.rs")
    text = open(path).read()
    if text.count(LOOP_START) != 1 or text.count(LOOP_END) != 1:
        sys.exit(f"{path}: the kick loop is not where fast-tsp 0.2.2 has it")
    text = text.replace(LOOP_START, "    let kick_t0 = std::time::Instant::now();\n" + LOOP_START)
    text = text.replace(LOOP_END, '    eprintln!("KICKLOOP {} {}", kicks, kick_t0.elapsed().as_secs_f64());\n'
                        + LOOP_END)
    open(path, "w").write(text)
    # its own workspace, not towpath's (bench/out lies inside towpath's)
    with open(os.path.join(src, "Cargo.toml"), "a") as f:
        f.write("\n[workspace]\n")
    subprocess.run(["cargo", "build", "--release", "--example", "bench"], cwd=src, check=True)
    return exe


def case_file(tsp, name):
    """The instance's coordinates in fast-tsp's case format (`opt naive`, n, `x y` lines)."""
    lines = open(tsp).read().splitlines()
    start = next(i for i, l in enumerate(lines) if l.strip().startswith("NODE_COORD_SECTION"))
    pts = []
    for l in lines[start + 1:]:
        t = l.split()
        if len(t) < 3:
            break
        pts.append((t[1], t[2]))
    folder = os.path.join(OUT, "cases")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name + ".txt"), "w") as f:
        f.write(f"1 2\n{len(pts)}\n" + "".join(f"{x} {y}\n" for x, y in pts))
    return folder


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--instance", default=os.path.join(ROOT, "..", "shared", "data", "tsplib", "tsp", "fnl4461.tsp"))
    ap.add_argument("--time-limit", type=float, default=10.0)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--towpath", default=os.path.join(ROOT, "target", "release", "towpath"))
    args = ap.parse_args()
    name = os.path.splitext(os.path.basename(args.instance))[0]
    exe = fast_tsp_bench()
    cases = case_file(args.instance, name)
    rows = []
    for seed in range(1, args.runs + 1):
        out = subprocess.run([args.towpath, "solve", args.instance, "--time-limit", str(args.time_limit),
                              "--threads", "1", "--seed", str(seed), "--json"],
                             capture_output=True, text=True, check=True).stdout
        d = json.loads(out)
        rows.append(("towpath", seed, int(d["cost"]), d["iterations"], d["search_seconds"]))
        run = subprocess.run([exe, "--cases", cases, "--filter", name, "--time", str(args.time_limit),
                              "--threads", "1", "--seed", str(seed)], capture_output=True, text=True, check=True)
        kicks, secs = re.search(r"KICKLOOP (\d+) ([0-9.]+)", run.stderr).groups()
        cost = re.search(r"cost +(\d+)", run.stdout).group(1)
        rows.append(("fast-tsp", seed, int(cost), int(kicks), float(secs)))
        for r in rows[-2:]:
            print(f"{r[0]:9} seed {r[1]}: cost {r[2]}  {r[3]} kicks in {r[4]:.3f} s = {r[3] / r[4]:.0f}/s",
                  flush=True)
    print(f"\n| solver | runs | kicks/s (median) | kicks/s (each run) | cost (median) |")
    print("|---|---:|---:|---|---:|")
    for solver in ("towpath", "fast-tsp"):
        rs = [r for r in rows if r[0] == solver]
        rates = [r[3] / r[4] for r in rs]
        print(f"| {solver} | {len(rs)} | {statistics.median(rates):,.0f} | "
              f"{', '.join(f'{x:,.0f}' for x in rates)} | {statistics.median(r[2] for r in rs):,.0f} |")


if __name__ == "__main__":
    main()
