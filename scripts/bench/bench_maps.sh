#!/usr/bin/env bash
# Reproduces the real-map tables of docs/benchmarks.md: plans every plain
# building of ../shared/data/maps/ipa (0.05 m/px, tool 0.8 m; IPA colour
# rule grey >= 250 is free, i.e. free_thresh 0.021) with both partition
# solvers and both tour solvers, and compares the tour with a 30 s search.
#   scripts/bench/bench_maps.sh [--time-limit S] [--runs N] [--reference-s S] [--no-lp]
# The maps are licensed for academic, non-commercial use: they are read in
# place and never copied into this repository.
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "bench_maps: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
BUILD_DIR=${BUILD_DIR:-build-release}
BUILD_TYPE=Release BUILD_DIR="$BUILD_DIR" bash scripts/build.sh -DCOVPLAN_BUILD_TESTS=OFF -DCOVPLAN_BUILD_SERVER=OFF >/dev/null
maps=()
for f in "$IPA"/*.png; do
  case "$f" in *_furnitures.png) ;; *) maps+=("$f") ;; esac
done
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%F)"
"$BUILD_DIR"/bin/map_bench --resolution 0.05 --free-thresh 0.021 --tool-width 0.8 \
  --threads 2 --time-limit 0.5 --runs 5 --reference-s 30 "$@" "${maps[@]}"
