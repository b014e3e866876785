#!/usr/bin/env bash
# Extracts the optional data some example scenes use into scenes/data/ (not in the repository):
#   bunny00.off   the 2014 paper's rabbit (scenes/refine_fig10_rabbit.json), from the CGAL data
#                 that Debian's libcgal-demo package installs (apt-get install libcgal-demo).
# A scene whose data is absent is skipped by `sewn run` with a message (exit 0).
set -euo pipefail
cd "$(dirname "$0")"
archive=/usr/share/doc/libcgal-dev/data.tar.gz
if [[ ! -f $archive ]]; then
  echo "fetch_data.sh: $archive is not present (install Debian's libcgal-demo); nothing extracted" >&2
  exit 1
fi
mkdir -p data
tar xzf "$archive" -O data/meshes/bunny00.off > data/bunny00.off.part
mv data/bunny00.off.part data/bunny00.off
echo "fetch_data.sh: wrote scenes/data/bunny00.off"
