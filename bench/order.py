#!/usr/bin/env python3
"""Cutting/plotting and machining benchmark: `towpath order` against vpype's `linesort`
(greedy and `--two-opt`) on the same SVG files in the same run, and `towpath machine` (towpath's
solver against the `castelino` transformation) on seed-003-like parts.

Creates bench/.venv with a pinned vpype (and fontTools for the glyph drawing) and re-executes
itself there. Every pen-up length in the table is measured here, from the written SVG files,
by one parser (absolute path data: M/L/H/V/C/Q/Z, lines, polylines, polygons; the document's
width/viewBox give millimetres), never taken from a tool's own report; each output is also
checked to hold as many strokes as its input.

    python3 bench/order.py [--runs 3] [--sizes 1000,10000,100000] [--skip-vpype-2opt-above N]
                           [--write-markdown]

Writes bench/out/order-results.jsonl and, with --write-markdown, the tables between the
`<!-- cut-bench:start/end -->` and `<!-- mill-bench:start/end -->` markers in BENCHMARKS.md.
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
VENV = ROOT / "bench" / ".venv"
OUT = ROOT / "bench" / "out" / "order"
PINS = ["vpype==1.15.0", "fonttools==4.60.1"]
TOWPATH = ROOT / "target" / "release" / "towpath"


def ensure_venv():
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not (VENV / "bin" / "python").exists():
        subprocess.check_call([sys.executable, "-m", "venv", str(VENV)])
    subprocess.check_call([str(VENV / "bin" / "pip"), "install", "-q", *PINS])
    os.execv(str(VENV / "bin" / "python"), [str(VENV / "bin" / "python"), __file__, *sys.argv[1:]])


# ---------------------------------------------------------------- inputs

def random_strokes(n, seed, size=1000.0):
    """n straight strokes with uniform random ends in a size × size mm square."""
    rng = random.Random(seed)
    lines = []
    for _ in range(n):
        x1, y1, x2, y2 = (rng.uniform(0, size) for _ in range(4))
        lines.append(f'<path d="M{x1:.4f} {y1:.4f}L{x2:.4f} {y2:.4f}" fill="none" stroke="black"/>')
    return svg_doc(size, size, lines)


def svg_doc(w, h, body):
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}">\n'
            '<g id="layer1">\n' + "\n".join(body) + "\n</g>\n</svg>\n")


def glyph_text(font_path, text, size_mm=8.0, line_mm=11.0, width_chars=60):
    """Text set in a system font, each glyph outline flattened to closed polylines (mm)."""
    from fontTools.pens.basePen import BasePen
    from fontTools.ttLib import TTFont

    font = TTFont(font_path)
    gs = font.getGlyphSet()
    cmap = font.getBestCmap()
    upm = font["head"].unitsPerEm
    scale = size_mm / upm
    hmtx = font["hmtx"]

    class Flatten(BasePen):
        def __init__(self, gs, ox, oy):
            super().__init__(gs)
            self.ox, self.oy, self.polys, self.cur = ox, oy, [], []

        def pt(self, p):
            return (self.ox + p[0] * scale, self.oy - p[1] * scale)

        def _moveTo(self, p):
            self.cur = [self.pt(p)]

        def _lineTo(self, p):
            self.cur.append(self.pt(p))

        def _curveToOne(self, p1, p2, p3):
            p0 = self._getCurrentPoint()
            for i in range(1, 9):
                t = i / 8
                u = 1 - t
                x = u**3 * p0[0] + 3 * u * u * t * p1[0] + 3 * u * t * t * p2[0] + t**3 * p3[0]
                y = u**3 * p0[1] + 3 * u * u * t * p1[1] + 3 * u * t * t * p2[1] + t**3 * p3[1]
                self.cur.append(self.pt((x, y)))

        def _qCurveToOne(self, p1, p2):
            p0 = self._getCurrentPoint()
            for i in range(1, 7):
                t = i / 6
                u = 1 - t
                x = u * u * p0[0] + 2 * u * t * p1[0] + t * t * p2[0]
                y = u * u * p0[1] + 2 * u * t * p1[1] + t * t * p2[1]
                self.cur.append(self.pt((x, y)))

        def _closePath(self):
            if len(self.cur) >= 3:
                self.polys.append(self.cur)
            self.cur = []

        _endPath = _closePath

    body = []
    x, y = 10.0, 15.0
    words = text.split()
    col = 0
    for word in words:
        if col + len(word) > width_chars:
            x, y, col = 10.0, y + line_mm, 0
        for ch in word + " ":
            name = cmap.get(ord(ch))
            if name is None:
                continue
            pen = Flatten(gs, x, y)
            gs[name].draw(pen)
            for poly in pen.polys:
                d = "M" + "L".join(f"{px:.3f} {py:.3f}" for px, py in poly) + "Z"
                body.append(f'<path d="{d}" fill="none" stroke="black"/>')
            x += hmtx[name][0] * scale
            col += 1
    return svg_doc(10.0 + width_chars * size_mm * 0.62 + 10.0, y + 10.0, body)


def contour_map(seed, grid=180, size=400.0, levels=14):
    """A synthetic topographic map: isolines of a smooth random terrain (marching squares),
    joined into polylines; many open and closed strokes of very different lengths."""
    rng = random.Random(seed)
    bumps = [(rng.uniform(0, size), rng.uniform(0, size), rng.uniform(20, 90), rng.uniform(-1, 1)) for _ in range(40)]

    def z(x, y):
        return sum(a * math.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s)) for cx, cy, s, a in bumps)

    step = size / grid
    vals = [[z(i * step, j * step) for i in range(grid + 1)] for j in range(grid + 1)]
    lo = min(min(r) for r in vals)
    hi = max(max(r) for r in vals)
    body = []
    for k in range(1, levels + 1):
        lev = lo + (hi - lo) * k / (levels + 1)
        segs = []
        for j in range(grid):
            for i in range(grid):
                c = [vals[j][i], vals[j][i + 1], vals[j + 1][i + 1], vals[j + 1][i]]
                p = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                cross = []
                for e in range(4):
                    a, b = c[e], c[(e + 1) % 4]
                    if (a < lev) != (b < lev):
                        t = (lev - a) / (b - a)
                        pa, pb = p[e], p[(e + 1) % 4]
                        cross.append((round((pa[0] + t * (pb[0] - pa[0])) * step, 4), round((pa[1] + t * (pb[1] - pa[1])) * step, 4)))
                if len(cross) == 2:
                    segs.append((cross[0], cross[1]))
                elif len(cross) == 4:
                    segs.append((cross[0], cross[1]))
                    segs.append((cross[2], cross[3]))
        # Join segments sharing end points into polylines.
        ends = {}
        for idx, (a, b) in enumerate(segs):
            ends.setdefault(a, []).append(idx)
            ends.setdefault(b, []).append(idx)
        used = [False] * len(segs)
        for idx in range(len(segs)):
            if used[idx]:
                continue
            used[idx] = True
            line = [segs[idx][0], segs[idx][1]]
            for direction in (1, 0):
                while True:
                    tip = line[-1] if direction else line[0]
                    nxt = [s for s in ends.get(tip, []) if not used[s]]
                    if not nxt:
                        break
                    used[nxt[0]] = True
                    a, b = segs[nxt[0]]
                    q = b if a == tip else a
                    if direction:
                        line.append(q)
                    else:
                        line.insert(0, q)
            closed = line[0] == line[-1] and len(line) > 3
            pts = line[:-1] if closed else line
            d = "M" + "L".join(f"{x:.4f} {y:.4f}" for x, y in pts) + ("Z" if closed else "")
            body.append(f'<path d="{d}" fill="none" stroke="black"/>')
    return svg_doc(size, size, body)


# ---------------------------------------------------------------- measuring

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def parse_len(v):
    m = re.match(r"\s*(" + NUM + r")\s*([a-z%]*)", v or "")
    if not m:
        return None
    x, u = float(m.group(1)), m.group(2)
    return x * {"mm": 1.0, "cm": 10.0, "in": 25.4, "px": 25.4 / 96, "": 25.4 / 96, "pt": 25.4 / 72}.get(u, 1.0)


def strokes_of(svg_text):
    """Strokes (start, end) in document order, in mm; transforms are not followed (neither
    tool writes any on these files)."""
    head = re.search(r"<svg[^>]*>", svg_text, re.S).group(0)
    vb = re.search(r'viewBox="([^"]+)"', head)
    w = re.search(r'\swidth="([^"]+)"', head)
    scale = 1.0
    if vb and w:
        vbw = float(re.split(r"[\s,]+", vb.group(1).strip())[2])
        scale = parse_len(w.group(1)) / vbw
    out = []
    for m in re.finditer(r"<(path|line|polyline|polygon)\b([^>]*)>", svg_text, re.S):
        tag, attrs = m.group(1), m.group(2)
        if tag == "path":
            d = re.search(r'\sd="([^"]*)"', attrs).group(1)
            out.extend(subpaths(d))
        elif tag == "line":
            g = lambda k: float(re.search(r"\s" + k + r'="([^"]*)"', attrs).group(1))
            out.append(((g("x1"), g("y1")), (g("x2"), g("y2"))))
        else:
            nums = [float(x) for x in re.findall(NUM, re.search(r'points="([^"]*)"', attrs).group(1))]
            pts = list(zip(nums[0::2], nums[1::2]))
            if pts:
                out.append((pts[0], pts[0] if tag == "polygon" else pts[-1]))
    return [((a[0] * scale, a[1] * scale), (b[0] * scale, b[1] * scale)) for a, b in out]


def subpaths(d):
    toks = re.findall(r"[MmLlHhVvCcQqZzSsTtAa]|" + NUM, d)
    res = []
    i = 0
    cmd = None
    cur = start = None
    first = None
    while i < len(toks):
        t = toks[i]
        if t.isalpha():
            cmd = t
            i += 1
            if cmd in "Zz":
                if first is not None:
                    res.append((first, start))
                    first = None
                cur = start
                continue
        if cmd in "Mm":
            p = (float(toks[i]), float(toks[i + 1]))
            if cmd == "m" and cur is not None:
                p = (cur[0] + p[0], cur[1] + p[1])
            if first is not None:
                res.append((first, cur))
            first = start = cur = p
            i += 2
            cmd = "L" if cmd == "M" else "l"
        elif cmd in "Ll":
            p = (float(toks[i]), float(toks[i + 1]))
            cur = p if cmd == "L" else (cur[0] + p[0], cur[1] + p[1])
            i += 2
        elif cmd in "Hh":
            cur = (float(toks[i]) if cmd == "H" else cur[0] + float(toks[i]), cur[1])
            i += 1
        elif cmd in "Vv":
            cur = (cur[0], float(toks[i]) if cmd == "V" else cur[1] + float(toks[i]))
            i += 1
        elif cmd in "CcSsQqTtAa":
            n = {"C": 6, "S": 4, "Q": 4, "T": 2, "A": 7}[cmd.upper()]
            x, y = float(toks[i + n - 2]), float(toks[i + n - 1])
            cur = (x, y) if cmd.isupper() else (cur[0] + x, cur[1] + y)
            i += n
        else:
            i += 1
    if first is not None:
        res.append((first, cur))
    return res


def pen_up(strokes):
    total = 0.0
    for (a, b), (c, _) in zip(strokes, strokes[1:]):
        total += math.dist(b, c)
    return total


# ---------------------------------------------------------------- runners

CPU = []  # CPU seconds of the last timed process


def timed(cmd):
    """Runs a command; returns (wall seconds, stdout) and records its CPU time (wait4)."""
    out_f = OUT / ".stdout"
    err_f = OUT / ".stderr"
    with open(out_f, "w") as so, open(err_f, "w") as se:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=so, stderr=se)
        _, status, ru = os.wait4(p.pid, 0)
        dt = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    CPU.append(ru.ru_utime + ru.ru_stime)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({p.returncode}): {err_f.read_text()[-2000:]}")
    return dt, out_f.read_text()


def run_vpype(inp, out, two_opt):
    cmd = [str(VENV / "bin" / "vpype"), "read", "--single-layer", str(inp), "linesort"]
    if two_opt:
        cmd.append("--two-opt")
    cmd += ["write", str(out)]
    return timed(cmd)[0]


SOLVE = []  # towpath's reported solve seconds of the last towpath run


def run_towpath(inp, out, extra):
    dt, stdout = timed([str(TOWPATH), "order", str(inp), "-o", str(out), "--start", "none", "--json", *extra])
    SOLVE.append(json.loads(stdout)["solve_seconds"])
    return dt


def tenth_of_two_opt(row):
    """towpath's --time-limit for a whole run in 0.1x vpype 2-opt's median wall time: that time
    less towpath's own reading/checking/writing (its default run's median wall minus solve
    time), at least 1 ms."""
    v2, t = row["vpype linesort --two-opt"], row["towpath order"]
    overhead = statistics.median(w - s for w, s in zip(t["seconds"], t["solve"]))
    return max(0.001, 0.1 * v2["seconds_median"] - overhead)


def bench_cut(args, results):
    OUT.mkdir(parents=True, exist_ok=True)
    cases = []
    for n in args.sizes:
        p = OUT / f"random-{n}.svg"
        if not p.exists():
            p.write_text(random_strokes(n, seed=n))
        cases.append((f"{n:,} random strokes", p, n))
    font = Path("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")
    if font.exists():
        p = OUT / "glyphs.svg"
        if not p.exists():
            text = (Path(ROOT / "README.md").read_text().replace("`", "").replace("#", ""))[:2500]
            p.write_text(glyph_text(font, text))
        cases.append(("glyph outlines (DejaVu Sans, 2,500 chars of README.md)", p, None))
    p = OUT / "contour-map.svg"
    if not p.exists():
        p.write_text(contour_map(seed=3))
    cases.append(("contour map (isolines of a random terrain)", p, None))
    rows = []
    for label, inp, n in cases:
        src = strokes_of(inp.read_text())
        row = {"case": label, "strokes": len(src), "input_penup": pen_up(src)}
        tools = [("vpype linesort", lambda o: run_vpype(inp, o, False)),
                 ("towpath order", lambda o: run_towpath(inp, o, [])),
                 ("towpath order --no-inner-first", lambda o: run_towpath(inp, o, ["--no-inner-first"]))]
        if n is None or n <= args.skip_vpype_2opt_above:
            tools.insert(1, ("vpype linesort --two-opt", lambda o: run_vpype(inp, o, True)))
            tools.append(("towpath order, 0.1x 2-opt time",
                          lambda o: run_towpath(inp, o, ["--time-limit", f"{tenth_of_two_opt(row):.4f}"])))
            tools.append(("towpath order --no-inner-first, 0.1x 2-opt time",
                          lambda o: run_towpath(inp, o, ["--no-inner-first", "--time-limit",
                                                         f"{tenth_of_two_opt(row):.4f}"])))
        for name, fn in tools:
            times, pens, cpus = [], [], []
            SOLVE.clear()
            for r in range(args.runs):
                out = OUT / f"{inp.stem}.{name.replace(' ', '_').replace('-', '')}.{r}.svg"
                dt = fn(out)
                got = strokes_of(out.read_text())
                if len(got) != len(src):
                    raise RuntimeError(f"{name} on {inp.name}: {len(got)} strokes out of {len(src)}")
                times.append(dt)
                cpus.append(CPU[-1])
                pens.append(pen_up(got))
            rec = {"case": label, "tool": name, "strokes": len(src), "runs": args.runs,
                   "penup_median": statistics.median(pens), "seconds_median": statistics.median(times),
                   "cpu_median": statistics.median(cpus), "penups": pens, "seconds": times, "cpu": cpus,
                   "load": os.getloadavg()[0]}
            if name.startswith("towpath"):
                rec["solve"] = list(SOLVE)
            results.append(rec)
            print(json.dumps(rec), flush=True)
            row[name] = rec
        # A floor no order can go below (Held–Karp, `--bound`): open strokes only, one run.
        if n is not None and 2 * n <= 50_000:
            _, stdout = timed([str(TOWPATH), "order", str(inp), "--start", "none", "--bound", "--json"])
            rec = json.loads(stdout)
            row["bound"] = rec["rapid_lower_bound"]
            results.append({"case": label, "tool": "towpath order --bound", "bound": row["bound"],
                            "rapid_after": rec["rapid_after"], "seconds": rec["seconds"]})
            print(json.dumps(results[-1]), flush=True)
        rows.append(row)
    return rows


def cut_table(rows):
    out = ["| drawing | strokes | as drawn | vpype greedy | vpype 2-opt | towpath | towpath, no inner-first | towpath / 2-opt pen-up | towpath / 2-opt wall time | towpath in 0.1x 2-opt's time | its pen-up / 2-opt | its wall time / 2-opt | no inner-first in 0.1x 2-opt's time: pen-up / 2-opt | floor: Held–Karp bound on every order (/ 2-opt) |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        def cell(name):
            rec = r.get(name)
            return (f"{rec['penup_median']:,.0f} mm, {rec['seconds_median']:.2f} s ({rec['cpu_median']:.2f} s CPU)"
                    if rec else "not run")
        t, v2 = r.get("towpath order"), r.get("vpype linesort --two-opt")
        ratio_p = f"{t['penup_median'] / v2['penup_median']:.3f}" if t and v2 else "–"
        ratio_t = f"{t['seconds_median'] / v2['seconds_median']:.3f}" if t and v2 else "–"
        f = r.get("towpath order, 0.1x 2-opt time")
        fast_p = f"{f['penup_median'] / v2['penup_median']:.3f}" if f and v2 else "–"
        fast_t = f"{f['seconds_median'] / v2['seconds_median']:.3f}" if f and v2 else "–"
        g = r.get("towpath order --no-inner-first, 0.1x 2-opt time")
        free = (f"{g['penup_median']:,.0f} mm = {g['penup_median'] / v2['penup_median']:.3f} "
                f"({g['seconds_median'] / v2['seconds_median']:.3f} of its time)" if g and v2 else "–")
        b = r.get("bound")
        floor = (f"{b:,.0f} mm" + (f" ({b / v2['penup_median']:.3f})" if v2 else "")) if b else "–"
        out.append(f"| {r['case']} | {r['strokes']:,} | {r['input_penup']:,.0f} mm | {cell('vpype linesort')} | {cell('vpype linesort --two-opt')} | "
                   f"{cell('towpath order')} | {cell('towpath order --no-inner-first')} | {ratio_p} | {ratio_t} | "
                   f"{cell('towpath order, 0.1x 2-opt time') if f else 'not run'} | {fast_p} | {fast_t} | {free} | {floor} |")
    return "\n".join(out)


# ---------------------------------------------------------------- machining

def seed003_part(k, seed):
    """A plate with a feature hierarchy: a facing feature, k pockets (some dumbbells that split
    into cells, some with islands), slots inside some pockets; 3 tools."""
    rng = random.Random(seed)
    feats = [{"id": "face", "boundary": [[0, 0], [400, 0], [400, 300], [0, 300]], "depth": 1}]
    tools = {1: ["face"], 2: [], 3: []}
    cols, rows = 4, max(1, (k + 3) // 4)
    cw, ch = 400 / cols, 300 / rows
    for i in range(k):
        x0, y0 = (i % cols) * cw + 8, (i // cols) * ch + 8
        w, h = cw - 16, ch - 16
        fid = f"p{i}"
        if i % 3 == 0:
            neck = rng.uniform(6, 12)
            a = w * 0.38
            b = [[x0, y0], [x0 + a, y0], [x0 + a, y0 + h / 2 - neck], [x0 + w - a, y0 + h / 2 - neck], [x0 + w - a, y0],
                 [x0 + w, y0], [x0 + w, y0 + h], [x0 + w - a, y0 + h], [x0 + w - a, y0 + h / 2 + neck],
                 [x0 + a, y0 + h / 2 + neck], [x0 + a, y0 + h], [x0, y0 + h]]
            feats.append({"id": fid, "parent": "face", "boundary": b, "depth": 6})
        else:
            f = {"id": fid, "parent": "face", "boundary": [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]], "depth": 5}
            if i % 3 == 1:
                cx, cy = x0 + w / 2, y0 + h / 2
                f["islands"] = [[[cx - 8, cy - 8], [cx + 8, cy - 8], [cx + 8, cy + 8], [cx - 8, cy + 8]]]
            feats.append(f)
            if i % 3 == 2:
                feats.append({"id": f"s{i}", "parent": fid, "depth": 9,
                              "boundary": [[x0 + 10, y0 + 10], [x0 + 30, y0 + 10], [x0 + 30, y0 + h - 10], [x0 + 10, y0 + h - 10]]})
                tools[3].append(f"s{i}")
        tools[1].append(fid)
        tools[2].append(fid)
    return {"format": "towpath-part/1", "name": f"seed003-like-{k}", "origin": [0, 0], "clearance": 5, "features": feats,
            "tools": [{"number": 1, "radius": 6, "step_over": 5, "features": tools[1]},
                      {"number": 2, "radius": 3, "step_over": 2.5, "features": tools[2]},
                      {"number": 3, "radius": 1.5, "step_over": 1.2, "features": tools[3] or ["face"]}]}


def bench_mill(args, results):
    rows = []
    for k in (8, 16, 32):
        p = OUT / f"part-{k}.json"
        p.write_text(json.dumps(seed003_part(k, k)))
        row = {"part": f"{p.stem} ({k} pockets)"}
        for solver in ("towpath", "castelino"):
            times, after = [], []
            for _ in range(args.runs):
                dt, out = timed([str(TOWPATH), "machine", str(p), "--solver", solver, "--time-limit", "2", "--json"])
                v = json.loads(out)
                times.append(sum(t["solve_seconds"] for t in v["tools"]))
                after.append(v["rapid_after"])
                row["cells"] = sum(t["cells"] for t in v["tools"])
                row["before"] = v["rapid_before"]
            row[solver] = {"after": statistics.median(after), "solve": statistics.median(times)}
            results.append({"case": p.stem, "tool": f"machine {solver}", **row[solver]})
            print(json.dumps({"part": p.stem, "solver": solver, **row[solver]}), flush=True)
        rows.append(row)
    lines = ["| part | cells (all tools) | rapid before (feature order, first vertex) | towpath | castelino | towpath / castelino |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        t, c = r["towpath"], r["castelino"]
        lines.append(f"| {r['part']} | {r['cells']} | {r['before']:,.1f} mm | {t['after']:,.1f} mm ({t['solve']:.2f} s) | "
                     f"{c['after']:,.1f} mm ({c['solve']:.2f} s) | {t['after'] / c['after']:.3f} |")
    return "\n".join(lines)


def replace_between(text, start, end, body):
    a, b = text.index(start) + len(start), text.index(end)
    return text[:a] + "\n" + body + "\n" + text[b:]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--sizes", default="1000,10000,100000")
    ap.add_argument("--skip-vpype-2opt-above", type=int, default=10000)
    ap.add_argument("--no-mill", action="store_true")
    ap.add_argument("--no-cut", action="store_true", help="only the machining table")
    ap.add_argument("--write-markdown", action="store_true")
    args = ap.parse_args()
    args.sizes = [int(s) for s in args.sizes.split(",") if s]
    ensure_venv()
    if not TOWPATH.exists():
        subprocess.check_call(["cargo", "build", "--release", "-p", "towpath"], cwd=ROOT)
    results = []
    cut = None if args.no_cut else cut_table(bench_cut(args, results))
    if cut:
        print(cut)
    mill = None if args.no_mill else bench_mill(args, results)
    if mill:
        print(mill)
    with open(ROOT / "bench" / "out" / "order-results.jsonl", "a") as f:
        for r in results:
            f.write(json.dumps(r) + "\n")
    if args.write_markdown:
        md = ROOT / "BENCHMARKS.md"
        text = md.read_text()
        if cut:
            text = replace_between(text, "<!-- cut-bench:start -->", "<!-- cut-bench:end -->", cut)
        if mill:
            text = replace_between(text, "<!-- mill-bench:start -->", "<!-- mill-bench:end -->", mill)
        md.write_text(text)


if __name__ == "__main__":
    main()
