#!/usr/bin/env python3
"""towpath order against u-nesting-cutting (the Rust crate's `optimize_cutting_path`: holes
before exteriors, nearest neighbour and constrained 2-opt, Dewil et al. 2016) on sheets of
nested parts. Run by hand, not in CI.

Builds the peer (`bench/unesting/`, a separate Cargo workspace pinned to u-nesting-cutting
0.7.2), generates sheets of parts (rectangles, L-shapes and 24-gons with 0-4 holes each, shelf
packed with 5 mm gaps, fixed seeds), gives the same contours to both tools (the peer as JSON
with every part placed at its sheet coordinates, towpath as an SVG of closed paths), and
measures from their outputs with this script's own code: the rapid length between consecutive
contours (entry of each contour = where its cut starts and ends; the move from the origin is not
counted for either), holes cut after their part's outline (violations), and every contour once.

    python3 bench/unesting.py [--runs 3] [--sizes 50,200,1000] [--pierce 1]
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

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "bench" / "out" / "unesting"
PEER_DIR = ROOT / "bench" / "unesting"
PEER = PEER_DIR / "target" / "release" / "unesting-peer"
TOWPATH = ROOT / "target" / "release" / "towpath"


def rect(x, y, w, h):
    return [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]


def ngon(cx, cy, r, n=24):
    return [(cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n)) for k in range(n)]


def part(rng):
    """A part in local coordinates: (outer, holes, width, height)."""
    kind = rng.random()
    w, h = rng.uniform(40, 150), rng.uniform(40, 150)
    holes = []
    if kind < 0.5:
        outer = rect(0, 0, w, h)
        area = (0, 0, w, h)
    elif kind < 0.8:
        a, b = w * rng.uniform(0.4, 0.6), h * rng.uniform(0.4, 0.6)
        outer = [(0, 0), (w, 0), (w, b), (a, b), (a, h), (0, h)]
        area = (0, 0, w, b)
    else:
        r = min(w, h) / 2
        w = h = 2 * r
        outer = ngon(r, r, r)
        area = (r * 0.3, r * 0.3, r * 1.4, r * 1.4)
    k = rng.randint(0, 4)
    ax, ay, aw, ah = area
    cols = max(1, k)
    cw = aw / cols
    for i in range(k):
        hr = min(cw, ah) * rng.uniform(0.12, 0.3)
        cx, cy = ax + cw * (i + 0.5), ay + ah * 0.5
        if rng.random() < 0.5:
            holes.append(ngon(cx, cy, hr, 16))
        else:
            holes.append(rect(cx - hr, cy - hr, 2 * hr, 2 * hr))
    return outer, holes, w, h


def sheet(n, seed, width=3000.0, gap=5.0):
    rng = random.Random(seed)
    parts = []
    x = y = row_h = 0.0
    for _ in range(n):
        outer, holes, w, h = part(rng)
        if x + w > width:
            x, y, row_h = 0.0, y + row_h + gap, 0.0
        move = lambda pts: [(px + x, py + y) for px, py in pts]
        parts.append({"outer": move(outer), "holes": [move(hh) for hh in holes]})
        x += w + gap
        row_h = max(row_h, h)
    return parts


def svg(parts):
    xs = [p[0] for pt in parts for p in pt["outer"]]
    ys = [p[1] for pt in parts for p in pt["outer"]]
    w, h = max(xs) + 10, max(ys) + 10
    body = []
    for i, pt in enumerate(parts):
        for tag, ring in [(f"P{i}", pt["outer"])] + [(f"P{i}H{k}", hh) for k, hh in enumerate(pt["holes"])]:
            d = "M" + "L".join(f"{px:.4f} {py:.4f}" for px, py in ring) + "Z"
            body.append(f'<path id="{tag}" d="{d}" fill="none" stroke="black"/>')
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.3f}mm" height="{h:.3f}mm" '
            f'viewBox="0 0 {w:.3f} {h:.3f}">\n' + "\n".join(body) + "\n</svg>\n")


def towpath_order(svg_text):
    """(contour id, entry point) in the output's order."""
    out = []
    for m in re.finditer(r"<path\b([^>]*)>", svg_text, re.S):
        attrs = m.group(1)
        cid = re.search(r'\sid="([^"]*)"', attrs).group(1)
        d = re.search(r'\sd="([^"]*)"', attrs).group(1)
        nums = re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", d)
        out.append((cid, (float(nums[0]), float(nums[1]))))
    return out


def evaluate(seq, parts):
    """Rapid length between consecutive entries, holes-after-outline violations, missing/extra."""
    rapid = sum(math.dist(a[1], b[1]) for a, b in zip(seq, seq[1:]))
    done, bad = set(), 0
    for cid, _ in seq:
        if "H" not in cid and any(f"{cid}H{k}" not in done for k in range(len(parts[int(cid[1:])]["holes"]))):
            bad += 1
        done.add(cid)
    want = {f"P{i}" for i in range(len(parts))} | {f"P{i}H{k}" for i, p in enumerate(parts) for k in range(len(p["holes"]))}
    return rapid, bad, len(want ^ {c for c, _ in seq}) + (len(seq) - len(set(c for c, _ in seq)))


def timed(cmd):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed:\n{r.stderr}")
    return r.stdout, dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--sizes", default="50,200,1000")
    ap.add_argument("--pierce", type=int, default=1, help="the peer's pierce_candidates (its default 1)")
    args = ap.parse_args()
    subprocess.check_call(["cargo", "build", "--release", "-q"], cwd=PEER_DIR)
    if not TOWPATH.exists():
        subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "towpath"], cwd=ROOT)
    OUT.mkdir(parents=True, exist_ok=True)
    rows = ["| sheet | parts | contours | u-nesting-cutting rapid, time | towpath rapid, time (default limit) | towpath / peer rapid | towpath, `--time-limit 5` (the peer's 2-opt budget) | ratio | violations (peer, towpath) |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for n in [int(s) for s in args.sizes.split(",")]:
        parts = sheet(n, seed=n)
        contours = sum(1 + len(p["holes"]) for p in parts)
        pj, ps = OUT / f"sheet-{n}.json", OUT / f"sheet-{n}.svg"
        pj.write_text(json.dumps({"parts": parts}))
        ps.write_text(svg(parts))
        peer, tp, tp5 = [], [], []
        for r in range(args.runs):
            out, dt = timed([str(PEER), str(pj), str(args.pierce)])
            res = json.loads(out)
            seq = [(f"P{o['contour']['part']}" + ("" if o["contour"]["hole"] is None else f"H{o['contour']['hole']}"),
                    tuple(o["pierce"])) for o in res["order"]]
            peer.append(evaluate(seq, parts) + (res["seconds"], dt))
            o = OUT / f"sheet-{n}.towpath.{r}.svg"
            _, dt = timed([str(TOWPATH), "order", str(ps), "-o", str(o), "--start", "none", "--json"])
            tp.append(evaluate(towpath_order(o.read_text()), parts) + (dt, dt))
            _, dt = timed([str(TOWPATH), "order", str(ps), "-o", str(o), "--start", "none", "--time-limit", "5", "--json"])
            tp5.append(evaluate(towpath_order(o.read_text()), parts) + (dt, dt))
        pr, tr = statistics.median(p[0] for p in peer), statistics.median(t[0] for t in tp)
        pt, tt = statistics.median(p[4] for p in peer), statistics.median(t[4] for t in tp)
        pin = statistics.median(p[3] for p in peer)
        t5r, t5t = statistics.median(t[0] for t in tp5), statistics.median(t[4] for t in tp5)
        miss = max(p[2] for p in peer), max(t[2] for t in tp + tp5)
        if any(miss):
            raise SystemExit(f"sheet {n}: contours missing or repeated (peer {miss[0]}, towpath {miss[1]})")
        rows.append(f"| sheet-{n} | {n:,} | {contours:,} | {pr:,.0f} mm, {pt:.2f} s ({pin:.2f} s in the call) | "
                    f"{tr:,.0f} mm, {tt:.2f} s | {tr / pr:.3f} | {t5r:,.0f} mm, {t5t:.2f} s | {t5r / pr:.3f} | "
                    f"{max(p[1] for p in peer)}, {max(t[1] for t in tp + tp5)} |")
        print(rows[-1], flush=True)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
