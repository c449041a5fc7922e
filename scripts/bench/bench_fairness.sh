#!/usr/bin/env bash
# The fairness run of docs/robustness.md (issue 30, item 4): tenant B plans at
# a steady rate, alone and then beside tenant A, which keeps 4x its quota of
# calls in flight; B's p99 and errors are compared. Three runs:
#   B alone | B + A, no quotas (tenants only take turns) | B + A, A's quota
#   scripts/bench/bench_fairness.sh [--duration S] [--rate R] [--bin DIR]
# Only 127.0.0.1 is contacted; every run is bounded by --duration.
set -euo pipefail
cd "$(dirname "$0")/../.."
DURATION=20
RATE=2
BIN=build/bin
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) DURATION=$2; shift 2 ;;
    --rate) RATE=$2; shift 2 ;;
    --bin) BIN=$2; shift 2 ;;
    *) echo "bench_fairness: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -x "$BIN/covplan-server" ] || { echo "bench_fairness: no $BIN/covplan-server; run scripts/build.sh" >&2; exit 2; }
WORK=$(mktemp -d -t covplan-fair.XXXXXX)
SERVER=
stop_server() { [ -n "$SERVER" ] && { kill -TERM "$SERVER" 2>/dev/null || true; wait "$SERVER" 2>/dev/null || true; }; SERVER=; }
trap 'stop_server; rm -rf "$WORK"' EXIT
TOKEN_A=tenant-a-bench-token
TOKEN_B=tenant-b-bench-token
{ printf '%s a\n' "$(printf %s "$TOKEN_A" | sha256sum | cut -d' ' -f1)"
  printf '%s b\n' "$(printf %s "$TOKEN_B" | sha256sum | cut -d' ' -f1)"; } > "$WORK/tokens"
# A: 1 running + 2 queued; 4x that is 12 calls in flight.
echo "a max_solves=1 max_queued=2" > "$WORK/quotas"
: > "$WORK/no-quotas"
A_CONCURRENCY=12
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
start_server() {  # $1: quota file
  PORT=$(free_port)
  rm -rf "$WORK/store"
  "$BIN"/covplan-server --port "$PORT" --metrics_port -1 --store_dir "$WORK/store" --threads 2 \
    --max_queue 16 --token_file "$WORK/tokens" --tenant_quota_file "$1" 2>"$WORK/server.log" &
  SERVER=$!
  for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
}
# B: the sample office at a 0.3 m tool (260 ranks) from random starts,
# searches of at most 0.3 s; "$@" adds or overrides flags.
load_b() {
  "$BIN"/covplan load --server "127.0.0.1:$PORT" --token "$TOKEN_B" --map maps/sample_office.yaml \
    --tool-width 0.3 --random-start --time-limit 0.3 --concurrency 2 --rate "$RATE" \
    --duration "$DURATION" --deadline-ms 10000 "$@"
}
# A: the same map at a 0.2 m tool (403 ranks), searches of at most 1 s,
# 12 calls in flight, 50 ms back-off on refusals.
load_a() {
  "$BIN"/covplan load --server "127.0.0.1:$PORT" --token "$TOKEN_A" --map maps/sample_office.yaml \
    --tool-width 0.2 --random-start --time-limit 1 --concurrency "$A_CONCURRENCY" \
    --backoff-ms 50 --duration "$((DURATION + 2))" --deadline-ms 10000 "$@"
}
row() {  # $1 label, $2 B's JSON, $3 A's JSON (or empty)
  /usr/bin/python3 - "$1" "$2" "$3" <<'PY'
import json, sys
label, b = sys.argv[1], json.loads(sys.argv[2])
a = json.loads(sys.argv[3]) if sys.argv[3] else None
err = lambda d: d["requests"] - d["ok"]
a_cols = f"{a['requests']} | {a['ok']} | {a['codes'].get('RESOURCE_EXHAUSTED', 0)}" if a else "- | - | -"
print(f"| {label} | {b['requests']} | {err(b)} | {b['p50_ms']:.0f} | {b['p99_ms']:.0f} | "
      f"{b['max_ms']:.0f} | {a_cols} |")
PY
}
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); server --threads 2 --max_queue 16; B at $RATE/s for ${DURATION} s; A with $A_CONCURRENCY calls in flight"
echo
echo "| run | B requests | B errors | B p50 ms | B p99 ms | B max ms | A requests | A ok | A RESOURCE_EXHAUSTED |"
echo "|---|---|---|---|---|---|---|---|---|"
# Warm-up: each tenant's artifacts cached (each has its own map id) by one
# plan from a start the measured runs do not draw.
warm_up() {
  load_b --requests 1 --seed 99 >/dev/null
  A_CONCURRENCY=1 load_a --requests 1 --seed 99 >/dev/null
}
start_server "$WORK/quotas"
warm_up
row "B alone" "$(load_b --seed 3)" ""
stop_server
for run in no-quotas quotas; do
  start_server "$WORK/$run"
  warm_up
  load_a --seed 7 > "$WORK/a.json" &
  A=$!
  sleep 1
  B_OUT=$(load_b --seed 3)
  wait "$A"
  label="B + A, no quotas (turns only)"
  [ "$run" = quotas ] && label="B + A, A at max_solves=1 max_queued=2"
  row "$label" "$B_OUT" "$(cat "$WORK/a.json")"
  stop_server
done
