"""The elastic suite's convergence families, read from a raw benchmark JSON (shared by derive
and plot): family (answer, name, size label) -> {size: (error %, CPU ms per solve)}."""

import re


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
        m = re.match(r"elastic/rod_elastica/seg(\d+)/", name)
        if m and "error vs elastica %" in b:
            out.setdefault(("rod end-moment cantilever vs the elastica", "discrete elastic rod (tip / L)", "segments"), {})[
                int(m.group(1))] = (b["error vs elastica %"], ms)
            continue
        m = re.match(r"elastic/cantilever/N(\d+)/([a-z]+)/", name)
        if m and "error vs Timoshenko %" in b:
            out.setdefault(("StVK tet cantilever vs Timoshenko", f"Kuhn tets, {m.group(2)}", "N"), {})[int(m.group(1))] = (
                b["error vs Timoshenko %"], ms)
    return out
