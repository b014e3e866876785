#!/usr/bin/env python3
"""Turns one suite's Google Benchmark JSON output into the report every suite shares.

    report.py --suite S --raw RAW.json [--published P.json] --out-dir DIR   writes DIR/S.md, DIR/S.json
    report.py --suite S --raw RAW.json [--published P.json] --print         prints the table only
    (--plot FILE, repeatable: an SVG beside the report, linked from it)

Benchmarks are named "<suite>/<case>/ours" and "<suite>/<case>/peer" (see
bench/harness/sewn_bench.hpp); a peer's label is its name. Each (case, metric) becomes a row:
the time in the benchmark's unit, then one row per user counter, named by the counter. Values
are medians over the repetitions; times are the CPU time of the benchmark's thread, because the
measured code is single-threaded and, on a shared machine, wall time also counts the time the
thread waited for a core. Any benchmark that reported an error fails the report: nothing is
written, so a broken operation cannot leave a fast-looking number behind.

The published sidecar maps a case to a paper's figure:
    {"hex32/step": {"published": 0.55, "source": "seed 002, Table 1", "metric": "ms"}}
("metric" defaults to the case's time unit).

A counter whose name starts with "_" is a fact for a suite's scripts (a mesh size, a step),
not a row. A suite may also pass --derived, the output of its bench/<suite>/derive script
(run by bench/run.sh on the same raw results): {"rows": [...], "sections": [{"title": ...,
"markdown": ...}]}. Its rows (the same shape as ours: slopes, ratios, values computed from
several benchmarks) join the table and the JSON; its sections (summaries, goal checks) are
printed after the header. --notes adds a suite's static method notes at the end.
"""

import argparse
import json
import os
import re
import statistics
import sys
from datetime import datetime

# Fields Google Benchmark writes for every run; anything else is a user counter.
STANDARD_FIELDS = {
    "name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
    "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit", "label",
    "error_occurred", "error_message", "aggregate_name", "aggregate_unit",
}
# Name components Google Benchmark appends for options set on a benchmark.
OPTION_SUFFIX = re.compile(r"^(real_time|process_time|manual_time|iterations:\d+|repeats:\d+|"
                           r"min_time:[0-9.e+-]+s?|min_warmup_time:[0-9.e+-]+s?|threads:\d+)$")
SIDES = ("ours", "peer")


def fail(msg):
    print(f"report.py: {msg}", file=sys.stderr)
    sys.exit(1)


def split_name(name, suite):
    """'cmap/hex16/build/ours/real_time' -> ('hex16/build', 'ours')."""
    parts = name.split("/")
    while parts and OPTION_SUFFIX.match(parts[-1]):
        parts.pop()
    if len(parts) < 3 or parts[0] != suite or parts[-1] not in SIDES:
        fail(f"benchmark '{name}' is not named '{suite}/<case>/ours' or '{suite}/<case>/peer'")
    return "/".join(parts[1:-1]), parts[-1]


def cpu_model():
    """The first CPU's model name, with its family/model numbers and clock: a virtual machine's
    name alone ("Intel(R) Xeon(R) Processor") does not tell one generation from another."""
    fields = {}
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if not line.strip():
                    break
                key, _, value = line.partition(":")
                fields[key.strip()] = value.strip()
    except OSError:
        pass
    if "model name" not in fields:
        return "unknown CPU"
    detail = [f"family {fields[k]}" if k == "cpu family" else f"model {fields[k]}"
              for k in ("cpu family", "model") if k in fields]
    if "cpu MHz" in fields:
        detail.append(f"{float(fields['cpu MHz']):.0f} MHz")
    return fields["model name"] + (f" ({', '.join(detail)})" if detail else "")


def collect(raw, suite):
    """Per (case, side): times, time unit, counters, label, registration order."""
    errors = [f"{b['name']}: {b.get('error_message', 'error')}" for b in raw["benchmarks"] if b.get("error_occurred")]
    if errors:
        fail("benchmarks reported errors, no report written:\n  " + "\n  ".join(errors))
    runs = {}
    for b in raw["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue  # aggregates: we take our own medians over the repetitions
        case, side = split_name(b.get("run_name", b["name"]), suite)
        r = runs.setdefault((case, side), {"time": [], "unit": b["time_unit"], "counters": {}, "label": None,
                                            "order": b.get("family_index", 0)})
        r["time"].append(b["cpu_time"])
        if b.get("label"):
            r["label"] = b["label"]
        for k, v in b.items():
            if k not in STANDARD_FIELDS and not k.startswith("_") and isinstance(v, (int, float)):
                r["counters"].setdefault(k, []).append(v)
    if not runs:
        fail("no benchmark ran")
    return runs


def round_sig(v, digits=4):
    return None if v is None else float(f"{v:.{digits}g}")


def ratio(a, b):
    return a / b if a is not None and b not in (None, 0) else None


def build_rows(runs, published):
    cases = {}
    for (case, side), r in runs.items():
        c = cases.setdefault(case, {})
        c[side] = r
    # a case's place: where ours was registered (one translation unit, so a stable order)
    def order(case):
        sides = cases[case]
        return (sides["ours"]["order"] if "ours" in sides else min(s["order"] for s in sides.values()), case)

    rows = []
    for case in sorted(cases, key=order):
        sides = cases[case]
        units = {r["unit"] for r in sides.values()}
        if len(units) != 1:
            fail(f"case {case}: ours and peer use different time units {sorted(units)}")
        unit = units.pop()
        metrics = [(unit, {s: r["time"] for s, r in sides.items()})]
        for name in sorted({k for r in sides.values() for k in r["counters"]}):
            metrics.append((name, {s: r["counters"][name] for s, r in sides.items() if name in r["counters"]}))
        pub = published.get(case, {})
        for metric, values in metrics:
            med = {s: statistics.median(v) for s, v in values.items()}
            has_pub = pub and pub.get("metric", unit) == metric
            rows.append({
                "case": case,
                "metric": metric,
                "ours": round_sig(med.get("ours")),
                "peer": round_sig(med.get("peer")),
                "peer_name": sides["peer"]["label"] if "peer" in sides else None,
                "published": pub.get("published") if has_pub else None,
                "source": pub.get("source") if has_pub else None,
            })
    for case in published:
        if case not in cases:
            print(f"report.py: warning: published figure for case '{case}', which did not run", file=sys.stderr)
    return rows


def fmt(v):
    if v is None:
        return "–"
    a = abs(v)
    if a >= 100:
        return f"{v:.0f}"
    if a >= 10:
        return f"{v:.1f}"
    if a >= 1:
        return f"{v:.2f}"
    return f"{v:.3g}"


ROW_KEYS = ("case", "metric", "ours", "peer", "peer_name", "published", "source")


def load_derived(path):
    """Rows and sections a suite's derive script computed; checked for the shared row shape."""
    with open(path, encoding="utf-8") as f:
        derived = json.load(f)
    rows = derived.get("rows", [])
    for r in rows:
        if set(r) != set(ROW_KEYS):
            fail(f"{path}: derived row {r} does not have exactly the keys {list(ROW_KEYS)}")
    sections = derived.get("sections", [])
    for sec in sections:
        if not isinstance(sec.get("title"), str) or not isinstance(sec.get("markdown"), str):
            fail(f"{path}: a derived section needs a 'title' and a 'markdown' string")
    return rows, sections


def machine_load(ctx):
    """The 1-minute load average at the benchmarks' start (Google Benchmark's context) and now,
    as text; "" where neither is known."""
    start = ctx.get("load_avg") or []
    now = None
    try:
        with open("/proc/loadavg", encoding="utf-8") as f:
            now = float(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        pass
    if not start and now is None:
        return ""
    fmt_load = lambda v: "unknown" if v is None else f"{v:.2f}"
    return f"{fmt_load(start[0] if start else None)} / {fmt_load(now)}"


def markdown(suite, header, rows, reps, scale, date, plots, written, sections=(), notes=None):
    out = [f"# {suite} benchmarks" + ("" if scale == "full" else f" ({scale} sizes)"), ""]
    if written:
        out += [f"Written by `bench/run.sh {suite}`: regenerate, never edit.", ""]
    out.append(f"- CPU: {header['cpu']}")
    out.append(f"- Compiler: {header['compiler']}")
    if header.get("blas"):
        out.append(f"- Dense kernels of CHOLMOD's factorizations: {header['blas']}")
    out.append(f"- Date: {date}")
    if header.get("load"):
        out.append(f"- Machine load (1-minute average) when the benchmarks started / when the report was written: "
                   f"{header['load']}. Above the CPU count other work shared the machine: absolute times are "
                   "inflated, ratios within the run less so.")
    out.append(f"- Each value is the median of {reps} repetitions, ours and the peer interleaved at random in one "
               "run; times are CPU time of the benchmark thread.")
    out.append("- ours/peer and ours/published below 1 favour ours, except for metrics marked "
               "\"higher is better\".")
    for sec in sections:
        out += ["", f"## {sec['title']}", "", sec["markdown"].rstrip("\n")]
    groups = {}
    for r in rows:
        groups.setdefault(r["peer_name"], []).append(r)
    for peer, group in groups.items():
        out += ["", f"## Peer: {peer}" if peer else "## No peer", ""]
        out.append("| case | metric | ours | peer | ours/peer | published | ours/published |")
        out.append("|---|---|---:|---:|---:|---:|---:|")
        for r in group:
            pub = fmt(r["published"]) + (f" ({r['source']})" if r["source"] else "")
            out.append(f"| {r['case']} | {r['metric']} | {fmt(r['ours'])} | {fmt(r['peer'])} | "
                       f"{fmt(ratio(r['ours'], r['peer']))} | {pub} | {fmt(ratio(r['ours'], r['published']))} |")
    if plots:
        out += ["", "## Plots", ""]
        out += [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in plots]
    if notes:
        out += ["", notes.rstrip("\n")]
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--suite", required=True)
    ap.add_argument("--raw", required=True, help="Google Benchmark JSON output")
    ap.add_argument("--published", help="the suite's published.json, if any")
    ap.add_argument("--plot", action="append", default=[], help="an SVG written beside the report")
    ap.add_argument("--derived", help="rows and sections from the suite's derive script (JSON)")
    ap.add_argument("--notes", help="the suite's method notes (markdown), appended to the report")
    dest = ap.add_mutually_exclusive_group(required=True)
    dest.add_argument("--out-dir", help="write <suite>.md and <suite>.json here")
    dest.add_argument("--print", action="store_true", help="print the table, write nothing")
    args = ap.parse_args()

    with open(args.raw, encoding="utf-8") as f:
        raw = json.load(f)
    published = {}
    if args.published and os.path.exists(args.published):
        with open(args.published, encoding="utf-8") as f:
            published = json.load(f)

    ctx = raw.get("context", {})
    runs = collect(raw, args.suite)
    rows = build_rows(runs, published)
    sections = []
    if args.derived:
        extra, sections = load_derived(args.derived)
        rows += extra
    notes = None
    if args.notes:
        with open(args.notes, encoding="utf-8") as f:
            notes = f.read()
    cpus = ctx.get("num_cpus") or os.cpu_count()
    header = {
        "suite": args.suite,
        "cpu": f"{cpu_model()} ({cpus} logical CPUs)",
        "compiler": ctx.get("sewn_build", "unknown compiler"),
        "blas": ctx.get("sewn_blas"),
        "load": machine_load(ctx),
    }
    reps = max(len(r["time"]) for r in runs.values())
    date = ctx.get("date") or datetime.now().isoformat(timespec="seconds")
    md = markdown(args.suite, header, rows, reps, ctx.get("sewn_scale", "full"), date, args.plot,
                  written=not args.print, sections=sections, notes=notes)
    if args.print:
        sys.stdout.write(md)
        return
    os.makedirs(args.out_dir, exist_ok=True)
    with open(os.path.join(args.out_dir, f"{args.suite}.json"), "w", encoding="utf-8") as f:
        json.dump({**header, "rows": rows}, f, indent=2, ensure_ascii=False)
        f.write("\n")
    with open(os.path.join(args.out_dir, f"{args.suite}.md"), "w", encoding="utf-8") as f:
        f.write(md)


if __name__ == "__main__":
    main()
