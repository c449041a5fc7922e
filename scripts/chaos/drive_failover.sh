#!/usr/bin/env bash
# Robots that outlive their replica (issue 30, item 3), on the one-machine
# cluster (scripts/deploy/cluster.sh: 3 replicas behind HAProxy, PostgreSQL
# as the shared store): ROBOTS simulated robots drive the sample office
# through the router at once (`covplan simulate --server ROUTER --watch
# SPEED`, robot i with seed i, light clutter so every run replans); at each
# time in KILL_AT (seconds from the start) the replica holding the most Drive
# sessions is SIGKILLed and started again DOWN seconds later. Each robot's
# session reconnects through the router by itself. Then each robot drives the
# same mission again with nothing killed (no --watch), and the two are
# compared.
#
#   bash scripts/chaos/drive_failover.sh                 # 8 robots, kills at 4 and 10 s
#   ROBOTS=4 KILL_AT="3" bash scripts/chaos/drive_failover.sh
#
# Prints a line per robot and a summary (robots completed, reconnects, their
# p50 and max, the largest loss of swept share against the calm run); exits 1
# unless every robot completed with no problems and swept within 0.03 of its
# calm run. Environment: ROBOTS (8), SPEED (120), KILL_AT ("4 10"), DOWN (2),
# CLUTTER (1), COVPLAN_BIN (build/bin), COVPLAN_CLUSTER_DIR
# (/tmp/covplan-cluster), COVPLAN_CLUSTER_PORT (56100). Leaves the cluster up
# (scripts/deploy/cluster.sh down stops it).
set -euo pipefail
cd "$(dirname "$0")/../.."
export COVPLAN_BIN=${COVPLAN_BIN:-$PWD/build/bin}
export COVPLAN_CLUSTER_DIR=${COVPLAN_CLUSTER_DIR:-/tmp/covplan-cluster}
BASE=${COVPLAN_CLUSTER_PORT:-56100}
ROBOTS=${ROBOTS:-8}
SPEED=${SPEED:-120}
KILL_AT=${KILL_AT:-4 10}
DOWN=${DOWN:-2}
CLUTTER=${CLUTTER:-1}
CLUSTER="bash scripts/deploy/cluster.sh"
OUT=$COVPLAN_CLUSTER_DIR/drive-failover
rm -rf "$OUT"
mkdir -p "$OUT"
$CLUSTER up >/dev/null

# run ROBOT OUT_JSON [extra flags...]: one robot's simulated mission through the router.
run() {
  "$COVPLAN_BIN/covplan" simulate --map maps/sample_office.yaml --clutter "$CLUTTER" --seed "$1" \
    --time-limit 0.3 --no-offline-bound --server "127.0.0.1:$BASE" --svg "${2%.json}.svg" "${@:3}" \
    >"$2" 2>"$2.err"
}
# The replica (1..3) with the most open Drive sessions.
busiest() {
  local best=1 most=-1 n count
  for n in 1 2 3; do
    count=$(curl -s "http://127.0.0.1:$((BASE + 10 + n))/metrics" |
      awk '$1 == "covplan_drive_sessions" {print int($2)}')
    if [ "${count:-0}" -gt "$most" ]; then best=$n most=${count:-0}; fi
  done
  echo "$best $most"
}

start=$(date +%s.%N)
pids=()
for i in $(seq 1 "$ROBOTS"); do
  run "$i" "$OUT/robot$i.json" --watch "$SPEED" &
  pids+=($!)
done
(
  for at in $KILL_AT; do
    now=$(date +%s.%N)
    sleep "$(awk -v a="$at" -v s="$start" -v n="$now" 'BEGIN {d = a - (n - s); print (d > 0 ? d : 0)}')"
    read -r victim sessions < <(busiest)
    echo "t=${at}s: replica$victim holds $sessions sessions"
    $CLUSTER kill "$victim"
    sleep "$DOWN"
    $CLUSTER start "$victim" >/dev/null
    echo "t=$(awk -v s="$start" -v n="$(date +%s.%N)" 'BEGIN {printf "%.1f", n - s}')s: replica$victim started again"
  done
) | tee "$OUT/kills.log" &
killer=$!
failed=0
for p in "${pids[@]}"; do wait "$p" || failed=$((failed + 1)); done
wait "$killer"
echo "all robots done after $(awk -v s="$start" -v n="$(date +%s.%N)" 'BEGIN {printf "%.1f", n - s}') s; the calm runs:"
for i in $(seq 1 "$ROBOTS"); do run "$i" "$OUT/calm$i.json" || true; done

/usr/bin/python3 - "$OUT" "$ROBOTS" <<'PY'
import json, statistics, sys
out, robots = sys.argv[1], int(sys.argv[2])
def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None
ok, reconnects, worst = 0, [], 0.0
for i in range(1, robots + 1):
    r, calm = load(f"{out}/robot{i}.json"), load(f"{out}/calm{i}.json")
    if r is None:
        err = open(f"{out}/robot{i}.json.err").read().strip().splitlines()
        print(f"robot {i}: FAILED: {err[-1] if err else 'no output'}")
        continue
    loss = (calm["swept_reachable_ratio"] - r["swept_reachable_ratio"]) if calm else float("nan")
    worst = max(worst, loss) if calm else worst
    good = r["completed"] and not r["problems"] and calm is not None and loss <= 0.03
    ok += good
    if r["server_reconnects"]:
        reconnects.append(r["max_reconnect_s"])
    calm_text = f"{calm['swept_reachable_ratio']:.4f}" if calm else "none: it failed"
    print(f"robot {i}: completed {r['completed']}, problems {r['num_problems']}, replans "
          f"{r['num_replans']}, reconnects {r['server_reconnects']} (longest "
          f"{r['max_reconnect_s']:.2f} s), swept {r['swept_reachable_ratio']:.4f} "
          f"(calm run {calm_text})")
p50 = statistics.median(reconnects) if reconnects else 0.0
print(f"summary: {ok} of {robots} robots completed with no problems and swept within 0.03 of "
      f"their calm run; {len(reconnects)} reconnected, longest reconnect per robot p50 "
      f"{p50:.2f} s, max {max(reconnects, default=0.0):.2f} s; largest swept loss {worst:.4f}")
sys.exit(0 if ok == robots else 1)
PY
