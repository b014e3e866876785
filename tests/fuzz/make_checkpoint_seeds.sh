#!/usr/bin/env bash
# Writes the seeds of fuzz_checkpoint (tests/fuzz/corpus/fuzz_checkpoint/) with a built sewn:
# small runs, each stopped at its second checkpoint, that together fill every part of the
# format: each integrator's history, a cut, a piercing, refinement and coarsening records with
# the hysteresis counters, rods' angles and frames, cholmod-pcg's kept factorization (when the
# build has CHOLMOD). Run it after a change of the checkpoint format:
#
#   tests/fuzz/make_checkpoint_seeds.sh build/release/apps/sewn
set -euo pipefail
sewn=$(realpath "$1")
dir=$(cd "$(dirname "$0")" && pwd)/corpus/fuzz_checkpoint
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# seed NAME JSON: runs the scene NAME and keeps its checkpoint
seed() {
  printf '%s' "$2" >"$work/$1.json"
  "$sewn" run --quiet --checkpoint-every 1 --stop-after-checkpoints 2 --out "$work/$1" "$work/$1.json" || return 1
  cp "$work/$1/$1.checkpoint" "$dir/$1.checkpoint"
  echo "$1.checkpoint: $(stat -c %s "$dir/$1.checkpoint") bytes"
}

# cube NAME INTEGRATOR [MORE]: one 10 cm hexahedron held at its base
cube() {
  seed "$1" '{"name": "'"$1"'", "materials": {"m": {"young": 1e5, "density": 1000}},
    "meshes": [{"type": "hex_grid", "material": "m", "cells": [1, 1, 1], "size": [0.1, 0.1, 0.1]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}}],
    "integrator": '"$2"', "duration": 0.004, "output": {"frames": 4}'"${3:-}"'}'
}

rm -f "$dir"/*.checkpoint
cube cube_semi '{"type": "semi-implicit", "step": 1e-4}'
cube cube_implicit '{"type": "implicit", "step": 1e-3}'
cube cube_midpoint '{"type": "midpoint", "step": 1e-3}'
cube cube_newton '{"type": "newton", "step": 1e-3}'
cube cube_pcg '{"type": "implicit", "step": 1e-3, "solver": "cholmod-pcg"}' || echo "(a build without CHOLMOD: no cube_pcg.checkpoint)"
seed bar_cut '{"name": "bar_cut", "materials": {"m": {"young": 1e5, "density": 1000}},
  "meshes": [{"type": "hex_grid", "material": "m", "cells": [3, 1, 1], "size": [0.3, 0.1, 0.1]}],
  "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
  "integrator": {"type": "implicit", "step": 1e-3}, "duration": 0.004, "output": {"frames": 4},
  "cuts": [{"type": "plane", "time": 0, "point": [0.1, 0, 0], "normal": [1, 0, 0]},
           {"type": "pierce", "time": 0.001, "where": {"type": "box", "min": [0.2, -1, -1], "max": [0.3, 1, 1]}}]}'
seed refined '{"name": "refined", "materials": {"m": {"young": 1e4, "density": 1000}},
  "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
  "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
  "integrator": {"type": "implicit", "step": 2e-3}, "duration": 0.008, "output": {"frames": 4},
  "refinement": {"criteria": [{"type": "diagonal_strain", "threshold": 0.01}], "max_level": 2, "coarsen": true, "calm_steps": 1}}'
seed rod '{"name": "rod", "materials": {"w": {"young": 1e8, "density": 1500}},
  "meshes": [{"type": "polyline", "material": "w", "points": [[0, 0, 0], [0.03, 0.01, -0.01], [0.05, 0.03, -0.02], [0.06, 0.06, -0.03]]}],
  "model": {"type": "mixed", "groups": [{"tag": 0, "as": "rod", "semi_axes": [0.004, 0.002]}]}, "damping": {"model": "none"},
  "fixed": [{"where": {"type": "points", "indices": [0, 1]}}],
  "integrator": {"type": "newton", "step": 1e-3}, "duration": 0.004, "output": {"frames": 4}}'
