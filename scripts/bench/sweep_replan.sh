#!/usr/bin/env bash
# Robustness sweep of the replanner (docs/robustness.md): drives the shipped
# sample office through random clutter with every replanning method and
# counts the problems the simulator finds. The simulator checks every
# replanned path whole against the known map and every cell already
# reported blocked, and every driven step against the true map; each
# violation is counted in the run's "num_problems" field (the first 20 are
# listed in "problems"). Uses only the repo.
#
#   scripts/bench/sweep_replan.sh                          # 4 methods x 2 levels x 6 seeds
#   SEEDS="1 2" METHODS="auto" LEVELS=20 scripts/bench/sweep_replan.sh
#
# Environment: BUILD_DIR (build), MAP (maps/sample_office.yaml), METHODS
# ("auto ilp1 ilp2 greedy_detour"), LEVELS ("10 20"), SEEDS ("1 2 3 4 5 6"),
# JOBS (parallel runs, 2), OUT (runs.jsonl path; default a temp file).
# Prints one line per run and a summary; exits 1 when any run has a problem
# or fails.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR=${BUILD_DIR:-build}
MAP=${MAP:-maps/sample_office.yaml}
METHODS=${METHODS:-"auto ilp1 ilp2 greedy_detour"}
LEVELS=${LEVELS:-"10 20"}
SEEDS=${SEEDS:-"1 2 3 4 5 6"}
JOBS=${JOBS:-2}
OUT=${OUT:-$(mktemp -t sweep_replan.XXXXXX.jsonl)}
COVPLAN="$BUILD_DIR/bin/covplan"
[ -x "$COVPLAN" ] || { echo "sweep_replan: $COVPLAN not built (scripts/build.sh)" >&2; exit 2; }
: > "$OUT"

run_one() {  # method clutter seed
  local out
  if out=$("$COVPLAN" simulate --map "$MAP" --clutter "$2" --seed "$3" --method "$1" \
             --replan-tour-limit 0.1 --local 2>&1); then
    printf '{"method":"%s","clutter":%s,"seed":%s,"run":%s}\n' "$1" "$2" "$3" "$out"
  else
    printf '{"method":"%s","clutter":%s,"seed":%s,"error":%s}\n' "$1" "$2" "$3" \
      "$(printf '%s' "$out" | /usr/bin/python3 -c 'import json,sys; print(json.dumps(sys.stdin.read()))')"
  fi
}
export -f run_one
export COVPLAN MAP
for m in $METHODS; do for c in $LEVELS; do for s in $SEEDS; do echo "$m $c $s"; done; done; done |
  xargs -P "$JOBS" -L 1 bash -c 'run_one "$0" "$1" "$2"' >> "$OUT"

/usr/bin/python3 - "$OUT" <<'EOF'
import json, sys
runs = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
bad = 0
for r in sorted(runs, key=lambda r: (r["method"], r["clutter"], r["seed"])):
    if "error" in r:
        bad += 1
        print(f'{r["method"]:14} {r["clutter"]:>3}% seed {r["seed"]}: FAILED {r["error"][:200]}')
        continue
    x = r["run"]
    p = x.get("problems", [])
    n = x.get("num_problems", len(p))  # the list holds the first 20
    cut = not x.get("completed", True)  # e.g. walled in: the termination says why
    bad += bool(n) or cut
    print(f'{r["method"]:14} {r["clutter"]:>3}% seed {r["seed"]}: problems {n} '
          + (f'STOPPED ({x.get("termination", "")[:80]}) ' if cut else '') +
          f'replans {x["num_replans"]} stoppage {x["stoppage_s"]:.1f} s '
          f'coverage {x["covered_free_area_ratio"]:.4f}' + (f'  {p[:3]}' if p else ''))
print(f'{len(runs)} runs, {bad} with problems, failures or early stops; runs in {sys.argv[1]}')
sys.exit(1 if bad else 0)
EOF
