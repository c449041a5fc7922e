#!/usr/bin/env bash
# The soak of docs/robustness.md (issue 30): one covplan-server under a steady
# mix for --duration seconds. First its plan capacity is measured (random
# starts on the sample office at a 0.3 m tool, 4 callers, 10 s); then, window
# after window, Plans arrive at --load (default 0.8) of that capacity less
# what the Drive sessions take, while Drive sessions (`covplan simulate
# --server`, 8 % clutter, a fresh seed each: ~13 replans in ~2 s) run one
# after another. Per window: requests, errors, p50/p99, resident memory and
# the server's CPU share; at the end the memory's growth after the first
# window (warm-up) and its slope.
#   scripts/chaos/soak.sh [--duration S] [--window S] [--load F] [--bin DIR]
#                         [--check --max-growth-pct P]
# --check exits 1 when a call or session failed (an error; a session that
# ended before its plan's end is listed, not counted) or memory grew more
# than P % (default 5) after warm-up. Only 127.0.0.1 is contacted.
set -euo pipefail
cd "$(dirname "$0")/../.."
DURATION=1800
WINDOW=60
LOAD=0.8
BIN=${COVPLAN_BIN:-build/bin}
CHECK=0
MAX_GROWTH=5
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) DURATION=$2; shift 2 ;;
    --window) WINDOW=$2; shift 2 ;;
    --load) LOAD=$2; shift 2 ;;
    --bin) BIN=$2; shift 2 ;;
    --check) CHECK=1; shift ;;
    --max-growth-pct) MAX_GROWTH=$2; shift 2 ;;
    *) echo "soak: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -x "$BIN/covplan-server" ] || { echo "soak: no $BIN/covplan-server; run scripts/build.sh" >&2; exit 2; }
WORK=$(mktemp -d -t covplan-soak.XXXXXX)
SERVER=
SESSIONS=
cleanup() {
  [ -n "$SESSIONS" ] && kill "$SESSIONS" 2>/dev/null || true
  [ -n "$SERVER" ] && { kill -TERM "$SERVER" 2>/dev/null || true; wait "$SERVER" 2>/dev/null || true; }
  rm -rf "$WORK"
}
trap cleanup EXIT
PORT=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
"$BIN"/covplan-server --port "$PORT" --metrics_port -1 --store_dir "$WORK/store" --threads 2 \
  --max_queue 16 2>"$WORK/server.log" &
SERVER=$!
for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
TARGET="127.0.0.1:$PORT"
load() {  # $@: extra flags
  "$BIN"/covplan load --server "$TARGET" --map maps/sample_office.yaml --tool-width 0.3 \
    --random-start --deadline-ms 5000 "$@"
}
field() { /usr/bin/python3 -c 'import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])' "$1" "$2"; }
rss_mib() { awk '/VmRSS/ {printf "%.1f", $2 / 1024}' /proc/"$SERVER"/status; }
cpu_ticks() { awk '{print $14 + $15}' /proc/"$SERVER"/stat; }
HZ=$(getconf CLK_TCK)
load --concurrency 1 --requests 1 --seed 999 >/dev/null  # the map's artifacts
CAPACITY_JSON=$(load --concurrency 4 --duration 10 --seed 998)
CAPACITY=$(/usr/bin/python3 -c 'import json,sys; d=json.loads(sys.argv[1]); print("%.2f" % (d["ok"] / d["duration_s"]))' "$CAPACITY_JSON")
# The sessions, one after another, each line of results kept.
(
  seed=1
  while true; do
    if out=$("$BIN"/covplan simulate --map maps/small_rooms.yaml --clutter 8 --seed "$seed" \
             --server "$TARGET" --no-offline-bound 2>&1); then
      echo "$out" | tail -1 >> "$WORK/sessions.jsonl"
      # A run that ended before its plan did (its termination says why).
      echo "$out" | tail -1 | grep -q '"completed": true' ||
        echo "seed $seed: $(echo "$out" | tail -1 | grep -o '"termination": "[^"]*"')" >> "$WORK/sessions.cut"
    else
      echo "{\"failed\": true, \"seed\": $seed}" >> "$WORK/sessions.jsonl"
      echo "seed $seed: $(echo "$out" | tail -2 | tr '\n' ' ' | cut -c1-300)" >> "$WORK/sessions.err"
    fi
    seed=$((seed + 1))
  done
) &
SESSIONS=$!
# What the sessions alone take of the server (a short window), so the plans
# fill the rest up to the load factor.
sleep 5
T0=$(cpu_ticks); sleep 5; T1=$(cpu_ticks)
SESSION_SHARE=$(/usr/bin/python3 -c "print(($T1 - $T0) / $HZ / 5 / 2)")
RATE=$(/usr/bin/python3 -c "print(max(0.1, $CAPACITY * ($LOAD - $SESSION_SHARE)))")
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); server --threads 2 --max_queue 16"
echo "plan capacity: $CAPACITY plans/s (4 callers, 10 s); Drive sessions alone: $(/usr/bin/python3 -c "print(f'{100 * $SESSION_SHARE:.0f}')") % of the 2 cores; Plans at $RATE/s for a load of $LOAD; ${DURATION} s in windows of ${WINDOW} s"
echo
echo "| t s | plans | plan errors | p50 ms | p99 ms | sessions completed | sessions failed | server CPU % | RSS MiB |"
echo "|---|---|---|---|---|---|---|---|---|"
START=$(date +%s)
ERRORS=0
: > "$WORK/rss"
while [ $(( $(date +%s) - START )) -lt "$DURATION" ]; do
  C0=$(cpu_ticks); W0=$(date +%s.%N)
  OUT=$(load --concurrency 4 --rate "$RATE" --duration "$WINDOW" --seed "$(( $(date +%s) % 100000 ))")
  C1=$(cpu_ticks); W1=$(date +%s.%N)
  RSS=$(rss_mib); echo "$RSS" >> "$WORK/rss"
  DONE=$(grep -c '"completed": true' "$WORK/sessions.jsonl" 2>/dev/null || true)
  FAILED=$(grep -c '"failed": true' "$WORK/sessions.jsonl" 2>/dev/null || true)
  ERR=$(( $(field "$OUT" requests) - $(field "$OUT" ok) ))
  ERRORS=$((ERRORS + ERR))
  /usr/bin/python3 - "$OUT" "$(( $(date +%s) - START ))" "$DONE" "$FAILED" "$C0" "$C1" "$W0" "$W1" "$HZ" "$RSS" "$ERR" <<'PY'
import json, sys
d = json.loads(sys.argv[1]); t, done, failed = sys.argv[2:5]
c0, c1, w0, w1, hz = (float(x) for x in sys.argv[5:10])
cpu = 100 * (c1 - c0) / hz / (w1 - w0) / 2
print(f"| {t} | {d['requests']} | {sys.argv[11]} | {d['p50_ms']:.0f} | {d['p99_ms']:.0f} | {done} | {failed} | {cpu:.0f} | {sys.argv[10]} |")
PY
done
kill "$SESSIONS" 2>/dev/null || true; wait "$SESSIONS" 2>/dev/null || true; SESSIONS=
FAILED=$(grep -c '"failed": true' "$WORK/sessions.jsonl" 2>/dev/null || true)
CUT=$(cat "$WORK/sessions.cut" 2>/dev/null | wc -l)
[ -s "$WORK/sessions.err" ] && { echo; echo "sessions that failed (an error from the client or server):"; head -20 "$WORK/sessions.err"; }
[ -s "$WORK/sessions.cut" ] && { echo; echo "sessions that ended before their plan's end:"; sort -u "$WORK/sessions.cut" | head -20; }
SUMMARY=$(/usr/bin/python3 - "$WORK/rss" "$WINDOW" "$MAX_GROWTH" <<'PY'
import sys
rss = [float(x) for x in open(sys.argv[1]) if x.strip()]
window = float(sys.argv[2])
after = rss[1:] if len(rss) > 2 else rss
base = after[0]
growth = 100 * (max(after) - base) / base
n = len(after)
xs = [i * window / 3600 for i in range(n)]
mx, my = sum(xs) / n, sum(after) / n
den = sum((x - mx) ** 2 for x in xs)
slope = sum((x - mx) * (y - my) for x, y in zip(xs, after)) / den if den > 0 else 0.0
print(f"{growth:.2f} {slope:.1f} {base:.1f} {max(after):.1f}")
PY
)
read -r GROWTH SLOPE BASE PEAK <<<"$SUMMARY"
echo
echo "after warm-up (window 1): RSS $BASE MiB -> peak $PEAK MiB (+$GROWTH %), slope $SLOPE MiB/h; plan errors $ERRORS; sessions failed $FAILED, ended early $CUT"
if [ "$CHECK" = 1 ]; then
  fail=0
  [ "$ERRORS" -eq 0 ] || { echo "soak: $ERRORS plan calls failed" >&2; fail=1; }
  [ "$FAILED" -eq 0 ] || { echo "soak: $FAILED sessions failed" >&2; fail=1; }
  /usr/bin/python3 -c "import sys; sys.exit(0 if $GROWTH <= $MAX_GROWTH else 1)" ||
    { echo "soak: memory grew $GROWTH % after warm-up (limit $MAX_GROWTH %)" >&2; fail=1; }
  exit $fail
fi
