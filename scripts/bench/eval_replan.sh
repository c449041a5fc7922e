#!/usr/bin/env bash
# The replanning evaluation of docs/benchmarks.md §7 (thesis §4.6): the robot
# plans OARP on a plain IPA building and drives it through the building as it
# is, replanning with each method when its 5.6 m line-of-sight sensor finds
# new obstacles; compared with the offline lower bound (OARP planned on the
# true map). Three datasets:
#   furnished  known X.png, true X_furnitures.png, every map, every method;
#   clutter10  known X.png, true = X.png + 10 % random rectangles, SEEDS seeds;
#   levels     LEVEL_MAP at 2, 5, 10, 15, 20 % clutter, LEVEL_SEEDS seeds.
# Robot and sensor as the thesis: tool 0.8 m, 1 m/s, 0.5 m/s^2, 30 deg/s, 5.6 m.
#
#   scripts/bench/eval_replan.sh                 # about 20 min on 2 cores
#   CLUTTER_MAPS=all scripts/bench/eval_replan.sh  # clutter on every map too: about 35 min
#   SEEDS=2 MAPS="lab_ipa lab_b_scan" CLUTTER_MAPS=all scripts/bench/eval_replan.sh
#
# Environment: IPA_DIR, BUILD_DIR (build-release), JOBS (parallel runs, 2),
# MAPS (all plain maps), CLUTTER_MAPS (the maps of clutter10: "all" = MAPS; by
# default the seven whose runs are quick enough for 20 min, i.e. without
# lab_a_scan, lab_f_scan and lab_intel), SEEDS (5), FULL_SEEDS (1: how many clutter seeds also
# run ilp1, ilp2 and full; greedy_detour and auto run on every seed), LEVEL_MAP
# (lab_ipa), LEVELS ("2 5 10 15 20"), LEVEL_SEEDS (5), SETS ("furnished
# clutter10 levels"), OUT_DIR (where runs.jsonl is kept; default a temp dir),
# SKIP_BUILD (set: use the covplan already in BUILD_DIR).
# Prints the markdown tables on stdout. The maps are licensed for academic,
# non-commercial use: they are read in place and never copied.
set -euo pipefail
cd "$(dirname "$0")/../.."
IPA=${IPA_DIR:-../shared/data/maps/ipa}
if [ ! -d "$IPA" ]; then
  echo "eval_replan: $IPA not found (the IPA maps live in ../shared/data, outside the repo)" >&2
  exit 2
fi
BUILD_DIR=${BUILD_DIR:-build-release}
JOBS=${JOBS:-2}
SEEDS=${SEEDS:-5}
FULL_SEEDS=${FULL_SEEDS:-1}
LEVEL_MAP=${LEVEL_MAP:-lab_ipa}
LEVELS=${LEVELS:-"2 5 10 15 20"}
LEVEL_SEEDS=${LEVEL_SEEDS:-5}
SETS=${SETS:-"furnished clutter10 levels"}
OUT_DIR=${OUT_DIR:-$(mktemp -d /tmp/eval_replan.XXXXXX)}
mkdir -p "$OUT_DIR"
if [ -z "${MAPS:-}" ]; then
  MAPS=""
  for f in "$IPA"/*.png; do
    case "$f" in *_furnitures.png) ;; *) MAPS="$MAPS $(basename "$f" .png)" ;; esac
  done
fi
CLUTTER_MAPS=${CLUTTER_MAPS:-"Freiburg101_scan Freiburg52_scan Freiburg79_scan lab_b_scan lab_c_scan lab_d_scan lab_ipa"}
[ "$CLUTTER_MAPS" = all ] && CLUTTER_MAPS=$MAPS

if [ -z "${SKIP_BUILD:-}" ]; then
  BUILD_TYPE=Release BUILD_DIR="$BUILD_DIR" bash scripts/build.sh -DCOVPLAN_BUILD_TESTS=OFF \
    -DCOVPLAN_BUILD_BENCHMARKS=OFF >/dev/null
fi
COVPLAN="$BUILD_DIR/bin/covplan"
COMMON="--resolution 0.05 --free-thresh 0.021 --tool-width 0.8 --max-speed 1 --acceleration 0.5 \
--turn-rate 30 --sensor-range 5.6 --time-limit 1 --local"

# One job per line: "LABEL<TAB>ARGS". The first method of every true map also
# plans it offline (the lower bound); the others skip that.
jobs_file="$OUT_DIR/jobs.txt"
: >"$jobs_file"
add() { printf '%s\t%s\n' "$1" "$2" >>"$jobs_file"; }
methods_for_seed() {  # clutter seed -> methods
  if [ "$1" -le "$FULL_SEEDS" ]; then echo "greedy_detour auto ilp1 ilp2 full"; else echo "greedy_detour auto"; fi
}
add_clutter() {  # SET MAP PERCENT SEEDS: MAP with PERCENT % clutter, seeds 1..SEEDS
  local label=$1 map=$2 percent=$3 seed method bound
  for seed in $(seq 1 "$4"); do
    bound=""
    for method in $(methods_for_seed "$seed"); do
      add "$label $map $percent $seed $method" "--map $IPA/$map.png --clutter $percent --seed $seed --method $method $bound"
      bound="--no-offline-bound"
    done
  done
}
for set in $SETS; do
  case "$set" in
    furnished)
      for m in $MAPS; do
        bound=""
        for method in greedy_detour auto ilp1 ilp2 full; do
          add "furnished $m 0 1 $method" "--map $IPA/$m.png --true-map $IPA/${m}_furnitures.png --seed 1 --method $method $bound"
          bound="--no-offline-bound"
        done
      done ;;
    clutter10)
      for m in $CLUTTER_MAPS; do add_clutter clutter10 "$m" 10 "$SEEDS"; done ;;
    levels)
      for p in $LEVELS; do add_clutter levels "$LEVEL_MAP" "$p" "$LEVEL_SEEDS"; done ;;
    *) echo "eval_replan: unknown set '$set'" >&2; exit 2 ;;
  esac
done

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u '+%F %H:%M UTC')"
echo "runs: $(wc -l <"$jobs_file") ($JOBS in parallel), results in $OUT_DIR/runs.jsonl"
export COVPLAN COMMON
run_one() {
  local label=${1%%$'\t'*} args=${1#*$'\t'}
  local t0 t1 json err
  err=$(mktemp)
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086
  if ! json=$("$COVPLAN" simulate $COMMON $args 2>"$err"); then
    json="{\"error\": \"$(tr '"\n\\' "'  " <"$err")\"}"
  fi
  rm -f "$err"
  t1=$(date +%s.%N)
  printf '{"label": "%s", "wall_s": %.1f, "run": %s}\n' "$label" "$(echo "$t1 - $t0" | bc)" "$json"
}
export -f run_one
start=$(date +%s)
tr '\n' '\0' <"$jobs_file" | xargs -0 -P "$JOBS" -I{} bash -c 'run_one "$@"' _ {} >"$OUT_DIR/runs.jsonl"
echo "wall: $(( $(date +%s) - start )) s"
python3 - "$OUT_DIR/runs.jsonl" <<'EOF'
import json, math, sys, statistics as st

runs, errors = [], []
for line in open(sys.argv[1]):
    r = json.loads(line)
    s, m, pct, seed, method = r["label"].split()
    if "error" in r["run"]:
        errors.append((r["label"], r["run"]["error"]))
        continue
    r.update(set=s, map=m, pct=float(pct), seed=int(seed), method=method)
    runs.append(r)
truth_of = lambda r: (r["set"], r["map"], r["pct"], r["seed"])
bound, cell_bound, bound_cov = {}, {}, {}
for r in runs:
    if r["run"]["offline_lower_bound_s"] is not None:
        bound[truth_of(r)] = r["run"]["offline_lower_bound_s"]
        cell_bound[truth_of(r)] = r["run"]["offline_cell_bound_s"]
        bound_cov[truth_of(r)] = r["run"]["offline_covered_free_area_ratio"]
by = {truth_of(r) + (r["method"],): r["run"] for r in runs}
METHODS = ["greedy_detour", "auto", "ilp1", "ilp2", "full"]


def mean(xs):
    xs = [x for x in xs if x is not None and not math.isnan(x)]
    return st.mean(xs) if xs else float("nan")


def pct(a, b):
    return 100.0 * (a / b - 1.0)


def block(title, keys, key_name):
    """keys: [(row label, [truth keys])]"""
    print(f"\n#### {title}\n")
    print(f"| {key_name} | bound s (true map / cell model) | " + " | ".join(f"{m} s" for m in METHODS) +
          " | AUTO vs GREEDY | AUTO vs cell bound | AUTO vs true-map bound | AUTO stoppage (max) |"
          " AUTO replan ms (mean) | coverage AUTO / offline | AUTO m in obstacles |")
    print("|" + "---|" * (len(METHODS) + 9))
    rows = []
    for label, truths in keys:
        cells = []
        for m in METHODS:
            xs = [by[t + (m,)]["total_time_s"] for t in truths if t + (m,) in by]
            cells.append((f"{mean(xs):.0f}" + (f" ({len(xs)})" if len(xs) < len(truths) else "")) if xs else "–")
        pairs = [(by[t + ("auto",)], by[t + ("greedy_detour",)]) for t in truths
                 if t + ("auto",) in by and t + ("greedy_detour",) in by]
        autos = [(t, by[t + ("auto",)]) for t in truths if t + ("auto",) in by]
        row = dict(
            gain=mean([pct(a["total_time_s"], g["total_time_s"]) for a, g in pairs]),
            wins=sum(a["total_time_s"] < g["total_time_s"] for a, g in pairs), n=len(pairs),
            vs_cell=mean([pct(a["total_time_s"], cell_bound[t]) for t, a in autos if t in cell_bound]),
            vs_true=mean([pct(a["total_time_s"], bound[t]) for t, a in autos if t in bound]),
            stop=max([100 * a["stoppage_s"] / a["total_time_s"] for _, a in autos], default=float("nan")))
        rows.append(row)
        print(f"| {label} | {mean([bound.get(t) for t in truths]):.0f} / {mean([cell_bound.get(t) for t in truths]):.0f} | "
              + " | ".join(cells) +
              f" | {row['gain']:+.1f} % ({row['wins']}/{row['n']} runs better) | {row['vs_cell']:+.1f} % | {row['vs_true']:+.1f} % |"
              f" {row['stop']:.3f} % | {mean([a['mean_replan_ms'] for _, a in autos]):.0f} |"
              f" {mean([a['covered_free_area_ratio'] for _, a in autos]):.3f} / {mean([bound_cov.get(t) for t in truths]):.3f} |"
              f" {mean([a['length_in_obstacles_m'] for _, a in autos]):.1f} |")
    print(f"| **mean** | | " + " | ".join("" for _ in METHODS) +
          f" | **{mean([r['gain'] for r in rows]):+.1f} %** ({sum(r['wins'] for r in rows)}/{sum(r['n'] for r in rows)})"
          f" | **{mean([r['vs_cell'] for r in rows]):+.1f} %** | **{mean([r['vs_true'] for r in rows]):+.1f} %** |"
          f" {max([r['stop'] for r in rows], default=float('nan')):.3f} % | | | |")


def stoppage_table(rows):
    print("\n#### Every method: stoppage share of total time (max over runs) / mean replan compute / mean replans per run\n")
    print("| runs | " + " | ".join(METHODS) + " |")
    print("|" + "---|" * (len(METHODS) + 1))
    for label, rs in rows:
        cells = []
        for m in METHODS:
            ms = [r["run"] for r in rs if r["method"] == m]
            if not ms:
                cells.append("–")
                continue
            stop = max(100 * r["stoppage_s"] / r["total_time_s"] for r in ms)
            cells.append(f"{stop:.3f} % / {mean([r['mean_replan_ms'] for r in ms]):.0f} ms / "
                         f"{mean([r['num_replans'] for r in ms]):.0f}")
        print(f"| {label} | " + " | ".join(cells) + " |")


order = ["furnished", "clutter10", "levels"]
stop_rows = []
for s in sorted({r["set"] for r in runs}, key=order.index):
    rs = [r for r in runs if r["set"] == s]
    truths = sorted({truth_of(r) for r in rs})
    if s == "levels":
        levels = sorted({t[2] for t in truths})
        keys = [(f"{p:g} %", [t for t in truths if t[2] == p]) for p in levels]
        block(f"{rs[0]['map']} at clutter levels ({len({t[3] for t in truths})} seeds each; mean totals)", keys, "clutter")
        stop_rows += [(f"{rs[0]['map']} {p:g} %", [r for r in rs if r["pct"] == p]) for p in levels]
    else:
        keys = [(m, [t for t in truths if t[1] == m]) for m in sorted({t[1] for t in truths})]
        block("Furnished maps (known: X.png, true: X_furnitures.png)" if s == "furnished"
              else f"10 % clutter ({len({t[3] for t in truths})} seeds per map; mean totals)", keys, "map")
        stop_rows.append((s, rs))
    problems = sum(len(r["run"]["problems"]) for r in rs)
    stopped = sum(not r["run"]["completed"] for r in rs)
    print(f"\nreplanner problems worked around: {problems}; runs stopped by a bound: {stopped}; "
          f"summed wall time: {sum(r['wall_s'] for r in rs):.0f} s over {len(rs)} runs")
stoppage_table(stop_rows)
for label, e in errors:
    print(f"\nERROR {label}: {e}")
for r in runs:
    for p in r["run"]["problems"]:
        print(f"\nproblem in {r['label']}: {p}")
EOF
