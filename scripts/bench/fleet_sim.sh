#!/usr/bin/env bash
# Fleet simulation with a failing robot (docs/benchmarks.md, "Fleet
# simulation"): three robots plan an IPA building (lab_a_scan, plain map) and
# drive it as it is, sensing and replanning as the single-robot simulator
# does; one robot fails at a third of the planned makespan and what nobody
# has swept then is divided again between the two survivors, from where they
# stand (covplan simulate --robot ... --fail-robot ID@S). Printed: the
# makespan driven, the redivision's estimated makespan (a fresh 2-robot plan
# of what was left) against the time the survivors took after the failure,
# and the reachable cells nobody swept. True maps: the plain map with 10 %
# random clutter (as scripts/bench/eval_replan.sh makes it, seeds 1..SEEDS)
# and the furnished map X_furnitures.png. Each true map is driven once
# without a failure too. Starts: farthest-first over the 0.8 m drive grid
# (as fleet_bench spreads them): the north-east wing, the south-west corner,
# the south-east wing.
#
#   bash scripts/bench/fleet_sim.sh        # about 3 min on 2 cores
#   SEEDS=3 FAIL=r1 bash scripts/bench/fleet_sim.sh
#
# Environment: IPA_DIR, BUILD_DIR (build), MAP (lab_a_scan), ROBOTS (the
# --robot flags), FAIL (the robot that fails, r2), BUDGET (planning budget,
# 2 s), SEEDS (1), TRUTHS ("clutter10 furnished"), OUT_DIR (a temp dir: the
# runs' JSON and SVG are kept there). The maps are licensed for academic,
# non-commercial use: they are read in place and never copied.
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "fleet_sim: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
BUILD_DIR=${BUILD_DIR:-build}
MAP=${MAP:-lab_a_scan}
ROBOTS=${ROBOTS:-"--robot r1=32.4,34 --robot r2=2,6 --robot r3=39.6,6"}
FAIL=${FAIL:-r2}
BUDGET=${BUDGET:-2}
SEEDS=${SEEDS:-1}
TRUTHS=${TRUTHS:-"clutter10 furnished"}
OUT_DIR=${OUT_DIR:-$(mktemp -d /tmp/fleet_sim.XXXXXX)}
mkdir -p "$OUT_DIR"
[ -x "$BUILD_DIR/bin/covplan" ] || BUILD_DIR="$BUILD_DIR" bash scripts/build.sh >/dev/null
COVPLAN="$BUILD_DIR/bin/covplan"
PY=/usr/bin/python3
# The robot and sensor of the replanning evaluation (eval_replan.sh).
COMMON="--resolution 0.05 --free-thresh 0.021 --tool-width 0.8 --max-speed 1 --acceleration 0.5 \
--turn-rate 30 --time-limit $BUDGET"

# The failure comes at a third of the fleet plan's makespan on the known map.
# shellcheck disable=SC2086
"$COVPLAN" plan --local --map "$IPA/$MAP.png" $COMMON $ROBOTS --out "$OUT_DIR/plan.json" >/dev/null
makespan=$($PY -c 'import json,sys; print(json.load(open(sys.argv[1]))["makespan_s"])' "$OUT_DIR/plan.json")
t_fail=$($PY -c "print(round($makespan / 3, 1))")
echo "# $MAP: fleet plan makespan $(printf %.1f "$makespan") s on the known map; $FAIL fails at $t_fail s"

runs=()
run() {  # LABEL TRUE-MAP-FLAGS [--fail-robot ...]
  local label=$1 truth=$2
  shift 2
  echo
  echo "## $label"
  echo "\$ covplan simulate --map $IPA/$MAP.png $truth $COMMON --sensor-range 5.6 $ROBOTS $*"
  # shellcheck disable=SC2086
  "$COVPLAN" simulate --map "$IPA/$MAP.png" $truth $COMMON --sensor-range 5.6 $ROBOTS "$@" \
    --out "$OUT_DIR/$label.json" --svg "$OUT_DIR/$label.svg"
  runs+=("$label")
}
for truth in $TRUTHS; do
  case "$truth" in
    clutter10)
      for seed in $(seq 1 "$SEEDS"); do
        run "clutter10-seed$seed" "--clutter 10 --seed $seed"
        run "clutter10-seed$seed-fail" "--clutter 10 --seed $seed" --fail-robot "$FAIL@$t_fail"
      done
      ;;
    furnished)
      run furnished "--true-map $IPA/${MAP}_furnitures.png"
      run furnished-fail "--true-map $IPA/${MAP}_furnitures.png" --fail-robot "$FAIL@$t_fail"
      ;;
    *) echo "fleet_sim: unknown true map set '$truth'" >&2 && exit 2 ;;
  esac
done

echo
echo "| true map | failure | planned makespan s | driven makespan s | cells left | redivision estimate s | achieved after failure s | ratio | unswept reachable |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
for label in "${runs[@]}"; do
  $PY - "$OUT_DIR/$label.json" "$label" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
label = sys.argv[2]
truth = label[:-5] if label.endswith("-fail") else label
cells = f"{r['unswept_reachable_cells']} of {r['reachable_cells']}"
if r["redivisions"]:
    d = r["redivisions"][0]
    print(f"| {truth} | {d['failed_robot']} at {d['time_s']:.1f} s | {r['planned_makespan_s']:.1f} | "
          f"{r['makespan_s']:.1f} | {d['left_cells']} | {d['estimated_makespan_s']:.1f} | "
          f"{d['achieved_s']:.1f} | {d['achieved_over_estimated']:.3f} | {cells} |")
else:
    print(f"| {truth} | none | {r['planned_makespan_s']:.1f} | {r['makespan_s']:.1f} | | | | | {cells} |")
EOF
done
echo
echo "runs kept in $OUT_DIR"
