"""The elastic suite's convergence families, read from a raw benchmark JSON (shared by derive
and plot). families(): the static solves, family (answer, name, size label) -> {size: (error %,
CPU ms per solve)}; dynamic_families(): the runs from release to rest, the same keys ->
{size: (error %, CPU s per simulated s)}."""

import re

TIMOSHENKO_MM = 14.868  # the cantilever's answer, Euler-Bernoulli plus shear (PHYSICS_NOTES §4)
# shell_course.cpp's cases -> their answer (the published value they are compared with)
SHELL_COURSE = {"scordelis_lo": "Scordelis-Lo roof vs 0.3024", "hemisphere": "pinched hemisphere vs 0.094",
                "pinched_cylinder": "pinched cylinder vs 1.8248e-5"}


def families(raw):
    out = {}
    for b in raw["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = b.get("run_name", b["name"])
        ms = b["cpu_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
        m = re.match(r"elastic/shell_strip/([a-z]+)/([a-z]+)/nx(\d+)/", name)
        if m and "error vs Euler-Bernoulli %" in b:
            out.setdefault(("shell strip vs Euler-Bernoulli", f"{m.group(1)}, {m.group(2)}", "nx"), {})[int(m.group(3))] = (
                b["error vs Euler-Bernoulli %"], ms)
            continue
        m = re.match(r"elastic/shell_course/([a-z_]+)/([a-z]+)/([a-z]+)/n(\d+)/", name)
        if m and "error vs reference %" in b:
            out.setdefault((SHELL_COURSE[m.group(1)], f"{m.group(2)}, {m.group(3)}", "n"), {})[int(m.group(4))] = (
                b["error vs reference %"], ms)
            continue
        m = re.match(r"elastic/rod_elastica/seg(\d+)/", name)
        if m and "error vs elastica %" in b:
            out.setdefault(("rod end-moment cantilever vs the elastica", "discrete elastic rod (tip / L)", "segments"), {})[
                int(m.group(1))] = (b["error vs elastica %"], ms)
            continue
        m = re.match(r"elastic/cantilever/N(\d+)/([a-z]+)/", name)
        if m and "error vs Timoshenko %" in b:
            out.setdefault(("StVK tet cantilever vs Timoshenko", f"Kuhn tets, {m.group(2)}", "N"), {})[int(m.group(1))] = (
                b["error vs Timoshenko %"], ms)
        # the mass-spring beam (bench/mss/cantilever.cpp): its static tip, against the tets' answer
        m = re.match(r"elastic/cantilever/static/N(\d+)/", name)
        if m and "_tip_mm" in b:
            out.setdefault(("mass-spring cantilever vs Timoshenko", "cubes of springs, static", "N"), {})[int(m.group(1))] = (
                100.0 * abs(b["_tip_mm"] - TIMOSHENKO_MM) / TIMOSHENKO_MM, ms)
    return out


def step_label(h):
    return f"h = {h * 1e3:g} ms"


# The runs to rest of to_rest.cpp: name pattern (its last group the size) -> (answer, family
# with the pattern's other groups and the step filled in, size label).
RUNS_TO_REST = [
    (r"elastic/to_rest/tets/N(\d+)/", "StVK tet cantilever vs Timoshenko", "Kuhn tets, Newton BE {h}", "N"),
    (r"elastic/to_rest/shell_strip/([a-z]+)/([a-z]+)/nx(\d+)/", "shell strip vs Euler-Bernoulli",
     "{0}, {1}, Newton BE {h}", "nx"),
    (r"elastic/to_rest/rod/seg(\d+)/", "rod cantilever under its weight vs Euler-Bernoulli",
     "discrete elastic rod, Newton BE {h}", "segments"),
]


def dynamic_families(raw):
    """Runs from release to rest: cost per simulated second against the error of the rest state."""
    out = {}
    for b in raw["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration" or "_cpu_s_per_simulated_s" not in b:
            continue
        name = b.get("run_name", b["name"])
        cost = b["_cpu_s_per_simulated_s"]
        for pattern, answer, family, size in RUNS_TO_REST:
            m = re.match(pattern, name)
            if m:
                key = (answer, family.format(*m.groups()[:-1], h=step_label(b["_h"])), size)
                out.setdefault(key, {})[int(m.groups()[-1])] = (b["error %"], cost)
                break
        # the mass-spring beam run to rest by linearly implicit Euler (bench/mss/cantilever.cpp)
        m = re.match(r"elastic/cantilever/N(\d+)/implicit_h1e-2/", name)
        if m and "_tip_mm" in b:
            out.setdefault(("mass-spring cantilever vs Timoshenko",
                            f"cubes of springs, linearly implicit Euler {step_label(b['_h'])}", "N"), {})[int(m.group(1))] = (
                100.0 * abs(b["_tip_mm"] - TIMOSHENKO_MM) / TIMOSHENKO_MM, cost)
    return out
