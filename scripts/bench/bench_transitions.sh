#!/usr/bin/env bash
# Transitions that scale (docs/benchmarks.md section 13): plans a generated
# warehouse (~5,700 ranks at a 0.3 m tool), an open 50 m lawn at a 0.05 m
# tool (10^6 cells, ~1,100 ranks) and an IPA office at 0.3 m (lab_a_scan,
# ~500 ranks) with `covplan plan --local`, each with a "before" binary and
# the current one, and measures wall time and peak RSS (/usr/bin/time -v).
#   BEFORE=/path/to/old/covplan AFTER=build-rel/bin/covplan scripts/bench/bench_transitions.sh [OUT_DIR]
# Old binaries are run without --threads (they do not have it) and capped
# with `timeout 300`. The 60 s rows run the new solver with
# --tour-effort thorough (keeps searching for the whole budget).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-/tmp/covplan-bench-transitions}
AFTER=${AFTER:-build-rel/bin/covplan}
BEFORE=${BEFORE:-}
IPA=${IPA_DIR:-../shared/data/maps/ipa}
mkdir -p "$OUT"
/usr/bin/python3 scripts/maps/gen_warehouse.py warehouse "$OUT"
/usr/bin/python3 scripts/maps/gen_warehouse.py lawn "$OUT"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%FT%TZ)"

run() {  # label binary args...
  local label=$1 bin=$2
  shift 2
  local log="$OUT/$(echo "$label" | tr ' /' '__').log"
  timeout 300 /usr/bin/time -v "$bin" plan --local "$@" >"$log" 2>&1
  local rc=$?
  local wall rss ranks dur tour err
  wall=$(grep -m1 "Elapsed (wall clock)" "$log" | awk '{print $NF}')
  rss=$(grep -m1 "Maximum resident set size" "$log" | awk '{print int($NF/1024)}')
  ranks=$(grep -m1 "^ranks" "$log" | awk '{print $2}')
  dur=$(grep -m1 "^duration" "$log" | awk '{print $2}')
  tour=$(grep -m1 "^tour" "$log" | cut -c12- | cut -d, -f1,3)
  err=""
  [ $rc -ne 0 ] && err="exit $rc: $(grep -m1 "covplan plan:" "$log" | cut -c1-110)"
  [ $rc -eq 124 ] && err="timeout 300 s"
  printf '| %s | %s | %s MiB | %s | %s s | %s %s |\n' "$label" "$wall" "$rss" "${ranks:--}" "${dur:--}" "${tour:-}" "$err"
}

echo "| run | wall | peak RSS | ranks | est. duration | tour / error |"
echo "|---|---|---|---|---|---|"
OFFICE=("--map" "$IPA/lab_a_scan.png" "--resolution" "0.05" "--tool-width" "0.3")
WARE=("--map" "$OUT/warehouse.yaml" "--tool-width" "0.3")
LAWN=("--map" "$OUT/lawn.yaml" "--tool-width" "0.05")
if [ -n "$BEFORE" ]; then
  run "before office default" "$BEFORE" "${OFFICE[@]}"
  run "before office --time-limit 1" "$BEFORE" "${OFFICE[@]}" --time-limit 1
  run "before office --time-limit 60" "$BEFORE" "${OFFICE[@]}" --time-limit 60
  run "before warehouse" "$BEFORE" "${WARE[@]}"
  run "before lawn" "$BEFORE" "${LAWN[@]}"
fi
run "after office default" "$AFTER" "${OFFICE[@]}" --threads 2
run "after office --time-limit 1" "$AFTER" "${OFFICE[@]}" --threads 2 --time-limit 1
run "after office 60 s thorough" "$AFTER" "${OFFICE[@]}" --threads 2 --time-limit 60 --tour-effort thorough
run "after warehouse default" "$AFTER" "${WARE[@]}" --threads 2
run "after warehouse 60 s thorough" "$AFTER" "${WARE[@]}" --threads 2 --time-limit 60 --tour-effort thorough
run "after lawn default" "$AFTER" "${LAWN[@]}" --threads 2
run "after lawn 60 s thorough" "$AFTER" "${LAWN[@]}" --threads 2 --time-limit 60 --tour-effort thorough
