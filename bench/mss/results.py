"""Reads bench_mss's Google Benchmark JSON for the derive and plot scripts (stdlib only).

Medians over repetitions of the CPU time (in the benchmark's unit) and of every counter,
"_"-prefixed facts included, per (case, side), as bench/report.py takes them. Benchmarks that
reported an error are skipped here; report.py refuses to write a report when there are any.
"""

import json
import math
import re
import statistics

OPTION_SUFFIX = re.compile(r"^(real_time|process_time|manual_time|iterations:\d+|repeats:\d+|"
                           r"min_time:[0-9.e+-]+s?|min_warmup_time:[0-9.e+-]+s?|threads:\d+)$")
STANDARD = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
            "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit", "label",
            "error_occurred", "error_message", "aggregate_name", "aggregate_unit"}
TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}

# PHYSICS_NOTES §4: tip deflections (mm) of the MSS (Baudet, ν = 0.3) from a linear static solve,
# quoted by the notes' author. A cross-check of our own solves, never used as a result.
NOTES_TIP_MM = {2: 10.28, 4: 12.87, 8: 13.78, 16: 14.03}


class Result:
    def __init__(self):
        self.times_us = []
        self.counters = {}
        self.label = None

    @property
    def us(self):
        return statistics.median(self.times_us)

    def c(self, name, default=None):
        v = self.counters.get(name)
        return statistics.median(v) if v else default


def load(path):
    """{(case, side): Result}, case without the "mss/" prefix."""
    with open(path, encoding="utf-8") as f:
        raw = json.load(f)
    out = {}
    for b in raw.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration" or b.get("error_occurred"):
            continue
        parts = b.get("run_name", b["name"]).split("/")
        while parts and OPTION_SUFFIX.match(parts[-1]):
            parts.pop()
        if len(parts) < 3 or parts[-1] not in ("ours", "peer"):
            continue
        key = ("/".join(parts[1:-1]), parts[-1])
        r = out.setdefault(key, Result())
        r.times_us.append(b["cpu_time"] * TO_US[b["time_unit"]])
        if b.get("label"):
            r.label = b["label"]
        for k, v in b.items():
            if k not in STANDARD and isinstance(v, (int, float)):
                r.counters.setdefault(k, []).append(v)
    return out


def get(res, case, side="ours"):
    return res.get((case, side))


def fit_slope(points):
    """Least-squares slope of log(y) against log(x) over (x, y) points; None if fewer than 2."""
    pts = [(math.log(x), math.log(y)) for x, y in points if x and y and x > 0 and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    return sxy / sxx if sxx > 0 else None


def fit_line(points):
    """(slope, intercept) of log10(y) = slope·log10(x) + intercept, or None."""
    pts = [(math.log10(x), math.log10(y)) for x, y in points if x and y and x > 0 and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx <= 0:
        return None
    slope = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx
    return slope, my - slope * mx


def scaleup(res):
    """[(N, dof, h, {series: (us, cg_iterations)})] for the scale-up cubes, by N."""
    rows = []
    ns = sorted({int(case.split("/")[1][1:]) for case, _ in res if case.startswith("scaleup/N")})
    for n in ns:
        base = f"scaleup/N{n}"
        series = {}
        for name, case, side in (("ours semi-implicit", base + "/semi_implicit", "ours"),
                                 ("CGAL LCC+MSS semi-implicit", base + "/semi_implicit", "peer"),
                                 ("bare loop semi-implicit", base + "/semi_implicit_vs_bare", "peer"),
                                 ("ours implicit", base + "/implicit", "ours"),
                                 ("CGAL LCC+MSS implicit", base + "/implicit", "peer")):
            r = get(res, case, side)
            if r:
                series[name] = (r.us, r.c("cg_iterations"))
        any_r = get(res, base + "/semi_implicit") or get(res, base + "/implicit")
        if any_r is None:
            continue
        rows.append((n, any_r.c("_dof"), any_r.c("_h"), series))
    return rows


def cantilever(res):
    """(statics {N: Result}, runs [(case, Result)]) of the cantilever family."""
    statics, runs = {}, []
    for (case, side), r in res.items():
        if side != "ours" or not case.startswith("cantilever/"):
            continue
        if case.startswith("cantilever/static/N"):
            statics[int(case.rsplit("N", 1)[1])] = r
        else:
            runs.append((case, r))
    runs.sort(key=lambda cr: (cr[1].c("_n"), cr[0]))
    return statics, runs


def reference(statics):
    """The extrapolated tip deflection: from the three finest static solves N/4, N/2, N the
    observed order p = log2((t(N/2) - t(N/4)) / (t(N) - t(N/2))) and t∞ = t(N) + (t(N) - t(N/2)) /
    (2^p - 1). Returns (t∞, p, finest N) or None with fewer than three solves."""
    ns = sorted(statics)
    if len(ns) < 3:
        return None
    n1, n2, n3 = ns[-3:]
    if not (n2 == 2 * n1 and n3 == 2 * n2):
        return None
    t1, t2, t3 = (statics[n].c("_tip_mm") for n in (n1, n2, n3))
    ratio = (t2 - t1) / (t3 - t2)
    if not ratio > 1:
        return None
    p = math.log2(ratio)
    return t3 + (t3 - t2) / (2 ** p - 1), p, n3


def run_label(case):
    """'cantilever/N4/implicit_h1e-3' -> ('implicit', 1e-3) or ('semi-implicit', None)."""
    kind = case.split("/")[-1]
    if kind.startswith("implicit_h"):
        return "implicit", float(kind[len("implicit_h"):])
    return "semi-implicit", None


def pareto(points, rel_tol=1e-3):
    """Indices of the points (error, cost) no other point dominates: j dominates i if its error is
    no larger and its cost no larger, one of them strictly. Errors within rel_tol of each other
    count as equal: runs of one resolution settle on the same equilibrium to about 1e-6, and the
    extrapolated reference is itself uncertain by about 1e-3 (see derive)."""
    front = []
    for i, (x, y) in enumerate(points):
        dominated = False
        for j, (x2, y2) in enumerate(points):
            if j == i:
                continue
            no_worse = x2 <= x * (1 + rel_tol) and y2 <= y
            better = x2 < x * (1 - rel_tol) or y2 < y
            if no_worse and better:
                dominated = True
                break
        if not dominated:
            front.append(i)
    return front
