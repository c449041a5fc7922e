#!/usr/bin/env bash
# The floor a driven mission sweeps (docs/benchmarks.md section 18): for
# every IPA building, plan on the plain map and drive the furnished one
# (`covplan simulate --true-map`, AUTO replanning, the thesis robot and
# sensor), then measure on the furnished map's pixels the area the tool can
# reach, the share of it the driven path swept, the offline plan's share
# (OARP planned on the furnished map), the cells the robot reported for
# furniture smaller than a cell, and how far it still drove through
# furniture (length_in_obstacles_m, issue 32's item 5). The maps are read in
# place, never copied.
#   bash scripts/bench/floor_driven.sh     # TOOL=0.8 JOBS=2 IPA_DIR=../shared/data/maps/ipa
set -euo pipefail
cd "$(dirname "$0")/../.."
TOOL=${TOOL:-0.8}
JOBS=${JOBS:-2}
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "floor_driven: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
[ -x build/bin/covplan ] || bash scripts/build.sh >/dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export TOOL IPA out
run() {  # one plain map's name
  build/bin/covplan simulate --map "$IPA/$1.png" --true-map "$IPA/$1_furnitures.png" \
    --resolution 0.05 --free-thresh 0.021 --tool-width "$TOOL" --max-speed 1 --acceleration 0.5 \
    --turn-rate 30 --sensor-range 5.6 --time-limit 1 --method auto --local >"$out/$1.json"
}
export -f run
maps=$(for f in "$IPA"/*_furnitures.png; do basename "$f" _furnitures.png; done)
printf '%s\n' $maps | xargs -P "$JOBS" -I{} bash -c 'run {}'
echo "| map | reachable m² (furnished) | driven: swept of reachable | missed m² | offline plan: swept of reachable | small obstacles reported | in obstacles m | of the driven path |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|"
for m in $maps; do
  /usr/bin/python3 - "$m" "$out/$m.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[2]))
print("| %s | %.1f | %.2f %% | %.1f | %.2f %% | %d | %.1f | %.2f %% |" % (
    sys.argv[1], r["reachable_area_m2"], 100 * r["swept_reachable_ratio"], r["missed_reachable_m2"],
    100 * r["offline_swept_reachable_ratio"], r["small_obstacles_found"], r["length_in_obstacles_m"],
    100 * r["length_in_obstacles_m"] / r["path_length_m"]))
PY
done
