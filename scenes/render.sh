#!/usr/bin/env bash
# Runs every example scene (scenes/*.json), and the built-in default scene, to its end and
# copies the picture of its last frame to docs/pictures/<scene>.png, the pictures the README shows. Regenerate them with this script
# after changing a scene or the renderer; never edit them by hand.
#
#   scenes/render.sh            all scenes and the default one
#   scenes/render.sh default    only the default scene
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
  for s in "$@"; do [[ $s == default ]] && scenes+=(default) || scenes+=("scenes/${s%.json}.json"); done
else
  scenes=(default scenes/*.json)
fi
mkdir -p docs/pictures
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  start=$(date +%s%N)
  if [[ $name == default ]]; then
    build/release/apps/sewn run --out "out/$name" --quiet
  else
    rm -f "out/$name/$name.png"
    build/release/apps/sewn run "$scene" --out "out/$name" --quiet
  fi
  if [[ ! -e "out/$name/$name.png" ]]; then  # skipped: its optional data is absent (scenes/fetch_data.sh)
    printf '%-28s skipped\n' "$name"
    continue
  fi
  cp "out/$name/$name.png" "docs/pictures/$name.png"
  ms=$((($(date +%s%N) - start) / 1000000))
  printf '%-28s %6d ms  -> docs/pictures/%s.png\n' "$name" "$ms" "$name"
done
