#!/usr/bin/env bash
# The floor a plan sweeps, measured on the map's pixels (docs/benchmarks.md
# section 18): for the shipped office and every plain IPA building, one
# `covplan plan --local` at tool TOOL (0.8 m), and from its plan.json the
# area the tool can reach, the share of it the path sweeps, the reachable
# area it misses, the grid's own coverage figure, and the measure's time
# (floor_ms: building the reachable floor, not cached in a one-shot CLI run,
# plus stamping the path). The IPA maps are read in place, never copied.
#   bash scripts/bench/floor.sh        # TOOL=0.8 IPA_DIR=../shared/data/maps/ipa
set -euo pipefail
cd "$(dirname "$0")/../.."
TOOL=${TOOL:-0.8}
IPA=${IPA_DIR:-../shared/data/maps/ipa}
[ -x build/bin/covplan ] || bash scripts/build.sh >/dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| map | reachable m² | swept of reachable | missed m² | grid: covered free area | floor ms | planning ms |"
echo "|---|---:|---:|---:|---:|---:|---:|"
row() {  # name, covplan plan arguments...
  local name=$1
  shift
  build/bin/covplan plan --local --tool-width "$TOOL" "$@" --out "$out/p.json" >/dev/null
  /usr/bin/python3 - "$name" "$out/p.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[2]))["stats"]
g = lambda k: float(s.get(k, s.get(''.join(w.title() if i else w for i, w in enumerate(k.split('_'))), 0)))
print("| %s | %.1f | %.2f %% | %.1f | %.2f %% | %.0f | %.0f |" % (
    sys.argv[1], g("reachable_area_m2"), 100 * g("swept_reachable_ratio"), g("missed_reachable_m2"),
    100 * g("covered_free_area_ratio"), g("floor_ms"), g("planning_ms")))
PY
}
row sample_office.yaml --map maps/sample_office.yaml
for m in "$IPA"/*.png; do
  case "$m" in *furnitures*) continue ;; esac
  row "$(basename "$m")" --map "$m" --resolution 0.05 --free-thresh 0.021
done
