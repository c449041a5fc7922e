#!/usr/bin/env bash
# Reproduces the planner comparison of docs/benchmarks.md: `covplan compare`
# on every plain building of ../shared/data/maps/ipa (not the *_furnitures
# variants; 0.05 m/px, IPA colour rule grey >= 250 is free, i.e.
# free_thresh 0.021, tool 0.8 m, as scripts/bench/bench_maps.sh), one markdown
# table for all maps on stdout (and in $OUT when set).
#   scripts/bench/compare_planners.sh [ALGORITHMS] [more covplan compare flags...]
#   ALGORITHMS: comma-separated planner names, e.g. oarp,stc,boustrophedon
#               (default: every planner the build registers)
# COVPLAN_BIN runs an existing binary instead of building build-release/.
# The maps are licensed for academic, non-commercial use: they are read in
# place and never copied into this repository.
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "compare_planners: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
algorithms=()
listed="(every registered planner)"
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then
  algorithms=(--algorithms "$1")
  listed=$1
  shift
fi
BIN=${COVPLAN_BIN:-}
if [ -z "$BIN" ]; then
  BUILD_DIR=${BUILD_DIR:-build-release}
  BUILD_TYPE=Release BUILD_DIR="$BUILD_DIR" bash scripts/build.sh -DCOVPLAN_BUILD_TESTS=OFF >/dev/null
  BIN="$BUILD_DIR/bin/covplan"
fi
out=$(mktemp)
trap 'rm -f "$out"' EXIT
{
  echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%F)"
  echo "planners: $listed; extra flags: ${*:-none}"
  echo
  header=1
  for f in "$IPA"/*.png; do
    case "$f" in *_furnitures.png) continue ;; esac
    flags=(--markdown --name "$(basename "$f" .png)")
    [ "$header" = 1 ] || flags+=(--no-header)
    "$BIN" compare --map "$f" --resolution 0.05 --free-thresh 0.021 --tool-width 0.8 \
      "${algorithms[@]}" "${flags[@]}" "$@"
    header=0
  done
} | tee "$out"
if [ -n "${OUT:-}" ]; then cp "$out" "$OUT"; fi
