#!/usr/bin/env python3
"""Sequencing benchmark: towpath against LKH-3 (elkai), fast-tsp and OR-Tools routing (guided
local search) on the same instances, at the same time limit, in the same run.

    python3 bench/seq.py                         # default list, 10 s, 3 runs, writes BENCHMARKS.md
    python3 bench/seq.py --time-limit 5 --runs 1 --instances my_list.txt
    python3 bench/seq.py --only towpath          # no peers (no virtualenv needed)
    python3 bench/seq.py --scale-only            # the 100,000-task scale check alone

Every instance is converted once by `towpath convert --matrix` into towpath's JSON format, so the
peers read exactly the problem towpath solves (coordinate files of over 5,000 points, too large
for a matrix, are read as points and priced from them: seqlib.PointCosts); every peer answer is re-priced and checked for
feasibility here (bench/seqlib.py) before it is reported. The peers are installed into
bench/.venv (pinned versions) on first use. Raw results go to bench/out/seq-results.jsonl
(`--resume` skips what is already there), the table into BENCHMARKS.md between the
`<!-- seq-bench:start -->` / `<!-- seq-bench:end -->` markers.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import seqlib  # noqa: E402
from seqlib import Cell, Infeasible, Model  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "bench"
VENV = BENCH / ".venv"
OUT = BENCH / "out"
#: Most entries `towpath convert --matrix` writes (towpath_formats::MAX_MATRIX_ENTRIES); larger
#: coordinate instances are read as points and priced on demand (`seqlib.PointCosts`).
MAX_MATRIX_ENTRIES = 25_000_000

PINS = {"elkai": "2.0.1", "fast-tsp": "0.2.2", "ortools": "9.15.6755"}
PEERS = ["lkh3", "fast-tsp", "ortools"]
#: Which instance kinds each peer can take.
PEER_KINDS = {
    "lkh3": {"TSP", "ATSP", "GTSP"},
    "fast-tsp": {"TSP"},
    "ortools": {"TSP", "ATSP", "SOP", "GTSP", "PCGTSP"},
}


# --------------------------------------------------------------------------- environment



def load_note(load_vals):
    """How busy the machine was: quiet when the 1-minute load stayed near the benchmark's own threads."""
    med = seqlib.median(load_vals) or 0
    span = f"median {med:.1f} (min {min(load_vals, default=0):.1f}, max {max(load_vals, default=0):.1f})"
    cores = os.cpu_count() or 2
    if med <= cores + 0.5:
        return (f"Quiet: no other jobs ran; 1-minute load average during the runs {span}, the benchmark's own "
                f"solver threads.")
    return (f"**Taken under load**: other jobs ran on the same {cores} cores; 1-minute load average during the "
            f"runs {span}. Wall times and solution quality at a fixed limit are therefore pessimistic and noisy "
            f"for every solver.")

def venv_python() -> Path:
    return VENV / "bin" / "python"


def in_venv() -> bool:
    return Path(sys.prefix).resolve() == VENV.resolve()


def ensure_venv() -> None:
    """Creates bench/.venv with the pinned peers if needed and re-runs this script in it."""
    if in_venv():
        return
    if not venv_python().exists():
        print(f"creating {VENV}", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    probe = subprocess.run(
        [str(venv_python()), "-c", "import elkai, fast_tsp, ortools; from importlib.metadata import version as v; "
         "print(v('elkai'), v('fast-tsp'), v('ortools'))"],
        capture_output=True, text=True,
    )
    if probe.returncode != 0 or probe.stdout.split() != [PINS["elkai"], PINS["fast-tsp"], PINS["ortools"]]:
        pins = [f"{k}=={v}" for k, v in PINS.items()]
        print(f"installing {' '.join(pins)} into {VENV}", file=sys.stderr)
        subprocess.run([str(venv_python()), "-m", "pip", "install", "--quiet", *pins], check=True)
    os.execv(str(venv_python()), [str(venv_python()), str(Path(__file__).resolve()), *sys.argv[1:]])


def default_data_dir() -> Path:
    for cand in [ROOT.parent / "shared" / "data", ROOT.parent.parent / "shared" / "data", Path("/work/shared/data")]:
        if (cand / "index.csv").exists():
            return cand
    return ROOT.parent / "shared" / "data"


def build_towpath() -> Path:
    subprocess.run(["cargo", "build", "--release", "-p", "towpath", "--quiet"], cwd=ROOT, check=True)
    return ROOT / "target" / "release" / "towpath"


# --------------------------------------------------------------------------- processes


def run_measured(cmd: list[str], timeout: float, stdout_path: Path) -> dict:
    """Runs a command with stdout to a file; returns wall time, CPU time, peak RSS (MiB), exit
    status and whether it was killed at `timeout`."""
    t0 = time.perf_counter()
    with open(stdout_path, "wb") as out, open(stdout_path.with_suffix(".err"), "wb") as err:
        proc = subprocess.Popen(cmd, stdout=out, stderr=err)
        killed = False
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid != 0:
                break
            if time.perf_counter() - t0 > timeout:
                proc.kill()
                killed = True
                pid, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.02)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return {
        "wall": time.perf_counter() - t0,
        "cpu": usage.ru_utime + usage.ru_stime,
        "rss_mib": usage.ru_maxrss / 1024.0,
        "code": proc.returncode,
        "killed": killed,
    }


def convert(towpath: Path, src: Path, dst: Path, matrix: bool) -> None:
    if dst.exists() and dst.stat().st_mtime >= src.stat().st_mtime:
        return
    cmd = [str(towpath), "convert", str(src), "--to", "json", "-o", str(dst)] + (["--matrix"] if matrix else [])
    subprocess.run(cmd, check=True)


# --------------------------------------------------------------------------- towpath


def run_towpath(towpath: Path, src: Path, limit: float, seed: int, threads: int, model: Model) -> dict:
    out = OUT / "tmp" / "towpath.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [str(towpath), "solve", str(src), "--json", "--time-limit", str(limit), "--seed", str(seed),
           "--threads", str(threads)]
    m = run_measured(cmd, 3 * limit + 120, out)
    res = {"wall": m["wall"], "cpu": m["cpu"], "rss_mib": m["rss_mib"]}
    if m["code"] != 0:
        res.update(cost=None, status=f"exit {m['code']}", time=m["wall"])
        return res
    doc = json.loads(out.read_text())
    res["time"] = doc["time_seconds"]
    # Re-price towpath's answer too, through the same checker as the peers.
    try:
        states = tour_states(model, doc["tour"], doc["type"])
        cost = seqlib.price_states(model, states)
    except (Infeasible, KeyError, ValueError) as e:
        res.update(cost=None, status=f"infeasible: {e}")
        return res
    if abs(cost - doc["cost"]) > 1e-6 * max(1.0, abs(cost)):
        res.update(cost=None, status=f"cost mismatch: towpath says {doc['cost']}, re-priced {cost}")
        return res
    res["cost"] = cost
    return res


def tour_states(model: Model, tour: list, kind: str) -> list[int]:
    """towpath's answer (node numbers in the file's numbering) as states of the JSON model."""
    if kind in ("GTSP", "PCGTSP"):
        return [int(v) - 1 for v in tour]
    return [int(v) - 1 for v in tour]


# --------------------------------------------------------------------------- peers (workers)


def worker_main(argv: list[str]) -> None:
    """`seq.py --worker PEER KIND MATRIX_JSON NATIVE_JSON LIMIT SEED THREADS`: runs one peer and
    prints {"states": [...], "time": s, "cpu": s, "note": ...} on stdout."""
    peer, kind, matrix_json, native_json, limit, seed, threads = argv
    limit, seed, threads = float(limit), int(seed), int(threads)
    doc = json.loads(Path(matrix_json).read_text())
    model = Model.from_json(doc)
    native = json.loads(Path(native_json).read_text()) if native_json != matrix_json else doc
    t0, c0 = time.perf_counter(), time.process_time()
    if peer == "lkh3":
        states, note = solve_lkh3(model, native, kind, limit, seed)
    elif peer == "fast-tsp":
        states, note = solve_fast_tsp(model, limit, threads)
    elif peer == "ortools":
        states, note = solve_ortools(model, kind, limit)
    else:
        raise SystemExit(f"unknown peer {peer}")
    print(json.dumps({"states": states, "time": time.perf_counter() - t0, "cpu": time.process_time() - c0,
                      "note": note}))


def int_matrix(model: Model, forbidden: int) -> list[list[int]]:
    return [[forbidden if c is None else int(round(c)) for c in row] for row in model.matrix]


#: towpath JSON metrics that are TSPLIB coordinate types LKH reads itself.
LKH_METRICS = {"euclidean_nint": "EUC_2D", "euclidean_ceil": "CEIL_2D", "att": "ATT", "geo": "GEO",
               "manhattan_nint": "MAN_2D", "maximum_nint": "MAX_2D"}


def lkh_problem(model: Model, native: dict, kind: str) -> tuple[str, list[list[int]] | None]:
    """The LKH problem text: coordinates when the instance has a TSPLIB metric (LKH's own
    candidate sets then apply), else the full matrix. GTSP goes through the Noon–Bean ATSP."""
    n = model.n
    pts = native["states"].get("points")
    metric = native["states"].get("metric")
    if kind == "TSP" and pts is not None and metric in LKH_METRICS and all(len(p) == 2 for p in pts):
        lines = [f"TYPE : TSP", f"DIMENSION : {n}", f"EDGE_WEIGHT_TYPE : {LKH_METRICS[metric]}", "NODE_COORD_SECTION"]
        lines += [f"{i + 1} {p[0]!r} {p[1]!r}" for i, p in enumerate(pts)]
        return "\n".join(lines) + "\nEOF\n", None
    if kind == "GTSP":
        mat, _ = seqlib.noon_bean(model.matrix, model.sets())
        typ = "ATSP"
    else:
        finite = [c for row in model.matrix for c in row if c is not None]
        mat = int_matrix(model, 10 * int(max(finite) + 1))
        typ = "TSP" if kind == "TSP" else "ATSP"
    lines = [f"TYPE : {typ}", f"DIMENSION : {n}", "EDGE_WEIGHT_TYPE : EXPLICIT", "EDGE_WEIGHT_FORMAT : FULL_MATRIX",
             "EDGE_WEIGHT_SECTION"]
    lines += [" ".join(map(str, row)) for row in mat]
    return "\n".join(lines) + "\nEOF\n", mat


def solve_lkh3(model: Model, native: dict, kind: str, limit: float, seed: int) -> tuple[list[int], str]:
    from elkai import _elkai

    problem, _ = lkh_problem(model, native, kind)
    # One run, unbounded trials, stopped by LKH's own time limits (which LKH measures in CPU
    # seconds; TOTAL_TIME_LIMIT includes its preprocessing).
    params = (f"RUNS = 1\nMAX_TRIALS = 1000000000\nTIME_LIMIT = {limit}\nTOTAL_TIME_LIMIT = {limit}\n"
              f"SEED = {seed}\nTRACE_LEVEL = 0\nPRECISION = 1\nPROBLEM_FILE = :stdin:\n")
    tour = [v - 1 for v in _elkai.solve_problem(params, problem)]
    note = ""
    if not tour:
        # Its preprocessing alone used up TOTAL_TIME_LIMIT: give the limit to the search only.
        params = params.replace(f"TOTAL_TIME_LIMIT = {limit}\n", "")
        tour = [v - 1 for v in _elkai.solve_problem(params, problem)]
        note = "† no tour within TOTAL_TIME_LIMIT; re-run with TIME_LIMIT only (preprocessing not limited)"
    if kind == "GTSP":
        return seqlib.noon_bean_decode(tour, model.sets()), note or "Noon-Bean ATSP"
    return tour, note


def solve_fast_tsp(model: Model, limit: float, threads: int) -> tuple[list[int], str]:
    import fast_tsp
    import numpy as np

    if isinstance(model.matrix, seqlib.PointCosts):
        # a coordinate instance too large for a Python matrix: the same costs, built by numpy
        p = np.array(model.matrix.points)
        m = np.empty((len(p), len(p)), dtype=np.int64)
        for i in range(len(p)):
            d = np.hypot(p[:, 0] - p[i, 0], p[:, 1] - p[i, 1])
            m[i] = np.floor(d + 0.5) if model.matrix.metric == "euclidean_nint" else np.ceil(d)
    else:
        m = np.array(int_matrix(model, 0), dtype=np.int64)
    np.fill_diagonal(m, 0)
    # The wall time reported includes building the matrix above (seconds at 4000+ nodes); the
    # note gives the solver's own time.
    t0 = time.perf_counter()
    tour = fast_tsp.find_tour(m, duration_seconds=limit, max_threads=threads)
    return [int(v) for v in tour], f"find_tour {time.perf_counter() - t0:.1f} s"


def solve_ortools(model: Model, kind: str, limit: float) -> tuple[list[int], str]:
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2

    n = model.n
    finite = [c for row in model.matrix for c in row if c is not None]
    big = int(max(finite) + 1) * (n + 1)
    cost = int_matrix(model, big)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.local_search_metaheuristic = routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    params.time_limit.FromMilliseconds(int(limit * 1000))

    if kind in ("TSP", "ATSP", "SOP"):
        if kind == "SOP":
            first, last = model.modes[model.first][0][0], model.modes[model.last][0][0]
            manager = pywrapcp.RoutingIndexManager(n, 1, [first], [last])
            params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.LOCAL_CHEAPEST_INSERTION
        else:
            manager = pywrapcp.RoutingIndexManager(n, 1, 0)
            params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
        routing = pywrapcp.RoutingModel(manager)
        arc = routing.RegisterTransitMatrix(cost)
        routing.SetArcCostEvaluatorOfAllVehicles(arc)
        if kind == "SOP":
            one = routing.RegisterUnaryTransitCallback(lambda i: 1)
            routing.AddDimension(one, 0, n + 1, True, "order")
            order = routing.GetDimensionOrDie("order")
            solver = routing.solver()
            for a, b in model.precedence:
                sa, sb = model.modes[a][0][0], model.modes[b][0][0]
                if first in (sa, sb) or last in (sa, sb):
                    continue  # the path's ends satisfy these by construction
                solver.Add(order.CumulVar(manager.NodeToIndex(sa)) < order.CumulVar(manager.NodeToIndex(sb)))
        sol, note = solve_seeded(routing, params, model, kind, lambda t: model.modes[t][0][0], manager)
        if sol is None:
            return [], "no solution"
        idx, route = routing.Start(0), []
        while not routing.IsEnd(idx):
            route.append(manager.IndexToNode(idx))
            idx = sol.Value(routing.NextVar(idx))
        if kind == "SOP":
            route.append(manager.IndexToNode(idx))
        return route, note

    # GTSP / PCGTSP: one vehicle per node of the anchor set (the pinned start set, else the
    # smallest), starting there and ending at a copy of it, so that the closing move is priced;
    # a large fixed cost per used vehicle makes one vehicle do the whole tour. Every other set is
    # a disjunction with max cardinality 1 and a large penalty.
    sets = model.sets()
    anchor = model.first if model.first is not None else min(range(len(sets)), key=lambda k: len(sets[k]))
    starts = sets[anchor]
    k = len(starts)
    size = n + k
    ext = [[big] * size for _ in range(size)]
    for i in range(n):
        ext[i][:n] = cost[i]
        for j, s in enumerate(starts):
            ext[i][n + j] = cost[i][s]
    for j, s in enumerate(starts):
        ext[s][n + j] = 0  # an unused vehicle goes straight from its start to its end
    manager = pywrapcp.RoutingIndexManager(size, k, starts, [n + j for j in range(k)])
    routing = pywrapcp.RoutingModel(manager)
    arc = routing.RegisterTransitMatrix(ext)
    routing.SetArcCostEvaluatorOfAllVehicles(arc)
    routing.SetFixedCostOfAllVehicles(big)
    penalty = big * 10
    for t, members in enumerate(sets):
        if t != anchor:
            routing.AddDisjunction([manager.NodeToIndex(v) for v in members], penalty, 1)
    if model.precedence:
        one = routing.RegisterUnaryTransitCallback(lambda i: 1)
        routing.AddDimension(one, 0, size + 1, True, "order")
        order = routing.GetDimensionOrDie("order")
        solver = routing.solver()
        pos = {}
        for t, members in enumerate(sets):
            if t != anchor:
                idxs = [manager.NodeToIndex(v) for v in members]
                pos[t] = solver.Sum([routing.ActiveVar(i) * order.CumulVar(i) for i in idxs])
        for a, b in model.precedence:
            if a != anchor and b != anchor:
                solver.Add(pos[a] < pos[b])
    params.first_solution_strategy = (routing_enums_pb2.FirstSolutionStrategy.LOCAL_CHEAPEST_INSERTION
                                      if model.precedence else routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC)
    sol, note = solve_seeded(routing, params, model, kind, lambda t: sets[t][0], manager, vehicles=k, anchor=anchor)
    if sol is None:
        return [], "no solution"
    best = []
    for v in range(k):
        idx, route = routing.Start(v), []
        while not routing.IsEnd(idx):
            route.append(manager.IndexToNode(idx))
            idx = sol.Value(routing.NextVar(idx))
        if len(route) > len(best):
            best = route
    return best, note


def solve_seeded(routing, params, model: Model, kind: str, node_of, manager, vehicles: int = 1, anchor=None):
    """Solves; under precedence, where OR-Tools' own first-solution strategies find nothing,
    starts the guided local search from a topological order (a feasible route)."""
    if not model.precedence:
        return routing.SolveWithParameters(params), ""
    order = seqlib.topological_tasks(model)
    inner = [node_of(t) for t in order if t != anchor]
    if kind == "SOP":
        inner = inner[1:-1]  # the path's ends are the vehicle's start and end
    routes = [inner] + [[] for _ in range(vehicles - 1)]
    routing.CloseModelWithParameters(params)
    initial = routing.ReadAssignmentFromRoutes(routes, True)
    if initial is None:
        return routing.SolveWithParameters(params), "unseeded"
    return routing.SolveFromAssignmentWithParameters(initial, params), "seeded with a topological order"


def run_peer(peer: str, kind: str, matrix_json: Path, native_json: Path, limit: float, seed: int, threads: int,
             model: Model) -> dict:
    out = OUT / "tmp" / f"{peer}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", peer, kind, str(matrix_json), str(native_json),
           str(limit), str(seed), str(threads)]
    # LKH measures its limit in CPU seconds and its preprocessing can exceed it: allow it time.
    m = run_measured(cmd, 10 * limit + 300, out)
    res = {"wall": m["wall"], "rss_mib": m["rss_mib"]}
    if m["code"] != 0 or m["killed"]:
        tail = out.with_suffix(".err").read_text(errors="replace").strip().splitlines()[-1:]
        res.update(cost=None, status="killed at timeout" if m["killed"] else f"crashed (exit {m['code']}) {tail}",
                   time=m["wall"])
        return res
    doc = json.loads(out.read_text().strip().splitlines()[-1])
    res.update(time=doc["time"], cpu=doc["cpu"], note=doc.get("note", ""))
    if not doc["states"]:
        res.update(cost=None, status=doc.get("note") or "no answer")
        return res
    try:
        res["cost"] = seqlib.price_states(model, doc["states"])
    except Infeasible as e:
        res.update(cost=None, status=f"infeasible: {e}")
    return res


# --------------------------------------------------------------------------- scale check


def scale_check(towpath: Path, tasks: int, limit: float, seed: int, threads: int) -> dict:
    """A random uniform Euclidean instance of `tasks` strokes (two modes each: both directions),
    written as towpath JSON with coordinates; solved with a time limit; wall time and peak RSS of
    the process, and a sampled 2-opt check of the answer."""
    rng = random.Random(seed)
    pts, jt = [], []
    for t in range(tasks):
        x, y = rng.uniform(0, 1000), rng.uniform(0, 1000)
        ang, length = rng.uniform(0, math.pi), rng.uniform(0.5, 3.0)
        a, b = 2 * t, 2 * t + 1
        pts.append([round(x, 4), round(y, 4)])
        pts.append([round(x + length * math.cos(ang), 4), round(y + length * math.sin(ang), 4)])
        jt.append({"id": f"s{t}", "modes": [{"entry": a, "exit": b}, {"entry": b, "exit": a}]})
    path = OUT / f"scale-{tasks}.json"
    path.write_text(json.dumps({"name": f"uniform-{tasks}-strokes", "states": {"points": pts, "metric": "euclidean"},
                                "tasks": jt}))
    out = OUT / "tmp" / "scale.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [str(towpath), "solve", str(path), "--json", "--time-limit", str(limit), "--seed", "1", "--threads",
           str(threads)]
    # Peak RSS from /usr/bin/time, whose own small process forks towpath: the rusage of a child
    # forked by this (possibly large) Python process would count pages shared before its exec.
    timer = Path("/usr/bin/time")
    if timer.exists():
        cmd = [str(timer), "-f", "maxrss_kb=%M", *cmd]
    m = run_measured(cmd, 10 * limit + 300, out)
    rss = m["rss_mib"]
    err = out.with_suffix(".err").read_text(errors="replace").splitlines()
    for line in err:
        if line.startswith("maxrss_kb="):
            rss = int(line.split("=", 1)[1]) / 1024.0
    res = {"tasks": tasks, "limit": limit, "wall": m["wall"], "cpu": m["cpu"], "rss_mib": rss, "code": m["code"]}
    if m["code"] != 0:
        return res
    doc = json.loads(out.read_text())
    res.update(cost=doc["cost"], solver_time=doc["time_seconds"], iterations=doc["iterations"])
    # Independent re-pricing and a sampled 2-opt check (segment reversal flips the strokes).
    steps = [(int(s["task"][1:]), int(s["mode"])) for s in doc["tour"]]
    seen = {t for t, _ in steps}
    res["feasible"] = len(steps) == tasks and len(seen) == tasks
    ent = [jt[t]["modes"][k]["entry"] for t, k in steps]
    ex = [jt[t]["modes"][k].get("exit") for t, k in steps]

    def d(i: int, j: int) -> float:
        return math.dist(pts[i], pts[j])

    n = len(steps)
    total = sum(d(ex[i], ent[(i + 1) % n]) for i in range(n))
    res["repriced"] = total
    moves, checked, gain = two_opt_scan(pts, ent, ex)
    res.update(improving_2opt_moves=moves, pairs_checked=checked, two_opt_gain=gain)
    return res


def two_opt_scan(pts, ent, ex, near: int = 5) -> tuple[int, int, float]:
    """Counts improving 2-opt moves (reverse the strokes between positions i+1..j, each stroke
    flipped) among candidate pairs: for every position i, the `near` positions j whose stroke
    exit lies closest to i's exit (a bucket grid). Returns (improving moves, pairs checked, sum
    of their gains)."""
    n = len(ent)
    cell = 1000.0 / max(1, int(math.sqrt(n / 2)))
    grid: dict[tuple[int, int], list[int]] = {}
    for j in range(n):
        p = pts[ex[j]]
        grid.setdefault((int(p[0] // cell), int(p[1] // cell)), []).append(j)

    def d(a, b):
        return math.dist(pts[a], pts[b])

    improving, checked, gain = 0, 0, 0.0
    for i in range(n):
        p = pts[ex[i]]
        gx, gy = int(p[0] // cell), int(p[1] // cell)
        cand = [j for dx in (-1, 0, 1) for dy in (-1, 0, 1) for j in grid.get((gx + dx, gy + dy), []) if j != i]
        cand.sort(key=lambda j: d(ex[i], ex[j]))
        for j in cand[:near]:
            a, b = (i, j) if i < j else (j, i)
            if b - a < 2 or (a == 0 and b == n - 1):
                continue
            checked += 1
            delta = (d(ex[a], ex[b]) + d(ent[a + 1], ent[(b + 1) % n])
                     - d(ex[a], ent[a + 1]) - d(ex[b], ent[(b + 1) % n]))
            if delta < -1e-7:
                improving += 1
                gain -= delta
    return improving, checked, gain


# --------------------------------------------------------------------------- orchestration


def load_results(path: Path) -> list[dict]:
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def append_result(path: Path, rec: dict) -> None:
    with open(path, "a") as f:
        f.write(json.dumps(rec) + "\n")


def versions() -> dict[str, str]:
    """Installed versions of the peers (asked of bench/.venv when not running inside it)."""
    code = "from importlib.metadata import version as v; print(' '.join(v(k) for k in %r))" % list(PINS)
    python = sys.executable if in_venv() or not venv_python().exists() else str(venv_python())
    out = subprocess.run([python, "-c", code], capture_output=True, text=True)
    if out.returncode != 0:
        return {}
    return dict(zip(PINS, out.stdout.split()))


def git_commit() -> str:
    out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    dirty = subprocess.run(["git", "status", "--porcelain", "--", "crates"], cwd=ROOT, capture_output=True, text=True)
    return out.stdout.strip() + ("+changes" if dirty.stdout.strip() else "")


def machine() -> str:
    cpu = ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = ""
    try:
        kb = int(Path("/proc/meminfo").read_text().split()[1])
        mem = f", {kb / 1024 / 1024:.0f} GiB RAM"
    except (OSError, ValueError, IndexError):
        pass
    return f"{os.cpu_count()} cores ({cpu}){mem}, {platform.system()} {platform.release()}"


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker_main(sys.argv[2:])
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--instances", type=Path, default=BENCH / "seq_instances.txt")
    ap.add_argument("--data", type=Path, default=None, help="benchmark data folder (with index.csv)")
    ap.add_argument("--time-limit", type=float, default=10.0)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--only", choices=["towpath", "peers"], default=None)
    ap.add_argument("--peers", default=",".join(PEERS), help="comma-separated subset of " + ",".join(PEERS))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--towpath", type=Path, default=None, help="towpath binary (default: cargo build --release)")
    ap.add_argument("--results", type=Path, default=OUT / "seq-results.jsonl")
    ap.add_argument("--resume", action="store_true", help="keep earlier results in --results, run the rest")
    ap.add_argument("--redo", default="", help="with --resume: drop these solvers' earlier results first "
                    "(comma-separated), e.g. `--resume --redo towpath` re-measures towpath and keeps the peers")
    ap.add_argument("--output", type=Path, default=ROOT / "BENCHMARKS.md")
    ap.add_argument("--scale-tasks", type=int, default=100_000)
    ap.add_argument("--scale-time-limit", type=float, default=60.0)
    ap.add_argument("--no-scale", action="store_true")
    ap.add_argument("--scale-only", action="store_true")
    ap.add_argument("--table-only", action="store_true", help="rewrite the table from --results, run nothing")
    args = ap.parse_args()

    peers = [] if args.only == "towpath" else [p for p in args.peers.split(",") if p]
    if peers and not args.table_only and not args.scale_only:
        ensure_venv()
    data = args.data or default_data_dir()
    index = seqlib.load_index(data / "index.csv")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "conv").mkdir(exist_ok=True)
    towpath = args.towpath or (ROOT / "target" / "release" / "towpath" if args.table_only else build_towpath())
    if not args.resume and not args.table_only and not args.scale_only and args.results.exists():
        args.results.rename(args.results.with_suffix(f".{int(time.time())}.bak"))
    redo = {x for x in args.redo.split(",") if x}
    if redo and args.resume and args.results.exists():
        kept = [r for r in load_results(args.results) if r["solver"] not in redo]
        args.results.write_text("".join(json.dumps(r) + "\n" for r in kept))
    # Keyed by path: names repeat across kinds (ESC47 is a SOP and a PCGTSP instance).
    done = {(r["path"], r["solver"], r["run"]) for r in load_results(args.results)
            if r.get("time_limit") == args.time_limit}
    instances = seqlib.read_instance_list(args.instances)
    loads = []
    commit = git_commit()

    if not args.table_only and not args.scale_only:
        # Run-major: a stopped benchmark still has every instance at the runs it finished.
        for run in range(args.runs):
            seed = run + 1
            for rel in instances:
                ref = index.get(rel)
                src = data / rel
                kind = ref.kind if ref else "?"
                name = ref.name if ref else Path(rel).stem
                nat_json = OUT / "conv" / f"{name}.{kind}.json"
                convert(towpath, src, nat_json, matrix=False)
                if ref and ref.dimension ** 2 > MAX_MATRIX_ENTRIES:
                    # too large for an explicit matrix: costs from the coordinates (PointCosts)
                    mat_json = nat_json
                else:
                    mat_json = OUT / "conv" / f"{name}.{kind}.matrix.json"
                    convert(towpath, src, mat_json, matrix=True)
                solvers = [] if args.only == "peers" else ["towpath"]
                solvers += [p for p in peers if args.only != "towpath"]
                if all((rel, s, run) in done for s in solvers):
                    continue
                model = Model.from_json(json.loads(mat_json.read_text()))
                for solver in solvers:
                    if (rel, solver, run) in done:
                        continue
                    rec = {"instance": name, "path": rel, "kind": kind, "solver": solver, "run": run, "seed": seed,
                           "time_limit": args.time_limit, "threads": args.threads, "load1": os.getloadavg()[0],
                           "commit": commit}
                    loads.append(rec["load1"])
                    try:
                        if solver == "towpath":
                            rec.update(run_towpath(towpath, src, args.time_limit, seed, args.threads, model))
                        elif kind not in PEER_KINDS.get(solver, set()):
                            rec.update(cost=None, status="n/a")
                        else:
                            rec.update(run_peer(solver, kind, mat_json, nat_json, args.time_limit, seed,
                                                args.threads, model))
                    except Exception as e:  # noqa: BLE001 - one failure must not stop the benchmark
                        rec.update(cost=None, status=f"harness error: {type(e).__name__}: {e}")
                    append_result(args.results, rec)
                    print(f"{name:>16} {solver:>9} run {run}: cost {rec.get('cost')} "
                          f"time {rec.get('time', 0):.1f}s {rec.get('status', '')} (load {rec['load1']:.1f})",
                          flush=True)

    scale = None
    scale_path = OUT / "scale.json"
    if args.scale_only or (not args.no_scale and not args.table_only and args.only != "peers"):
        scale = scale_check(towpath, args.scale_tasks, args.scale_time_limit, 1, args.threads)
        scale["load1"] = os.getloadavg()[0]
        scale_path.write_text(json.dumps(scale))
        print("scale:", scale, flush=True)
    elif scale_path.exists():
        scale = json.loads(scale_path.read_text())

    write_report(args, index, instances, peers or [p for p in PEERS], scale, data)


def write_report(args, index, instances, peers, scale, data) -> None:
    results = [r for r in load_results(args.results) if r.get("time_limit") == args.time_limit]
    if not results and scale is None:
        return
    by = {}
    for r in results:
        by.setdefault((r["path"], r["solver"]), []).append(r)
    rows = []
    for rel in instances:
        ref = index.get(rel)
        name = ref.name if ref else Path(rel).stem
        cells = {s: seqlib.summarize(by.get((rel, s), [])) for s in ["towpath", *peers]}
        if all(c.note == "not run" for c in cells.values()):
            continue
        rows.append({"name": name, "kind": ref.kind if ref else "?", "n": ref.dimension if ref else "?", "ref": ref,
                     "cells": cells})
    runs = max((r["run"] + 1 for r in results), default=0)
    load_vals = [r["load1"] for r in results if "load1" in r]
    vers = versions()
    tp_version = subprocess.run([str(ROOT / "target" / "release" / "towpath"), "--version"], capture_output=True,
                                text=True).stdout.strip() if (ROOT / "target" / "release" / "towpath").exists() else "?"
    # The commit(s) the measured towpath was built from (recorded with each result).
    git = ", ".join(sorted({r["commit"] for r in results if r.get("commit")})) or git_commit()
    head = [
        f"Generated by `python3 bench/seq.py` on {datetime.date.today().isoformat()}: time limit "
        f"{args.time_limit:g} s, {runs} run(s) per solver and instance (seeds 1..{runs}), medians shown; "
        f"towpath with `--threads {args.threads}`.",
        f"",
        f"- Machine: {machine()}. " + load_note(load_vals),
        f"- Versions: {tp_version} (commit {git}); " + ", ".join(f"{k} {v}" for k, v in vers.items())
        + f"; Python {platform.python_version()}.",
        f"- Instances: `{args.instances.relative_to(ROOT) if args.instances.is_relative_to(ROOT) else args.instances}` "
        f"from the shared benchmark data (`index.csv`); reference = optimum (opt), best known (BKS) or the "
        f"published PCGLNS upper bound (UB). gap % = (cost − reference) / reference. `tp/X` = towpath median "
        f"cost / X median cost (< 1: towpath better).",
        f"- Every answer (towpath's too) is re-priced and checked for feasibility in Python "
        f"(`bench/seqlib.py`) on the matrix written by `towpath convert --matrix`, the same data every solver read.",
        f"- time s = median wall seconds of the solve call (towpath: its own `time_seconds`; peers: the call in a "
        f"worker process, model building included, file loading excluded).",
    ]
    table = seqlib.render_table(rows, peers)
    notes = [
        "",
        "Notes:",
        "- **lkh3** = LKH-3.0.8 inside `elkai` (`elkai._elkai.solve_problem` with raw LKH parameters): one run, "
        "`MAX_TRIALS` unbounded, `TIME_LIMIT` = `TOTAL_TIME_LIMIT` = the time limit. LKH measures these in **CPU "
        "seconds** of its own process and `TOTAL_TIME_LIMIT` includes its preprocessing (the subgradient "
        "ascent), so under load its wall time exceeds the limit; its actual wall time is shown. TSP instances "
        "with TSPLIB coordinates are given to LKH as coordinates (its Delaunay/alpha candidates), others as a full "
        "matrix. GTSP goes through the Noon–Bean transformation to an ATSP (`seqlib.noon_bean`), decoded by "
        "the entry node of each set. **SOP and PCGTSP: n/a** — elkai 2.0.1's in-memory reader crashes on "
        "`TYPE: SOP` (it reads the SOP dimension line from a null file: segfault in `Read_EDGE_WEIGHT_SECTION`), "
        "and LKH-3 has no precedence-constrained GTSP type.",
        "- † LKH-3 produced no tour within `TOTAL_TIME_LIMIT` (its preprocessing alone exceeded the limit) and was "
        "re-run with `TIME_LIMIT` only, which does not limit the preprocessing: its cost is then not at the same "
        "budget; see its time column.",
        "- PCGTSP references are the `index.csv` upper bounds (one PCGLNS heuristic run each), not optima: "
        "negative gaps mean a better tour than that run. MIP-proven optima published with the same instances "
        "(ukoloff/PCGTSP-BnB `Salman/output`, priced by towpath's model in "
        "`crates/towpath-formats/tests/shared_data.rs`, ESC25 in the fixtures): ESC25 1383, ESC47 1063, prob.42 202.",
        "- **fast-tsp** `find_tour(matrix, duration_seconds=limit, max_threads=threads)`: symmetric TSP only "
        "(its documentation: the local search relies on symmetry), so ATSP/SOP/GTSP/PCGTSP are n/a. Its time "
        "column is the worker's wall time, which includes turning the Python matrix into a numpy array (seconds "
        "at 4000+ nodes); `find_tour` itself keeps to the limit (10.0 s in each of 9 runs timed around the call "
        "alone on 2026-12-03), and the raw results give that time in each run's note.",
        "- **ortools** routing with `GUIDED_LOCAL_SEARCH` and the time limit, one thread: TSP/ATSP directly; SOP as "
        "a path from node 1 to node n with an order dimension and `cumul(a) < cumul(b)` for every precedence pair; "
        "GTSP/PCGTSP with one `AddDisjunction(set, penalty, 1)` per set, one vehicle per node of the anchor set "
        "(PCGLNS start set, else the smallest set) ending at a copy of its start node so the closing move is priced, "
        "a large fixed cost per used vehicle, and for PCGTSP the order dimension with set positions "
        "Σ active·cumul and `pos(A) < pos(B)` per set precedence. Under precedence (SOP, PCGTSP) OR-Tools' "
        "first-solution strategies (`LOCAL_CHEAPEST_INSERTION`, `PATH_CHEAPEST_ARC`) returned no route on ESC47 "
        "and ESC25 when tried, so its search starts from a topological order (`ReadAssignmentFromRoutes`), a "
        "feasible route.",
    ]
    body = "\n".join(head) + "\n\n" + table + "\n" + "\n".join(notes) + "\n"
    if scale:
        ok = scale.get("code") == 0 and scale.get("feasible")
        body += (
            "\n**Scale check** (target: feasible, 2-opt-local-optimal within 60 s and under 2 GiB): "
            f"{scale['tasks']:,} random uniform Euclidean strokes in a 1000×1000 square, two modes each (both "
            f"directions), towpath JSON with coordinates, `towpath solve --time-limit {scale['limit']:g} "
            f"--threads {args.threads}`: "
            + (f"feasible, cost {scale['cost']:.1f} (re-priced {scale['repriced']:.1f}), process wall "
               f"{scale['wall']:.1f} s (solver {scale['solver_time']:.1f} s, CPU {scale['cpu']:.1f} s), peak RSS "
               f"{scale['rss_mib']:.0f} MiB; 2-opt check in Python (every position against the 5 strokes whose exits "
               f"are nearest): {scale['improving_2opt_moves']} improving moves among {scale['pairs_checked']:,} "
               f"pairs (gains summing to {scale.get('two_opt_gain', 0):.1f}, "
               f"{100 * scale.get('two_opt_gain', 0) / scale['cost']:.2f} % of the cost)"
               + (", so **not** 2-opt-local-optimal" if scale['improving_2opt_moves'] else ", 2-opt-local-optimal on them")
               + f"; load average {scale.get('load1', 0):.1f}."
               if ok else f"failed (exit {scale.get('code')}, wall {scale['wall']:.1f} s).")
            + "\n"
        )
    text = args.output.read_text() if args.output.exists() else "# Benchmarks\n"
    args.output.write_text(seqlib.replace_between_markers(text, body, "## Sequencing: towpath vs LKH-3, fast-tsp, OR-Tools"))
    print(f"wrote {args.output}", flush=True)


if __name__ == "__main__":
    main()
