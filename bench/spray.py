#!/usr/bin/env python3
"""Spray forming benchmark (run by hand, not in CI).

Runs `towpath spray` on a flat plate, a closed box, a cylinder section, a sphere cap and an
aircraft mesh, then RE-SIMULATES the written poses with its own code (a numpy re-implementation
of the spray-cone deposition model of docs/spray.md, written from the formulas, not from the
crate) on the welded mesh the run wrote into its thickness PLY. It reports thickness RMS over
the interior (an edge band one spray radius wide left out), coverage (area share within +-20 %
of the target, triangles that received nothing), travel and cycle time against Tewolde & Sheng
(2008)'s GA / ACO1 / ACO2 on the same passes, and against a plain single-direction plane-slicer
raster without partition (`--pattern slicer`); then times a 200k-triangle part. Timings are
medians of --repeats runs (wall and CPU time of the child process). Writes the "Spray forming"
section of BENCHMARKS.md and bench/out/spray/results.json.

    python3 bench/spray.py [--repeats 3] [--no-write]
"""
import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "bench", "out", "spray")
VENV = os.path.join(ROOT, "bench", ".venv")
BIN = os.path.join(ROOT, "target", "release", "towpath")
SECTION = "## Spray forming (towpath spray)"
MESHES = "/work/shared/data/meshes"


def ensure_numpy():
    try:
        import numpy  # noqa: F401
        return
    except ImportError:
        pass
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
    subprocess.check_call([py, "-m", "pip", "install", "-q", "numpy"])
    os.execv(py, [py] + sys.argv)


# ---------------------------------------------------------------- test parts

def box_stl(path, a, b, c, cell):
    """A closed box [0,a]x[0,b]x[0,c] as ASCII STL, each face a grid of about `cell` squares."""
    faces = [
        ((0, 0, 0), (0, b, 0), (a, 0, 0)),
        ((0, 0, c), (a, 0, 0), (0, b, 0)),
        ((0, 0, 0), (a, 0, 0), (0, 0, c)),
        ((0, b, 0), (0, 0, c), (a, 0, 0)),
        ((0, 0, 0), (0, 0, c), (0, b, 0)),
        ((a, 0, 0), (0, b, 0), (0, 0, c)),
    ]
    out = ["solid box"]
    for o, u, v in faces:
        lu = math.sqrt(sum(x * x for x in u))
        lv = math.sqrt(sum(x * x for x in v))
        nu, nv = max(1, round(lu / cell)), max(1, round(lv / cell))

        def p(i, j):
            return tuple(o[k] + u[k] * i / nu + v[k] * j / nv for k in range(3))

        for j in range(nv):
            for i in range(nu):
                for tri in ((p(i, j), p(i + 1, j), p(i + 1, j + 1)), (p(i, j), p(i + 1, j + 1), p(i, j + 1))):
                    out.append(" facet normal 0 0 0\n  outer loop")
                    out += ["   vertex %.9g %.9g %.9g" % q for q in tri]
                    out.append("  endloop\n endfacet")
    out.append("endsolid box")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")


def read_ply(path):
    """The ASCII PLY the run wrote: vertices, faces, the crate's per-vertex thickness."""
    import numpy as np
    with open(path) as fh:
        nv = nf = 0
        while True:
            line = fh.readline().strip()
            if line.startswith("element vertex"):
                nv = int(line.split()[2])
            elif line.startswith("element face"):
                nf = int(line.split()[2])
            elif line == "end_header":
                break
        v = np.loadtxt(fh, max_rows=nv, ndmin=2)
        f = np.loadtxt(fh, max_rows=nf, dtype=np.int64, ndmin=2)[:, 1:4]
    return v[:, :3], f, v[:, 3]


# ---------------------------------------------------------------- deposition (own code)

def profile_q(kind, value, R, r2):
    """Flux per unit area normalised to one over the footprint disk (docs/spray.md section 2)."""
    import numpy as np
    inside = r2 < R * R
    if kind == "beta":
        B = value
        q = B / (math.pi * R * R) * np.power(np.clip(1.0 - r2 / (R * R), 0.0, None), B - 1.0)
    else:
        s2 = 2.0 * value * value
        q = np.exp(-r2 / s2) / (math.pi * s2 * (1.0 - math.exp(-R * R / s2)))
    return np.where(inside, q, 0.0)


def spray_steps(poses, R, h, step_frac=16.0):
    """Cuts every spray segment into steps of at most R/step_frac: midpoint, axis, duration."""
    import numpy as np
    G, A, T = [], [], []
    for p0, p1 in zip(poses, poses[1:]):
        if not p0["spray"]:
            continue
        dt = p1["time"] - p0["time"]
        if dt <= 0:
            continue
        g0, g1 = np.array(p0["position"]), np.array(p1["position"])
        a0, a1 = np.array(p0["axis"]), np.array(p1["axis"])
        ang = math.acos(max(-1.0, min(1.0, float(a0 @ a1))))
        n = max(1, int(math.ceil(max(np.linalg.norm(g1 - g0), ang * h) / (R / step_frac))))
        s = (np.arange(n) + 0.5) / n
        G.append(g0[None, :] * (1 - s[:, None]) + g1[None, :] * s[:, None])
        a = a0[None, :] * (1 - s[:, None]) + a1[None, :] * s[:, None]
        A.append(a / np.linalg.norm(a, axis=1)[:, None])
        T.append(np.full(n, dt / n))
    if not G:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0)
    return np.vstack(G), np.vstack(A), np.concatenate(T)


def deposit(points, normals, gun, poses):
    """Thickness (um) at `points` with unit `normals` left by the path."""
    import numpy as np
    h, R, F = gun["standoff"], gun["radius"], gun["flow"]
    prof = gun["profile"]
    kind = prof["kind"]
    value = prof["beta"] if kind == "beta" else prof["sigma"]
    G, A, T = spray_steps(poses, R, h)
    out = np.zeros(len(points))
    chunk = 48
    for c0 in range(0, len(G), chunk):
        g, a, dt = G[c0:c0 + chunk], A[c0:c0 + chunk], T[c0:c0 + chunk]
        # Points the chunk can reach: within 2h along the axis, 2R across.
        lo = np.minimum(g, g + 2 * h * a).min(axis=0) - 2 * R
        hi = np.maximum(g, g + 2 * h * a).max(axis=0) + 2 * R
        sel = np.nonzero(np.all((points >= lo) & (points <= hi), axis=1))[0]
        if len(sel) == 0:
            continue
        P, N = points[sel], normals[sel]
        v = P[:, None, :] - g[None, :, :]                  # (k, m, 3)
        z = np.einsum("kmj,mj->km", v, a)
        vv = np.einsum("kmj,kmj->km", v, v)
        ok = (z > 0) & (z <= 2 * h)
        zs = np.where(ok, z, 1.0)
        r_eq2 = np.clip(vv - zs * zs, 0, None) * (h / zs) ** 2
        vn = -np.einsum("kmj,kj->km", v, N)
        q = profile_q(kind, value, R, r_eq2)
        rate = 1000.0 * F * q * (h / zs) ** 2 * np.clip(vn, 0, None) / zs
        rate = np.where(ok, rate, 0.0)
        out[sel] += rate @ dt
    return out


def sample_points(V, Fc, k=3):
    """Points inside every triangle: centroids of a k x k subdivision, each with its area share."""
    import numpy as np
    a, b, c = V[Fc[:, 0]], V[Fc[:, 1]], V[Fc[:, 2]]
    cr = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cr, axis=1)
    nrm = cr / np.maximum(2 * area, 1e-300)[:, None]
    bary = []
    for i in range(k):
        for j in range(k - i):
            bary.append(((3 * i + 1) / (3 * k), (3 * j + 1) / (3 * k)))
            if i + j + 2 <= k:
                bary.append(((3 * i + 2) / (3 * k), (3 * j + 2) / (3 * k)))
    pts, nrms, w, face = [], [], [], []
    for u, v in bary:
        pts.append(a + (b - a) * u + (c - a) * v)
        nrms.append(nrm)
        w.append(area / len(bary))
        face.append(np.arange(len(Fc)))
    return np.vstack(pts), np.vstack(nrms), np.concatenate(w), np.concatenate(face)


def boundary_band(V, Fc, points, band):
    """Points within `band` of a boundary edge (an edge used by one face)."""
    import numpy as np
    e = np.vstack([Fc[:, [0, 1]], Fc[:, [1, 2]], Fc[:, [2, 0]]])
    key = np.sort(e, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    bnd = key[cnt[inv.ravel()] == 1]
    mask = np.zeros(len(points), dtype=bool)
    if len(bnd) == 0:
        return mask
    A, B = V[bnd[:, 0]], V[bnd[:, 1]]
    for s in range(0, len(A), 256):
        a, b = A[s:s + 256], B[s:s + 256]
        lo = np.minimum(a, b).min(axis=0) - band
        hi = np.maximum(a, b).max(axis=0) + band
        sel = np.nonzero(np.all((points >= lo) & (points <= hi), axis=1) & ~mask)[0]
        if len(sel) == 0:
            continue
        p = points[sel][:, None, :]
        ab = (b - a)[None, :, :]
        t = np.clip(np.einsum("kmj,kmj->km", p - a[None], ab) / np.maximum(np.einsum("kmj,kmj->km", ab, ab), 1e-300), 0, 1)
        d2 = np.einsum("kmj,kmj->km", p - a[None] - t[..., None] * ab, p - a[None] - t[..., None] * ab)
        mask[sel] |= (d2 < band * band).any(axis=1)
    return mask


def evaluate(run, target):
    """Re-simulates a run's path on its mesh; path totals from the poses."""
    import numpy as np
    doc = json.load(open(run["path"]))
    V, Fc, _ = read_ply(run["ply"])
    gun, poses = doc["gun"], doc["poses"]
    P, N, W, face = sample_points(V, Fc)
    t = deposit(P, N, gun, poses)
    band = boundary_band(V, Fc, P, gun["radius"])
    keep = ~band
    if not keep.any():
        keep = np.ones(len(P), dtype=bool)
    w = W[keep]
    mean = float((t[keep] * w).sum() / w.sum())
    rms = float(math.sqrt(((t[keep] - mean) ** 2 * w).sum() / w.sum()) / mean) if mean > 0 else float("nan")
    within = float(W[np.abs(t - target) <= 0.2 * target].sum() / W.sum())
    within_int = float(w[np.abs(t[keep] - target) <= 0.2 * target].sum() / w.sum())
    bare = np.zeros(len(Fc), dtype=bool)
    bare[face[t < 0.01 * target]] = True
    travel = spray = 0.0
    for p0, p1 in zip(poses, poses[1:]):
        d = float(np.linalg.norm(np.array(p1["position"]) - np.array(p0["position"])))
        if p0["spray"]:
            spray += d
        else:
            travel += d
    times = [p["time"] for p in poses]
    return {
        "mean": mean, "min": float(t[keep].min()), "max": float(t[keep].max()), "rms_rel": rms,
        "within20_all": within, "within20_interior": within_int, "bare_triangles": int(bare.sum()),
        "triangles": int(len(Fc)), "travel": travel, "gun_spray_length": spray,
        "cycle": times[-1] if times else 0.0, "monotone": all(b > a for a, b in zip(times, times[1:])),
    }


# ---------------------------------------------------------------- runs

def run_towpath(name, surface, opts, tag, repeats):
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, f"{name}_{tag}.json")
    ply = os.path.join(OUT, f"{name}_{tag}.ply")
    cmd = [BIN, "spray", surface, *opts, "-o", path, "--thickness-map", ply, "--json"]
    walls, cpus, summary = [], [], None
    for _ in range(repeats):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        res = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        if res.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stderr}")
        walls.append(wall)
        cpus.append((r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
        summary = json.loads(res.stdout)
    return {"cmd": cmd, "path": path, "ply": ply, "summary": summary,
            "wall": statistics.median(walls), "cpu": statistics.median(cpus), "walls": walls}


def path_travel(path):
    """Travel (spray off) summed from a written path's poses, with this script's own code."""
    poses = json.load(open(path))["poses"]
    return sum(math.dist(p0["position"], p1["position"]) for p0, p1 in zip(poses, poses[1:]) if not p0["spray"])


def seed_runs(name, surface, opts, tag, extra, seeds):
    """Runs one solver with seeds 1..seeds: travel from the written poses and solver time."""
    path = os.path.join(OUT, f"{name}_{tag}_seed.json")
    travel, seconds = [], []
    for seed in range(1, seeds + 1):
        cmd = [BIN, "spray", surface, *opts, *extra, "--seed", str(seed), "-o", path, "--json"]
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stderr}")
        travel.append(path_travel(path))
        seconds.append(json.loads(res.stdout)["solver_seconds"])
    return {"travel": travel, "seconds": seconds}


CASES = [
    # name, surface, options, target (um)
    ("plate", "plane:a=600,b=400", ["--standoff", "200", "--spray-radius", "50"], 20.0),
    ("box", "@box", ["--standoff", "200", "--spray-radius", "50", "--home", "300,200,900"], 20.0),
    ("cylinder", "cylinder:r=300,l=600,a0=0,a1=120", ["--standoff", "200", "--spray-radius", "50", "--max-deviation", "15"], 20.0),
    ("sphere_cap", "sphere:r=400,lat0=30,lat1=90", ["--standoff", "200", "--spray-radius", "50", "--max-deviation", "15"], 20.0),
    # The wing-and-tail mesh is in feet-scale units (about 6 units long): gun and run-out in the
    # same units; thickness and flow keep their units (mm3/s per mm becomes per unit).
    ("swept_wing", os.path.join(MESHES, "swept_wing_and_tail.stl"),
     ["--standoff", "0.8", "--spray-radius", "0.2", "--flow", "1", "--max-deviation", "20"], 20.0),
]


def flow_target(opts, target):
    return ["--target-thickness", str(target), *opts, "--threads", "2"]


def sensitivity():
    """Sphere cap: thickness (re-simulated) by beta_th and pattern."""
    os.makedirs(OUT, exist_ok=True)
    rows = ["| β_th | pattern | patches | passes | patterns | RMS (interior) | within ±20 % (interior) | cycle s |",
            "|---|---|---|---|---|---|---|---|"]
    for beta in ("15", "20", "30", "45"):
        for pat in ("auto", "zigzag"):
            opts = ["--standoff", "200", "--spray-radius", "50", "--max-deviation", beta, "--pattern", pat]
            r = run_towpath("sens", "sphere:r=400,lat0=30,lat1=90", flow_target(opts, 20.0), f"{beta}_{pat}", 1)
            ev = evaluate(r, 20.0)
            s = r["summary"]
            pats = ", ".join(f"{k} {v}" for k, v in sorted(s["patterns"].items()))
            rows.append(f"| {beta}° | {pat} | {s['patches']} | {s['passes']} | {pats} | {100 * ev['rms_rel']:.2f} % | "
                        f"{100 * ev['within20_interior']:.2f} % | {ev['cycle']:.1f} |")
            print(rows[-1], flush=True)
    with open(os.path.join(OUT, "sensitivity.md"), "w") as fh:
        fh.write("\n".join(rows) + "\n")


def fmt(x, nd=2):
    return "—" if x is None else f"{x:.{nd}f}"


def main():
    ensure_numpy()
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=5,
                    help="seeds per solver for the travel/solver-time comparison (medians)")
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--only", default=None)
    ap.add_argument("--sensitivity", action="store_true",
                    help="only the sphere-cap study of beta_th x pattern, to bench/out/spray/sensitivity.md")
    args = ap.parse_args()
    if args.sensitivity:
        sensitivity()
        return
    if not os.path.exists(BIN):
        subprocess.check_call(["cargo", "build", "--release", "-p", "towpath"], cwd=ROOT)
    os.makedirs(OUT, exist_ok=True)
    box = os.path.join(OUT, "box.stl")
    box_stl(box, 600, 400, 300, 25)
    load_before = open("/proc/loadavg").read().split()[:3]
    results = {}
    for name, surface, opts, target in CASES:
        if args.only and name not in args.only.split(","):
            continue
        surface = box if surface == "@box" else surface
        base = flow_target(opts, target)
        row = {}
        for tag, extra in [("towpath", []), ("ga", ["--solver", "ga", "--time-limit", "600"]),
                           ("aco1", ["--solver", "aco1", "--time-limit", "600"]),
                           ("aco2", ["--solver", "aco2", "--time-limit", "600"]),
                           ("plain", ["--max-speed-change", "1"]),
                           ("slicer", ["--pattern", "slicer", "--max-speed-change", "1"])]:
            reps = args.repeats if tag in ("towpath", "slicer") else 1
            r = run_towpath(name, surface, base + extra, tag, reps)
            ev = evaluate(r, target)
            s = r["summary"]
            row[tag] = {"wall": r["wall"], "cpu": r["cpu"], "walls": r["walls"], "eval": ev,
                        "crate": {k: s.get(k) for k in ("patches", "passes", "spray_length_mm", "travel_mm", "turns",
                                                      "cycle_time_s", "thickness", "solver_seconds", "mesh_triangles",
                                                      "patterns", "timings", "total_seconds", "thickness_seconds")}}
            print(f"{name:11s} {tag:8s} patches {s['patches']:4d} passes {s['passes']:5d} travel {ev['travel']:9.1f} "
                  f"cycle {ev['cycle']:7.1f} s  RMS {100 * ev['rms_rel']:6.2f} % (crate {100 * s['thickness']['rms_rel']:6.2f} %) "
                  f"within20 {100 * ev['within20_interior']:6.2f} %/{100 * ev['within20_all']:6.2f} % bare {ev['bare_triangles']} "
                  f"solver {s['solver_seconds']:.3f} s wall {r['wall']:.2f} s cpu {r['cpu']:.2f} s", flush=True)
        row["seeds"] = {}
        for tag, extra in [("towpath", []), ("ga", ["--solver", "ga", "--time-limit", "600"]),
                           ("aco1", ["--solver", "aco1", "--time-limit", "600"]),
                           ("aco2", ["--solver", "aco2", "--time-limit", "600"])]:
            sr = seed_runs(name, surface, base, tag, extra, args.seeds)
            row["seeds"][tag] = sr
            print(f"{name:11s} {tag:8s} seeds 1-{args.seeds}: travel median {statistics.median(sr['travel']):9.2f} "
                  f"(max {max(sr['travel']):9.2f}) solver median {1e3 * statistics.median(sr['seconds']):9.3f} ms", flush=True)
        results[name] = row
    # Speed: 200k triangles.
    speed = {}
    if not args.only or "speed" in args.only.split(","):
        for name, surface, opts in [
            ("sphere_cap_200k", "sphere:r=400,lat0=30,lat1=90", ["--standoff", "200", "--spray-radius", "50", "--max-deviation", "15"]),
            ("plate_200k", "plane:a=600,b=400", ["--standoff", "200", "--spray-radius", "50"]),
        ]:
            r = run_towpath(name, surface, flow_target(opts, 20.0) + ["--triangles", "200000"], "speed", args.repeats)
            s = r["summary"]
            speed[name] = {"wall": r["wall"], "cpu": r["cpu"], "walls": r["walls"], "triangles": s["mesh_triangles"],
                           "timings": s["timings"], "load_seconds": s["load_seconds"],
                           "thickness_seconds": s["thickness_seconds"], "total_seconds": s["total_seconds"],
                           "patches": s["patches"], "passes": s["passes"]}
            print(f"{name}: {s['mesh_triangles']} triangles, wall {r['wall']:.2f} s (runs {', '.join(f'{w:.2f}' for w in r['walls'])}), "
                  f"cpu {r['cpu']:.2f} s, inside: {s['total_seconds']:.2f} s (load {s['load_seconds']:.2f}, "
                  f"thickness {s['thickness_seconds']:.2f}, {s['timings']})", flush=True)
    load_after = open("/proc/loadavg").read().split()[:3]
    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    results["_speed"] = speed
    results["_load"] = {"before": load_before, "after": load_after, "uptime": uptime}
    with open(os.path.join(OUT, "results.json"), "w") as fh:
        json.dump(results, fh, indent=1)
    if not args.no_write:
        write_section(results, args.repeats, args.seeds)


def write_section(res, repeats, seeds):
    L = [SECTION, ""]
    ld = res["_load"]
    L.append("`python3 bench/spray.py` (numpy re-simulation of the written poses with its own deposition code, "
             "on the welded mesh of each run's thickness PLY; sample points inside every triangle, edge band one "
             f"spray radius wide left out of RMS). Timings: median of {repeats} runs of the towpath and slicer "
             "configurations (GA/ACO once, seed 1), wall and CPU time of the process. The machine (2 cores) was shared "
             f"with other engineers' builds: load average {' '.join(ld['before'])} before, "
             f"{' '.join(ld['after'])} after (`{ld['uptime']}`); wall times are inflated accordingly, CPU "
             "times less so. Gun: standoff 200 mm, R 50 mm, beta = 2, 500 mm3/s, target 20 um, "
             "solver default budget (towpath_seq::solve_reversible: 15 improvement kicks per pass, at least 100, stopping "
             "after 3/20 of the budget without improvement but not before as many kicks again as the best took; 1 s "
             "time limit), speed modulation on (`--max-speed-change 3`, the default) except in the "
             "'without modulation' column (`--max-speed-change 1`) and for the slicer (a plain plane slicer has none), "
             "`--threads 2` (wing: standoff 0.8, R 0.2 in the mesh's units).")
    L.append("")
    L.append("### Thickness and coverage (re-simulated)")
    L.append("")
    L.append("| part | tris | patches | passes | mean um | RMS (interior) | within ±20 % interior / all | bare tris | crate RMS | without modulation: RMS, within ±20 % | slicer RMS | slicer within ±20 % |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, row in res.items():
        if name.startswith("_"):
            continue
        t, sl, pl = row["towpath"], row["slicer"], row["plain"]["eval"]
        e, c = t["eval"], t["crate"]
        L.append(f"| {name} | {e['triangles']} | {c['patches']} | {c['passes']} | {fmt(e['mean'])} | {fmt(100 * e['rms_rel'])} % | "
                 f"{fmt(100 * e['within20_interior'])} / {fmt(100 * e['within20_all'])} % | {e['bare_triangles']} | "
                 f"{fmt(100 * c['thickness']['rms_rel'])} % | {fmt(100 * pl['rms_rel'])} %, {fmt(100 * pl['within20_interior'])} % | "
                 f"{fmt(100 * sl['eval']['rms_rel'])} % | "
                 f"{fmt(100 * sl['eval']['within20_interior'])} % |")
    L.append("")
    L.append("### Integration: travel and time against GA / ACO1 / ACO2 and the plane slicer")
    L.append("")
    L.append("Seed 1. Travel (mm, spray off, summed from the written poses), cycle time (s), solver time (ms).")
    L.append("")
    L.append("| part | towpath travel | GA | ACO1 | ACO2 | towpath solver ms | GA ms | ACO1 ms | ACO2 ms | best paper / towpath time | cycle s towpath | cycle s slicer | wall s (cpu s) towpath | wall s slicer |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, row in res.items():
        if name.startswith("_"):
            continue
        tw = row["towpath"]
        tr = {k: row[k]["eval"]["travel"] for k in ("towpath", "ga", "aco1", "aco2")}
        ss = {k: row[k]["crate"]["solver_seconds"] for k in ("towpath", "ga", "aco1", "aco2")}
        best = min(("ga", "aco1", "aco2"), key=lambda k: tr[k])
        ratio = ss[best] / ss["towpath"] if ss["towpath"] > 0 else float("inf")
        L.append(f"| {name} | {tr['towpath']:.0f} | {tr['ga']:.0f} | {tr['aco1']:.0f} | {tr['aco2']:.0f} | {1e3 * ss['towpath']:.3f} | "
                 f"{1e3 * ss['ga']:.3f} | {1e3 * ss['aco1']:.3f} | {1e3 * ss['aco2']:.3f} | {ratio:.1f}x ({best}) | {tw['eval']['cycle']:.1f} | "
                 f"{row['slicer']['eval']['cycle']:.1f} | {tw['wall']:.2f} ({tw['cpu']:.2f}) | {row['slicer']['wall']:.2f} |")
    L.append("")
    L.append(f"### Integration over seeds 1-{seeds}: medians (the solvers are randomised)")
    L.append("")
    L.append("Travel from the written poses (median, and the worst seed in brackets) and solver time (median, "
             "milliseconds, summed over the pricing rounds). 'Best paper' is the paper solver with the lowest "
             "median travel; the speed ratio is its median solver time over towpath's.")
    L.append("")
    L.append("| part | passes | towpath travel | GA | ACO1 | ACO2 | towpath ms | GA ms | ACO1 ms | ACO2 ms | best paper | travel towpath / best | best paper time / towpath |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, row in res.items():
        if name.startswith("_") or "seeds" not in row:
            continue
        sd = row["seeds"]
        med = {k: statistics.median(sd[k]["travel"]) for k in sd}
        worst = {k: max(sd[k]["travel"]) for k in sd}
        ms = {k: 1e3 * statistics.median(sd[k]["seconds"]) for k in sd}
        best = min(("ga", "aco1", "aco2"), key=lambda k: (med[k], ms[k]))
        cells = " | ".join(f"{med[k]:.1f} ({worst[k]:.1f})" for k in ("towpath", "ga", "aco1", "aco2"))
        times = " | ".join(f"{ms[k]:.3f}" for k in ("towpath", "ga", "aco1", "aco2"))
        L.append(f"| {name} | {row['towpath']['crate']['passes']} | {cells} | {times} | {best} | "
                 f"{med['towpath'] / med[best]:.3f} | {ms[best] / ms['towpath']:.1f}x |")
    L.append("")
    if res.get("_speed"):
        L.append("### Speed: 200k triangles (partition, passes, sequencing, thickness map)")
        L.append("")
        L.append("| part | triangles | patches | passes | wall s (median) | runs | CPU s | in-process total s | load s | partition s | passes s | sequence s | thickness s |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for name, s in res["_speed"].items():
            tm = s["timings"]
            L.append(f"| {name} | {s['triangles']} | {s['patches']} | {s['passes']} | {s['wall']:.2f} | {', '.join(f'{w:.2f}' for w in s['walls'])} | "
                     f"{s['cpu']:.2f} | {s['total_seconds']:.2f} | {s['load_seconds']:.2f} | {tm['partition_s']:.2f} | {tm['passes_s']:.2f} | "
                     f"{tm['sequence_s']:.2f} | {s['thickness_seconds']:.2f} |")
        L.append("")
    text = "\n".join(L) + "\n"
    bm = os.path.join(ROOT, "BENCHMARKS.md")
    cur = open(bm).read()
    if SECTION in cur:
        start = cur.index(SECTION)
        nxt = cur.find("\n## ", start + len(SECTION))
        notes_marker = "<!-- spray notes -->"
        keep_notes = ""
        block = cur[start:nxt if nxt >= 0 else len(cur)]
        if notes_marker in block:
            keep_notes = block[block.index(notes_marker):].rstrip() + "\n"
        cur = cur[:start] + text + ("\n" + keep_notes if keep_notes else "") + (cur[nxt + 1:] if nxt >= 0 else "")
    else:
        cur = cur.rstrip() + "\n\n" + text
    with open(bm, "w") as fh:
        fh.write(cur)


if __name__ == "__main__":
    main()
