#!/usr/bin/env python3
"""Nested-part sheets: `towpath order` against u-nesting-cutting (issue 22).

u-nesting-cutting (crates.io, iyulab/U-Nesting) orders the contours of a nesting result holes
first with nearest neighbour and constrained 2-opt. Its side is the standalone crate in
bench/unesting/ (built here with `cargo build --release`, its own workspace), which reads the
sheet's JSON, hands u-nesting-cutting a nesting result with one fixed placement per part at
(0, 0) (the parts' polygons are already in sheet coordinates) and writes the order it chose.
towpath reads the same polygons from an SVG (one closed `<path>` per contour, viewBox = sheet
millimetres) and writes the ordered SVG: `towpath order IN.svg -o OUT.svg --json`, defaults.

Stdlib only. Every rapid length here is measured by this script from the written outputs
(towpath: the ordered SVG, each closed path entered and left at its first point;
u-nesting-cutting: the pierce point of each step, where its closed contour is entered and left):
from the origin (0, 0), which is both tools' default start, to the first entry, then from
contour to contour; the return to the origin is not counted (neither tool counts it). Each
output is checked: every contour exactly once, each entry point on its contour (towpath: the
written path is the input contour, re-started), and how many holes come after their part's
outer contour (violations).

    python3 bench/unesting.py [--runs 3] [--sizes 50,200,1000] [--diagnostics] [--write-markdown]

--diagnostics adds a second table (one run per cell, same measuring and checks): u-nesting-cutting
with nearest neighbour only (--max-2opt-iterations 0) and with no wall-clock limit on its 2-opt
(--time-limit-ms 0; sheets of at most 200 parts, its passes are cubic), and towpath with
--time-limit 0.5, 2 and 5 s at seeds 1, 2, 3 (median, min-max).
"""

import argparse
import json
import math
import os
import random
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from order import replace_between  # bench/order.py (stdlib only at import)

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "bench" / "out" / "unesting"
TOWPATH = ROOT / "target" / "release" / "towpath"
PEER_DIR = ROOT / "bench" / "unesting"
PEER = PEER_DIR / "target" / "release" / "unesting-peer"


# ---------------------------------------------------------------- sheets

def circle(cx, cy, r, n):
    return [(cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n)) for k in range(n)]


def rect(x0, y0, w, h):
    return [(x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h)]


def hole_in_cell(rng, x0, y0, w, h):
    """A round (16-gon) or rectangular hole well inside the cell."""
    cx, cy = x0 + w / 2, y0 + h / 2
    if rng.random() < 0.5:
        return circle(cx, cy, 0.32 * min(w, h), 16)
    hw, hh = 0.6 * w, 0.6 * h
    return rect(cx - hw / 2, cy - hh / 2, hw, hh)


def cells(x0, y0, w, h, k):
    """k cells splitting a box: a 2 × 2 grid for 4, else a row along the longer side."""
    if k == 4:
        return [(x0 + i * w / 2, y0 + j * h / 2, w / 2, h / 2) for j in range(2) for i in range(2)]
    if w >= h:
        return [(x0 + i * w / k, y0, w / k, h) for i in range(k)]
    return [(x0, y0 + i * h / k, w, h / k) for i in range(k)]


def make_part(rng, x0, y0, w, h):
    """(outer, holes) inside the box (x0, y0, w, h): a rectangle, an L or a circle (48-gon)
    with 0-4 holes."""
    k = rng.randint(0, 4)
    kind = rng.random()
    holes = []
    if kind < 0.4:
        outer = rect(x0, y0, w, h)
        m = 0.12 * min(w, h)
        holes = [hole_in_cell(rng, *c) for c in cells(x0 + m, y0 + m, w - 2 * m, h - 2 * m, k)] if k else []
    elif kind < 0.75:
        a, b = rng.uniform(0.4, 0.6), rng.uniform(0.45, 0.6)
        outer = [(x0, y0), (x0 + w, y0), (x0 + w, y0 + h * b), (x0 + w * a, y0 + h * b), (x0 + w * a, y0 + h), (x0, y0 + h)]
        m = 0.1 * min(w, h * b)
        holes = [hole_in_cell(rng, *c) for c in cells(x0 + m, y0 + m, w - 2 * m, h * b - 2 * m, k)] if k else []
    else:
        r = min(w, h) / 2
        cx, cy = x0 + w / 2, y0 + h / 2
        outer = circle(cx, cy, r, 48)
        if k:
            holes.append(circle(cx, cy, 0.25 * r, 16))
            for i in range(k - 1):
                t = 2 * math.pi * i / (k - 1) + 0.3
                holes.append(circle(cx + 0.62 * r * math.cos(t), cy + 0.62 * r * math.sin(t), 0.15 * r, 12))
    rnd = lambda ring: [(round(x, 4), round(y, 4)) for x, y in ring]
    return rnd(outer), [rnd(h) for h in holes]


def make_sheet(n, seed, gap=4.0):
    """n parts of 20-110 mm, shelf-packed left to right, rows bottom to top, with a gap."""
    rng = random.Random(seed)
    boxes = [(rng.uniform(20, 110), rng.uniform(20, 110)) for _ in range(n)]
    area = sum((w + gap) * (h + gap) for w, h in boxes)
    width = round(math.sqrt(area * 1.3) / 10) * 10
    parts = []
    x, y, row_h = gap, gap, 0.0
    for i, (w, h) in enumerate(boxes):
        if x + w + gap > width:
            x, y, row_h = gap, y + row_h + gap, 0.0
        outer, holes = make_part(rng, x, y, w, h)
        parts.append({"id": f"p{i}", "outer": outer, "holes": holes})
        x += w + gap
        row_h = max(row_h, h)
    height = math.ceil((y + row_h + gap) / 10) * 10
    return {"width": width, "height": height, "parts": parts}


def contours_of(sheet):
    """{name: ring} for every contour; names as the peer and the SVG use them."""
    out = {}
    for p in sheet["parts"]:
        out[p["id"] + "o"] = p["outer"]
        for k, h in enumerate(p["holes"]):
            out[f"{p['id']}h{k}"] = h
    return out


def sheet_svg(sheet):
    body = []
    for name, ring in contours_of(sheet).items():
        d = "M" + "L".join(f"{x:.4f} {y:.4f}" for x, y in ring) + "Z"
        body.append(f'<path id="{name}" d="{d}" fill="none" stroke="black"/>')
    w, h = sheet["width"], sheet["height"]
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}">\n'
            '<g id="layer1">\n' + "\n".join(body) + "\n</g>\n</svg>\n")


# ---------------------------------------------------------------- measuring

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def svg_paths(text):
    """[(id, points, closed)] of every <path> in document order (absolute and relative
    M/L/H/V/Z; the outputs hold nothing else, anything else is refused)."""
    out = []
    for m in re.finditer(r"<path\b([^>]*)>", text, re.S):
        attrs = m.group(1)
        pid = re.search(r'\sid="([^"]*)"', attrs).group(1)
        d = re.search(r'\sd="([^"]*)"', attrs).group(1)
        toks = re.findall(r"[A-Za-z]|" + NUM, d)
        pts, closed, cmd, i, cur, n_sub = [], False, None, 0, (0.0, 0.0), 0
        while i < len(toks):
            t = toks[i]
            if t.isalpha():
                if t not in "MmLlHhVvZz":
                    raise ValueError(f"path {pid}: command {t} not expected")
                cmd = t
                i += 1
                if cmd in "Zz":
                    closed = True
                continue
            if closed:
                raise ValueError(f"path {pid}: more than one subpath")
            if cmd in "Mm":
                n_sub += 1
                if n_sub > 1:
                    raise ValueError(f"path {pid}: more than one subpath")
            if cmd in "MmLl":
                p = (float(toks[i]), float(toks[i + 1]))
                cur = (cur[0] + p[0], cur[1] + p[1]) if cmd.islower() and pts else p
                i += 2
                if cmd == "M":
                    cmd = "L"
                elif cmd == "m":
                    cmd = "l"
            elif cmd in "Hh":
                cur = (float(toks[i]) + (cur[0] if cmd == "h" else 0.0), cur[1])
                i += 1
            elif cmd in "Vv":
                cur = (cur[0], float(toks[i]) + (cur[1] if cmd == "v" else 0.0))
                i += 1
            pts.append(cur)
        if closed and len(pts) > 1 and math.dist(pts[0], pts[-1]) < 1e-9:
            pts.pop()
        out.append((pid, pts, closed))
    return out


def seg_dist(p, a, b):
    ax, ay = b[0] - a[0], b[1] - a[1]
    L = ax * ax + ay * ay
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / L))
    return math.dist(p, (a[0] + t * ax, a[1] + t * ay))


def ring_dist(p, ring):
    return min(seg_dist(p, ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring)))


def rapid(entries, start=(0.0, 0.0)):
    """Rapid travel from `start` through the entry points (each closed contour is left where it
    was entered); no return to the start."""
    total, at = 0.0, start
    for e in entries:
        total += math.dist(at, e)
        at = e
    return total


def hole_violations(order):
    """Holes cut after the outer contour of their part."""
    outer_at = {name[:-1]: i for i, name in enumerate(order) if name.endswith("o")}
    return sum(1 for i, name in enumerate(order) if "h" in name and i > outer_at[name.split("h")[0]])


def check_order(tool, order, contours):
    if len(order) != len(contours) or set(order) != set(contours):
        missing = set(contours) - set(order)
        raise RuntimeError(f"{tool}: {len(order)} contours written, {len(set(order))} distinct, "
                           f"{len(contours)} in the sheet, missing {sorted(missing)[:5]}")


def measure_towpath(out_svg, contours, tol=2e-3):
    """(rapid, violations) of towpath's ordered SVG; checks every contour is there once, closed,
    and is its input ring (every written vertex on it, every input vertex written)."""
    paths = svg_paths(out_svg.read_text())
    order = [pid for pid, _, _ in paths]
    check_order("towpath", order, contours)
    for pid, pts, closed in paths:
        ring = contours[pid]
        if not closed:
            raise RuntimeError(f"towpath: {pid} written open")
        if any(ring_dist(p, ring) > tol for p in pts):
            raise RuntimeError(f"towpath: {pid} has a point off its contour")
        if any(min(math.dist(v, p) for p in pts) > tol for v in ring):
            raise RuntimeError(f"towpath: {pid} lost a vertex")
    return rapid([pts[0] for _, pts, _ in paths]), hole_violations(order)


def measure_peer(out_json, contours, tol=1e-6):
    v = json.loads(out_json)
    order = [s["contour"] for s in v["sequence"]]
    check_order("u-nesting-cutting", order, contours)
    entries = []
    for s in v["sequence"]:
        p = tuple(s["pierce"])
        if ring_dist(p, contours[s["contour"]]) > tol:
            raise RuntimeError(f"u-nesting-cutting: pierce point of {s['contour']} off its contour")
        entries.append(p)
    return rapid(entries), hole_violations(order), v


# ---------------------------------------------------------------- runners

def timed(cmd, stdout_path):
    """Runs a command; returns (wall seconds, CPU seconds, stdout text)."""
    err = OUT / ".stderr"
    with open(stdout_path, "w") as so, open(err, "w") as se:
        t0 = time.perf_counter()
        p = subprocess.Popen([str(c) for c in cmd], stdout=so, stderr=se)
        _, status, ru = os.wait4(p.pid, 0)
        dt = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({code}): {err.read_text()[-2000:]}")
    return dt, ru.ru_utime + ru.ru_stime, Path(stdout_path).read_text()


def build():
    env = dict(os.environ, CARGO_BUILD_JOBS=os.environ.get("CARGO_BUILD_JOBS", "1"))
    if not TOWPATH.exists():
        subprocess.check_call(["cargo", "build", "--release", "-p", "towpath"], cwd=ROOT, env=env)
    subprocess.check_call(["cargo", "build", "--release", "--manifest-path", str(PEER_DIR / "Cargo.toml")], env=env)


def bench(args):
    OUT.mkdir(parents=True, exist_ok=True)
    rows = []
    for n in args.sizes:
        sheet = make_sheet(n, seed=n)
        contours = contours_of(sheet)
        base = OUT / f"sheet-{n}"
        Path(f"{base}.json").write_text(json.dumps(sheet))
        Path(f"{base}.svg").write_text(sheet_svg(sheet))
        row = {"sheet": f"sheet-{n}", "parts": n, "contours": len(contours),
               "holes": len(contours) - n, "size": f"{sheet['width']} × {sheet['height']} mm",
               "as_drawn": rapid([ring[0] for ring in contours.values()]),
               "as_drawn_violations": hole_violations(list(contours))}
        for tool in ("u-nesting-cutting", "towpath"):
            rec = {"rapid": [], "wall": [], "cpu": [], "violations": [], "inner": []}
            for r in range(args.runs):
                if tool == "towpath":
                    out_svg = OUT / f"sheet-{n}.towpath.{r}.svg"
                    wall, cpu, so = timed([TOWPATH, "order", f"{base}.svg", "-o", out_svg, "--json"],
                                          OUT / f"sheet-{n}.towpath.{r}.json")
                    length, viol = measure_towpath(out_svg, contours)
                    rep = json.loads(so)
                    rec["inner"].append(rep["solve_seconds"])
                    rec["own"] = rep["rapid_after"]
                else:
                    out_json = OUT / f"sheet-{n}.unesting.{r}.json"
                    wall, cpu, so = timed([PEER, f"{base}.json"], out_json)
                    length, viol, rep = measure_peer(so, contours)
                    rec["inner"].append(rep["seconds"])
                    rec["own"] = rep["total_rapid_distance"]
                rec["rapid"].append(length)
                rec["wall"].append(wall)
                rec["cpu"].append(cpu)
                rec["violations"].append(viol)
                print(json.dumps({"sheet": n, "tool": tool, "run": r, "rapid": round(length, 3), "wall": round(wall, 3),
                                  "cpu": round(cpu, 3), "inner": round(rec["inner"][-1], 3), "violations": viol,
                                  "own_rapid": round(rec["own"], 3), "load": os.getloadavg()}), flush=True)
            row[tool] = {k: statistics.median(v) for k, v in rec.items() if k in ("rapid", "wall", "cpu", "inner")}
            row[tool]["violations"] = max(rec["violations"])
            row[tool]["runs"] = rec
        rows.append(row)
    return rows


def diagnostics(sizes):
    rows = []
    for n in sizes:
        base = OUT / f"sheet-{n}"
        sheet = json.loads(Path(f"{base}.json").read_text())
        contours = contours_of(sheet)
        row = {"sheet": f"sheet-{n}", "parts": n}
        peer_cases = [("nn", ["--max-2opt-iterations", "0"])] + ([("unlimited", ["--time-limit-ms", "0"])] if n <= 200 else [])
        for key, extra in peer_cases:
            out_json = OUT / f"sheet-{n}.unesting.{key}.json"
            wall, cpu, so = timed([PEER, f"{base}.json", *extra], out_json)
            length, viol, rep = measure_peer(so, contours)
            row[key] = {"rapid": length, "inner": rep["seconds"], "violations": viol}
            print(json.dumps({"sheet": n, "tool": f"u-nesting-cutting {key}", "rapid": round(length, 3),
                              "inner": round(rep["seconds"], 3), "violations": viol}), flush=True)
        for limit in (0.5, 2, 5):
            lens = []
            for seed in (1, 2, 3):
                out_svg = OUT / f"sheet-{n}.towpath.t{limit}.s{seed}.svg"
                timed([TOWPATH, "order", f"{base}.svg", "-o", out_svg, "--json", "--time-limit", limit, "--seed", seed],
                      OUT / f"sheet-{n}.towpath.t{limit}.s{seed}.json")
                length, viol = measure_towpath(out_svg, contours)
                if viol:
                    raise RuntimeError(f"towpath --time-limit {limit}: {viol} hole-order violations")
                lens.append(length)
                print(json.dumps({"sheet": n, "tool": f"towpath --time-limit {limit} --seed {seed}", "rapid": round(length, 3)}), flush=True)
            row[f"t{limit}"] = lens
        rows.append(row)
    return rows


def diag_table(rows, main_rows):
    base = {r["sheet"]: r["u-nesting-cutting"]["rapid"] for r in main_rows}
    out = ["| sheet | u-nesting-cutting, nearest neighbour only | u-nesting-cutting, default (table above) | "
           "u-nesting-cutting, 2-opt without time limit | towpath --time-limit 0.5 | towpath --time-limit 2 | towpath --time-limit 5 |",
           "|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        peer = lambda k: (f"{r[k]['rapid']:,.1f} mm ({r[k]['inner']:.2f} s)" if k in r else "not run")
        def tp(k):
            v = r[k]
            m = statistics.median(v)
            return f"{m:,.1f} mm ({min(v):,.0f}–{max(v):,.0f}) = {m / base[r['sheet']]:.3f}×"
        out.append(f"| {r['sheet']} | {peer('nn')} | {base[r['sheet']]:,.1f} mm | {peer('unlimited')} | "
                   f"{tp('t0.5')} | {tp('t2')} | {tp('t5')} |")
    return "\n".join(out)


def table(rows):
    out = ["| sheet | parts | contours (holes) | as drawn | u-nesting-cutting rapid | u-nesting-cutting time | "
           "towpath rapid | towpath time | towpath / u-nesting-cutting rapid | hole-order violations (peer, towpath) |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        u, t = r["u-nesting-cutting"], r["towpath"]
        cell = lambda x, what: (f"{x['wall']:.2f} s wall, {x['cpu']:.2f} s CPU ({what} {x['inner']:.2f} s)")
        out.append(f"| {r['sheet']} ({r['size']}) | {r['parts']:,} | {r['contours']:,} ({r['holes']:,}) | "
                   f"{r['as_drawn']:,.0f} mm | {u['rapid']:,.1f} mm | {cell(u, 'in the call')} | "
                   f"{t['rapid']:,.1f} mm | {cell(t, 'solve')} | {t['rapid'] / u['rapid']:.3f} | "
                   f"{u['violations']}, {t['violations']} |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--sizes", default="50,200,1000")
    ap.add_argument("--diagnostics", action="store_true")
    ap.add_argument("--write-markdown", action="store_true")
    args = ap.parse_args()
    args.sizes = [int(s) for s in args.sizes.split(",") if s]
    build()
    load_before = os.getloadavg()
    rows = bench(args)
    md = table(rows)
    print(md)
    print(f"load average before {load_before}, after {os.getloadavg()}")
    diag = None
    if args.diagnostics:
        diag = diag_table(diagnostics(args.sizes), rows)
        print(diag)
        print(f"load average after the diagnostics {os.getloadavg()}")
    with open(ROOT / "bench" / "out" / "unesting-results.jsonl", "a") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")
    if args.write_markdown:
        p = ROOT / "BENCHMARKS.md"
        text = replace_between(p.read_text(), "<!-- unesting-bench:start -->", "<!-- unesting-bench:end -->", md)
        if diag:
            text = replace_between(text, "<!-- unesting-diag:start -->", "<!-- unesting-diag:end -->", diag)
        p.write_text(text)


if __name__ == "__main__":
    main()
