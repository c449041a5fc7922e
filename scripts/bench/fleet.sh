#!/usr/bin/env bash
# Fleet figures for docs/benchmarks.md: the makespan division against its
# lower bound and the equal-area baseline on the ten IPA buildings in
# ../shared/data (plain maps, tool 0.8 m), k = 1, 2, 3, 4, 8 robots starting
# at spread-out places (k = 1: the single-robot plan against the bound), and
# the generated warehouse (tool 0.3 m, k = 8).
#   bash scripts/bench/fleet.sh            # BUDGET=0.8 TOOL=0.8 ROBOTS=1,2,3,4,8
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA:-../shared/data/maps/ipa}
BUDGET=${BUDGET:-0.8}
[ -x build/bin/fleet_bench ] || bash scripts/build.sh >/dev/null
# The IPA scans mark free space at 0.021 (docs/benchmarks.md, map_bench).
build/bin/fleet_bench --tool "${TOOL:-0.8}" --budget "$BUDGET" --robots "${ROBOTS:-1,2,3,4,8}" \
  --free-thresh 0.021 $(ls "$IPA"/*.png | grep -v furnitures)
if [ "${WAREHOUSE:-1}" = 1 ]; then
  out=$(mktemp -d)
  /usr/bin/python3 scripts/maps/gen_warehouse.py warehouse "$out"
  /usr/bin/time -f "warehouse peak RSS %M KiB, %e s" build/bin/fleet_bench --tool 0.3 \
    --budget "${WAREHOUSE_BUDGET:-3}" --threads 2 --robots 8 "$out/warehouse.yaml"
  rm -rf "$out"
fi
