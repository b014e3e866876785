#!/usr/bin/env bash
# Runs every example scene (scenes/*.json) to its end and copies the picture of its last frame
# to docs/pictures/<scene>.png, the pictures the README shows. Regenerate them with this script
# after changing a scene or the renderer; never edit them by hand.
#
#   scenes/render.sh            all scenes
#   scenes/render.sh fig05_unsew fig12_pierce   only these
#
# Builds the release preset first. The full output of each run (ParaView series, frames.csv)
# stays in out/<scene>/ for a closer look.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake --preset release >/dev/null
cmake --build --preset release --target sewn >/dev/null

if (($#)); then
  scenes=()
  for s in "$@"; do scenes+=("scenes/${s%.json}.json"); done
else
  scenes=(scenes/*.json)
fi
mkdir -p docs/pictures
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  start=$(date +%s%N)
  build/release/apps/sewn run "$scene" --out "out/$name" --quiet
  cp "out/$name/$name.png" "docs/pictures/$name.png"
  ms=$((($(date +%s%N) - start) / 1000000))
  printf '%-28s %6d ms  -> docs/pictures/%s.png\n' "$name" "$ms" "$name"
done
