"""Pure pieces of the sequencing benchmark: the benchmark index, the problem model read from
towpath's JSON format, an independent route checker (feasibility and cost), the GTSP -> ATSP
transformation used to give GTSP instances to LKH-3, medians, gaps and the markdown table.

Standard library only, so that `python3 -m unittest bench/test_seq.py` runs anywhere.
"""

from __future__ import annotations

import csv
import math
import statistics
from dataclasses import dataclass, field
from pathlib import Path

MARK_START = "<!-- seq-bench:start -->"
MARK_END = "<!-- seq-bench:end -->"


# --------------------------------------------------------------------------- index


@dataclass
class Reference:
    """A published value of an instance, from `index.csv`."""

    name: str
    kind: str
    dimension: int
    value: float | None
    status: str
    path: str

    @property
    def label(self) -> str:
        """Short tag for the table: opt, BKS (best known) or UB (upper bound)."""
        s = self.status.lower()
        if s.startswith("optimal"):
            return "opt"
        if s.startswith("best known"):
            return "BKS"
        if s.startswith("upper bound"):
            return "UB"
        return "?"


def load_index(path: Path) -> dict[str, Reference]:
    """Rows of `index.csv`, keyed by their `path` column (relative to the data folder)."""
    out = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            value = float(row["value"]) if row["value"].strip() else None
            out[row["path"]] = Reference(
                row["name"], row["type"], int(row["dimension"]), value, row["value_status"], row["path"]
            )
    return out


def read_instance_list(path: Path) -> list[str]:
    """Instance paths (relative to the data folder), one a line; `#` starts a comment."""
    out = []
    for line in Path(path).read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            out.append(line)
    return out


# --------------------------------------------------------------------------- model


class PointCosts:
    """The cost matrix of a coordinate instance, each entry computed when read: what `Model`
    holds for instances too large for `towpath convert --matrix` (over 5,000 points; a full
    matrix of Python floats at 10,000 points would take gigabytes). `costs[i][j]` as for a list
    of rows; only TSPLIB's EUC_2D (`euclidean_nint`: the Euclidean distance rounded to the
    nearest integer) and CEIL_2D (`euclidean_ceil`)."""

    METRICS = ("euclidean_nint", "euclidean_ceil")

    def __init__(self, points: list[list[float]], metric: str):
        if metric not in self.METRICS:
            raise ValueError(f"metric {metric!r} is not computed on demand (only {', '.join(self.METRICS)})")
        if any(len(p) != 2 for p in points):
            raise ValueError("only 2-D points are computed on demand")
        self.points = [(float(p[0]), float(p[1])) for p in points]
        self.metric = metric

    def cost(self, i: int, j: int) -> float:
        (xi, yi), (xj, yj) = self.points[i], self.points[j]
        d = math.hypot(xi - xj, yi - yj)
        return float(math.floor(d + 0.5) if self.metric == "euclidean_nint" else math.ceil(d))

    def __len__(self) -> int:
        return len(self.points)

    def __getitem__(self, i: int) -> "_PointRow":
        if not 0 <= i < len(self.points):
            raise IndexError(i)
        return _PointRow(self, i)

    def __iter__(self):
        return (self[i] for i in range(len(self.points)))


class _PointRow:
    """Row `i` of a [`PointCosts`] matrix."""

    def __init__(self, costs: PointCosts, i: int):
        self.costs, self.i = costs, i

    def __getitem__(self, j: int) -> float:
        return self.costs.cost(self.i, j)

    def __len__(self) -> int:
        return len(self.costs)

    def __iter__(self):
        return (self.costs.cost(self.i, j) for j in range(len(self.costs)))


@dataclass
class Model:
    """The part of a towpath JSON problem the benchmark needs: states with an explicit matrix
    (None = forbidden move), tasks with modes (entry, exit, cost), precedence between tasks,
    pins and ends. Tasks and states are 0-based indices."""

    matrix: list[list[float | None]] | PointCosts
    modes: list[list[tuple[int, int, float]]]
    precedence: list[tuple[int, int]] = field(default_factory=list)
    start: int | None = None
    end: str = "closed"  # "closed", "free" or "at"
    end_state: int | None = None
    first: int | None = None
    last: int | None = None
    ids: list[str] = field(default_factory=list)

    @property
    def n(self) -> int:
        return len(self.matrix)

    @property
    def num_tasks(self) -> int:
        return len(self.modes)

    @staticmethod
    def from_json(doc: dict) -> "Model":
        """Reads a towpath JSON problem that has `states.matrix` (write it with
        `towpath convert --matrix`), or 2-D `states.points` with a metric [`PointCosts`]
        computes."""
        states = doc["states"]
        if "matrix" in states:
            matrix = states["matrix"]
        elif "points" in states and states.get("metric") in PointCosts.METRICS:
            matrix = PointCosts(states["points"], states["metric"])
        else:
            raise ValueError("the problem has no explicit matrix: convert it with --matrix")
        ids = [t["id"] for t in doc["tasks"]]
        index = {tid: k for k, tid in enumerate(ids)}
        modes = [
            [(m["entry"], m.get("exit", m["entry"]), float(m.get("cost", 0.0))) for m in t["modes"]]
            for t in doc["tasks"]
        ]
        end = doc.get("end", "closed")
        end_state = None
        if isinstance(end, dict):
            end_state, end = end["at"], "at"
        return Model(
            matrix=matrix,
            modes=modes,
            precedence=[(index[a], index[b]) for a, b in doc.get("precedence", [])],
            start=doc.get("start"),
            end=end,
            end_state=end_state,
            first=index[doc["first"]] if doc.get("first") is not None else None,
            last=index[doc["last"]] if doc.get("last") is not None else None,
            ids=ids,
        )

    def state_owner(self) -> dict[int, tuple[int, int]]:
        """(task, mode) of each state, for problems whose modes are single states, each state in
        one mode only (TSP, ATSP, SOP, GTSP and PCGTSP converted by towpath)."""
        owner = {}
        for t, ms in enumerate(self.modes):
            for k, (a, b, _) in enumerate(ms):
                if a != b or a in owner:
                    raise ValueError("states do not name modes one to one")
                owner[a] = (t, k)
        return owner

    def sets(self) -> list[list[int]]:
        """The entry states of each task (a GTSP's sets)."""
        return [[m[0] for m in ms] for ms in self.modes]


class Infeasible(Exception):
    """A route that breaks the problem's rules."""


def steps_from_states(model: Model, states: list[int]) -> list[tuple[int, int]]:
    """A route given as visited states (one per task) turned into (task, mode) steps."""
    owner = model.state_owner()
    steps = []
    for s in states:
        if s not in owner:
            raise Infeasible(f"state {s} is not a mode of any task")
        steps.append(owner[s])
    return steps


def check_route(model: Model, steps: list[tuple[int, int]]) -> float:
    """Checks a route independently of any solver and returns its cost. A closed tour without a
    start state is read as a cycle (rotated to begin with the pinned first task, if any).
    Raises `Infeasible` with the reason."""
    steps = list(steps)
    if len(steps) != model.num_tasks:
        raise Infeasible(f"{len(steps)} steps for {model.num_tasks} tasks")
    seen = set()
    for t, k in steps:
        if not (0 <= t < model.num_tasks) or not (0 <= k < len(model.modes[t])):
            raise Infeasible(f"step ({t}, {k}) names no task and mode")
        if t in seen:
            raise Infeasible(f"task {model.ids[t] if model.ids else t} is done twice")
        seen.add(t)
    cyclic = model.end == "closed" and model.start is None
    if cyclic and model.first is not None:
        k = next(i for i, (t, _) in enumerate(steps) if t == model.first)
        steps = steps[k:] + steps[:k]
    if model.first is not None and steps[0][0] != model.first:
        raise Infeasible("the pinned first task is not first")
    if model.last is not None and steps[-1][0] != model.last:
        raise Infeasible("the pinned last task is not last")
    pos = {t: i for i, (t, _) in enumerate(steps)}
    for a, b in model.precedence:
        if pos[a] > pos[b]:
            raise Infeasible(f"precedence {a} -> {b} broken")

    def move(i: int, j: int) -> float:
        c = model.matrix[i][j]
        if c is None or not math.isfinite(c):
            raise Infeasible(f"forbidden move {i} -> {j}")
        return c

    total = 0.0
    prev = model.start
    for t, k in steps:
        entry, exit_, cost = model.modes[t][k]
        if prev is not None:
            total += move(prev, entry)
        total += cost
        prev = exit_
    if model.end == "at":
        total += move(prev, model.end_state)
    elif model.end == "closed":
        back = model.start if model.start is not None else model.modes[steps[0][0]][steps[0][1]][0]
        total += move(prev, back)
    return total


def price_states(model: Model, states: list[int]) -> float:
    """Checks a route given as visited states; see `check_route`."""
    return check_route(model, steps_from_states(model, states))


def topological_tasks(model: Model) -> list[int]:
    """A feasible task order: topological under precedence (lowest index first among ready
    tasks), with the pinned first and last tasks at the ends."""
    import heapq

    n = model.num_tasks
    succ: list[list[int]] = [[] for _ in range(n)]
    indeg = [0] * n
    for a, b in set(model.precedence):
        succ[a].append(b)
        indeg[b] += 1
    ready = [t for t in range(n) if indeg[t] == 0 and t not in (model.first, model.last)]
    heapq.heapify(ready)
    order = [model.first] if model.first is not None else []
    if model.first is not None:
        for b in succ[model.first]:
            indeg[b] -= 1
            if indeg[b] == 0 and b != model.last:
                heapq.heappush(ready, b)
    while ready:
        t = heapq.heappop(ready)
        order.append(t)
        for b in succ[t]:
            indeg[b] -= 1
            if indeg[b] == 0 and b not in (model.first, model.last):
                heapq.heappush(ready, b)
    if model.last is not None and model.last != model.first:
        order.append(model.last)
    if len(order) != n:
        raise Infeasible("precedence has a cycle")
    return order


# --------------------------------------------------------------------------- GTSP -> ATSP


def noon_bean(matrix: list[list[float | None]], sets: list[list[int]]) -> tuple[list[list[int]], int]:
    """The Noon–Bean transformation of a GTSP (sets partitioning the states) into an ATSP over the
    same states: inside each set a zero-cost cycle v1 -> v2 -> ... -> vk -> v1; leaving the set
    from v_i to a node w of another set costs c(v_{i+1}, w) + M; other moves cost `big`. A tour
    that visits each set's nodes consecutively, entering at v_j, costs the GTSP tour through the
    entry nodes plus M per set. Returns (integer matrix, M)."""
    n = len(matrix)
    finite = [c for row in matrix for c in row if c is not None and math.isfinite(c)]
    cmax = int(max(finite)) if finite else 1
    m_pen = 10 * (cmax + 1)
    big = 4 * (cmax + m_pen)
    set_of = {}
    for k, s in enumerate(sets):
        for v in s:
            set_of[v] = k
    a = [[big] * n for _ in range(n)]
    for s in sets:
        k = len(s)
        for i, v in enumerate(s):
            nxt = s[(i + 1) % k]
            if k > 1:
                a[v][nxt] = 0
            for w in range(n):
                if set_of.get(w) != set_of[v]:
                    c = matrix[nxt][w]
                    a[v][w] = big if c is None else int(round(c)) + m_pen
    return a, m_pen


def noon_bean_decode(tour: list[int], sets: list[list[int]]) -> list[int]:
    """The GTSP route (one state per set) read from an ATSP tour of `noon_bean`: the entry node of
    each run of a set's nodes; a set met again in a later run keeps its first run."""
    set_of = {v: k for k, s in enumerate(sets) for v in s}
    if not tour:
        return []
    # Rotate so that the tour starts at the beginning of a run.
    n = len(tour)
    r = next((i for i in range(n) if set_of[tour[i]] != set_of[tour[i - 1]]), 0)
    tour = tour[r:] + tour[:r]
    out, done, prev = [], set(), None
    for v in tour:
        k = set_of[v]
        if k != prev and k not in done:
            out.append(v)
            done.add(k)
        prev = k
    return out


# --------------------------------------------------------------------------- statistics


def median(values: list[float]) -> float | None:
    """Median of the values, None if there are none."""
    vals = [v for v in values if v is not None]
    return statistics.median(vals) if vals else None


def gap_percent(cost: float | None, reference: float | None) -> float | None:
    """(cost - reference) / reference in percent; None if either is unknown."""
    if cost is None or reference is None or reference == 0:
        return None
    return 100.0 * (cost - reference) / reference


def ratio(a: float | None, b: float | None) -> float | None:
    """a / b, None if either is unknown or b is 0."""
    if a is None or b is None or b == 0:
        return None
    return a / b


# --------------------------------------------------------------------------- table


def fmt_cost(c: float | None) -> str:
    if c is None:
        return "–"
    return f"{c:.0f}" if abs(c - round(c)) < 1e-9 else f"{c:.2f}"


def fmt_pct(g: float | None) -> str:
    return "–" if g is None else f"{g:.2f}"


def fmt_time(t: float | None) -> str:
    return "–" if t is None else f"{t:.1f}"


def fmt_ratio(r: float | None) -> str:
    return "–" if r is None else f"{r:.4f}"


@dataclass
class Cell:
    """One solver's medians on one instance, or why it has none."""

    cost: float | None = None
    time: float | None = None
    runs: int = 0
    feasible: int = 0
    note: str = ""  # "n/a", "infeasible", ...


def summarize(results: list[dict]) -> Cell:
    """Medians over the runs of one solver on one instance. Each result has `cost` (None if no
    feasible answer), `time` and optionally `status` ("n/a" for a peer that cannot express the
    instance)."""
    if not results:
        return Cell(note="not run")
    if all(r.get("status") == "n/a" for r in results):
        return Cell(note="n/a")
    feasible = [r for r in results if r.get("cost") is not None]
    cell = Cell(
        cost=median([r["cost"] for r in feasible]),
        time=median([r.get("time") for r in results]),
        runs=len(results),
        feasible=len(feasible),
    )
    if not feasible:
        reasons = sorted({r.get("status", "no answer") for r in results})
        cell.note = "; ".join(reasons)
    elif len(feasible) < len(results):
        cell.note = f"{len(feasible)}/{len(results)} feasible"
    # Footnotes a solver's worker attached to its answers (they start with a dagger).
    marks = sorted({r["note"][0] for r in feasible if r.get("note", "").startswith("†")})
    if marks:
        cell.note = " ".join(filter(None, [cell.note, *marks]))
    return cell


def render_table(rows: list[dict], peers: list[str]) -> str:
    """The markdown table. Each row: name, kind, n, ref (Reference or None), and `cells`:
    solver -> Cell for "towpath" and each peer."""
    head = ["instance", "type", "n", "reference", "towpath", "gap %", "time s"]
    for p in peers:
        head += [p, "gap %", "time s", f"tp/{p}"]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---:" if i > 1 else "---" for i in range(len(head))) + "|"]
    for row in rows:
        ref = row["ref"]
        refv = ref.value if ref else None
        reftext = f"{fmt_cost(refv)} ({ref.label})" if ref and refv is not None else "–"
        tp = row["cells"].get("towpath", Cell(note="not run"))
        cols = [row["name"], row["kind"], str(row["n"]), reftext]
        cols += cell_cols(tp, refv)
        for p in peers:
            c = row["cells"].get(p, Cell(note="not run"))
            cols += cell_cols(c, refv)
            cols.append(fmt_ratio(ratio(tp.cost, c.cost)))
        lines.append("| " + " | ".join(cols) + " |")
    return "\n".join(lines)


def cell_cols(c: Cell, refv: float | None) -> list[str]:
    if c.cost is None:
        return [c.note or "–", "–", fmt_time(c.time)]
    cost = fmt_cost(c.cost) + (f" ({c.note})" if c.note else "")
    return [cost, fmt_pct(gap_percent(c.cost, refv)), fmt_time(c.time)]


def replace_between_markers(text: str, body: str, heading: str) -> str:
    """Puts `body` between the seq-bench markers of `text`, adding a section with `heading` and
    the markers at the end if they are missing."""
    block = f"{MARK_START}\n{body.rstrip()}\n{MARK_END}"
    if MARK_START in text and MARK_END in text:
        a = text.index(MARK_START)
        b = text.index(MARK_END) + len(MARK_END)
        return text[:a] + block + text[b:]
    sep = "" if not text or text.endswith("\n\n") else ("\n" if text.endswith("\n") else "\n\n")
    return f"{text}{sep}{heading}\n\n{block}\n"
