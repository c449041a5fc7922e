#!/usr/bin/env bash
# Battery-constrained tours on every plain building of ../shared/data/maps/ipa
# (0.05 m/px, tool 0.8 m, IPA colour rule free_thresh 0.021), for OARP,
# boustrophedon and STC plans (PLANNERS="oarp boustrophedon stc"), two battery capacities, energy = distance (m), reserve
# 5 % of the capacity.
# Prints first the unconstrained plans (turns, path length, estimated
# duration, covered free-area ratio, planning time), then per map, planner
# and capacity: charge cycles, total energy, the unconstrained energy of the
# same tour from the station and back, the lower bound (unconstrained + the
# station visits no split of this order avoids) and the gap to it. The
# station (the same for both planners) is the first of the unconstrained
# OARP plan's coverage waypoints not on an obstacle pixel (the engine refuses
# those).
#   scripts/bench/bench_battery.sh [CAPACITY_A CAPACITY_B]     (default 400 200)
# The maps are licensed for academic, non-commercial use: they are read in
# place and never copied into this repository.
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "bench_battery: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
BUILD_DIR=${BUILD_DIR:-build-h}
CLI="$BUILD_DIR/bin/covplan"
[ -x "$CLI" ] || { echo "bench_battery: build $CLI first (ninja -C $BUILD_DIR covplan)" >&2; exit 2; }
CAPS=("${1:-400}" "${2:-200}")
read -r -a PLANNER_LIST <<< "${PLANNERS:-oarp boustrophedon stc}"
PY=/usr/bin/python3
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
common=(--local --resolution 0.05 --free-thresh 0.021 --tool-width 0.8 --time-limit 1 --seed 1)
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%F)"
maps=()
for f in "$IPA"/*.png; do
  case "$f" in *_furnitures.png) ;; *) maps+=("$f") ;; esac
done
printf '| map | planner | turns | length m | duration s | covered | planning ms |\n|---|---|---:|---:|---:|---:|---:|\n'
for f in "${maps[@]}"; do
  name=$(basename "$f" .png)
  for planner in "${PLANNER_LIST[@]}"; do
    "$CLI" plan --map "$f" "${common[@]}" --planner "$planner" --out "$TMP/$name.$planner.json" >/dev/null 2>&1 || continue
    $PY - "$TMP/$name.$planner.json" "$name" "$planner" <<'PYEOF'
import json, sys
s = json.load(open(sys.argv[1]))["stats"]
print("| %s | %s | %d | %.1f | %.0f | %.1f %% | %.0f |" % (sys.argv[2], sys.argv[3], s["num_turns"],
      s["coverage_length_m"] + s["transition_length_m"], s["estimated_duration_s"],
      100 * s["covered_free_area_ratio"], s["planning_ms"]))
PYEOF
  done
done
echo
printf '| map | planner | station | capacity | cycles | energy | unconstrained | lower bound | gap |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n'
for f in "${maps[@]}"; do
  name=$(basename "$f" .png)
  for planner in "${PLANNER_LIST[@]}"; do
    extra=()
    [ "$planner" = boustrophedon ] && extra=(--interruptible)
    plain="$TMP/$name.$planner.json"
    [ -f "$plain" ] || { echo "| $name | $planner | | - | unconstrained plan failed | | | | |"; continue; }
    for cap in "${CAPS[@]}"; do
      reserve=$($PY -c "print($cap * 0.05)")
      ok=0
      for station in $($PY -c 'import json,sys
p=[w for w in json.load(open(sys.argv[1]))["path"] if w["kind"]=="COVERAGE"]
print(" ".join("%.3f,%.3f" % (w["x"], w["y"]) for w in p[:8]))' "$TMP/$name.oarp.json"); do
        if "$CLI" plan --map "$f" "${common[@]}" --planner "$planner" "${extra[@]}" --battery-capacity "$cap" \
             --reserve "$reserve" --station "$station" --out "$TMP/bat.json" >/dev/null 2>"$TMP/err"; then
          ok=1; break
        fi
        grep -q "lies in an obstacle" "$TMP/err" || break
      done
      if [ "$ok" = 1 ]; then
        $PY - "$TMP/bat.json" "$name" "$planner" "$cap" "$station" <<'PYEOF'
import json, sys
r = json.load(open(sys.argv[1])); s = r["stats"]
e, lb = s["energy_total"], s["energy_lower_bound"]
print("| %s | %s | %s | %s | %d | %.1f | %.1f | %.1f | %.1f %% |" % (sys.argv[2], sys.argv[3], sys.argv[5], sys.argv[4],
      s["charge_cycles"], e, s["energy_unconstrained"], lb, 100.0 * (e - lb) / lb))
PYEOF
      else
        echo "| $name | $planner | $station | $cap | refused: $(tr '\n' ' ' < "$TMP/err" | head -c 160) | | | | |"
      fi
    done
  done
done
