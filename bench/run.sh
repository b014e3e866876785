#!/usr/bin/env bash
# Runs Sewn's benchmark suites and writes their reports.
#
#   bench/run.sh [suite...]          full sizes; writes bench/results/<suite>.md and .json
#   bench/run.sh --small [suite...]  small sizes; prints each suite's table, writes nothing
#   bench/run.sh --smoke             tiny sizes, every suite, one quick run each; writes nothing
#                                    (CI: proves the suites build, run, pass their checks and
#                                    report, in seconds)
#   bench/run.sh --list              prints the suites
#
# With no suite named, every suite runs: a suite is a folder bench/<suite>/ with a
# CMakeLists.txt defining the executable bench_<suite> (see bench/CMakeLists.txt).
# Full and small runs first call `tools/bootstrap bench` (installs CGAL and gnuplot if missing);
# the smoke run uses what is installed. Every run configures and builds the release preset.
#
# Ours and the peer are measured in the same process, their repetitions interleaved at random
# (the machine is noisy), and the report quotes medians. SEWN_BENCH_REPETITIONS and
# SEWN_BENCH_MIN_TIME (seconds per repetition) override the defaults below. To run one
# benchmark by hand:
#   SEWN_BENCH_SCALE=small build/release/bench/cmap/bench_cmap --benchmark_filter=hex8/build
#
# A suite may add bench/<suite>/published.json (published figures, see bench/report.py) and an
# executable bench/<suite>/plot hook, run as `plot RAW.json OUT_DIR` after the benchmarks, which
# writes OUT_DIR/<suite>-*.svg with gnuplot; the report links those plots. An executable
# bench/<suite>/derive, run as `derive RAW.json`, prints rows and sections computed from several
# benchmarks (fitted slopes, goal checks; see bench/report.py), and bench/<suite>/notes.md holds
# the suite's method notes; the report includes both.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=full
suites=()
for arg in "$@"; do
  case "$arg" in
    --smoke) mode=smoke ;;
    --small) mode=small ;;
    --list) mode=list ;;
    -h|--help) sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"; exit 0 ;;
    -*) echo "bench/run.sh: unknown option $arg (see --help)" >&2; exit 2 ;;
    *) suites+=("$arg") ;;
  esac
done

all=()
for f in bench/*/CMakeLists.txt; do
  [[ -e "$f" ]] && all+=("$(basename "$(dirname "$f")")")
done
if [[ $mode == list ]]; then
  printf '%s\n' "${all[@]}"
  exit 0
fi
if [[ $mode == smoke && ${#suites[@]} -gt 0 ]]; then
  echo "bench/run.sh: --smoke always runs every suite" >&2
  exit 2
fi
((${#suites[@]})) || suites=("${all[@]}")
if ((${#suites[@]} == 0)); then
  echo "bench/run.sh: no suite under bench/ yet, nothing to run"
  exit 0
fi
for s in "${suites[@]}"; do
  [[ -f "bench/$s/CMakeLists.txt" ]] || { echo "bench/run.sh: no suite '$s' (have: ${all[*]})" >&2; exit 2; }
done

case $mode in
  full) reps=10 min_time=0.2 ;;
  small) reps=3 min_time=0.05 ;;
  smoke) reps=1 min_time=0.001 ;;
esac
reps=${SEWN_BENCH_REPETITIONS:-$reps}
min_time=${SEWN_BENCH_MIN_TIME:-$min_time}

[[ $mode == smoke ]] || tools/bootstrap bench
cmake --preset release >/dev/null
targets=()
for s in "${suites[@]}"; do targets+=("bench_$s"); done
cmake --build --preset release --target "${targets[@]}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for s in "${suites[@]}"; do
  echo "::: bench $s ($mode: $reps repetitions, ${min_time}s each)"
  raw="$tmp/$s.raw.json"
  run=(env SEWN_BENCH_SCALE=$mode "build/release/bench/$s/bench_$s"
       --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true
       --benchmark_min_time="$min_time" --benchmark_out="$raw" --benchmark_out_format=json)
  if [[ $mode == small ]]; then
    # the table is what a person wants here; the per-benchmark log only when something fails
    "${run[@]}" >"$tmp/$s.log" 2>&1 || { cat "$tmp/$s.log"; exit 1; }
  else
    "${run[@]}"
  fi

  out=bench/results
  [[ $mode == full ]] || out="$tmp/results"
  mkdir -p "$out"
  plots=()
  if [[ -x "bench/$s/plot" ]]; then
    rm -f "$out/$s"-*.svg
    "bench/$s/plot" "$raw" "$out"
    for p in "$out/$s"-*.svg; do [[ -e "$p" ]] && plots+=(--plot "$p"); done
  fi
  extra=()
  if [[ -x "bench/$s/derive" ]]; then
    "bench/$s/derive" "$raw" >"$tmp/$s.derived.json"
    extra+=(--derived "$tmp/$s.derived.json")
  fi
  [[ -f "bench/$s/notes.md" ]] && extra+=(--notes "bench/$s/notes.md")
  report=(python3 bench/report.py --suite "$s" --raw "$raw" --published "bench/$s/published.json" "${plots[@]}"
          "${extra[@]}")
  if [[ $mode == small ]]; then
    "${report[@]}" --print
  else
    "${report[@]}" --out-dir "$out"
  fi
  if [[ $mode == full ]]; then echo "::: wrote $out/$s.md and $out/$s.json"; fi
done
