#!/usr/bin/env bash
# Load run of docs/benchmarks.md: starts a Release covplan-server on loopback,
# caches the sample map's decomposition with one Plan, then drives `covplan
# load` at concurrency 1, 4 and 16 and samples the server's resident memory.
#   scripts/bench/bench_load.sh [--duration S] [--deadline-ms D] [--cache-mb M]
# Only 127.0.0.1 is contacted; every run is bounded by --duration.
set -euo pipefail
cd "$(dirname "$0")/../.."
DURATION=10
DEADLINE_MS=500
CACHE_MB=64
MAP=maps/sample_office.yaml
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) DURATION=$2; shift 2 ;;
    --deadline-ms) DEADLINE_MS=$2; shift 2 ;;
    --cache-mb) CACHE_MB=$2; shift 2 ;;
    --map) MAP=$2; shift 2 ;;
    *) echo "bench_load: unknown argument $1" >&2; exit 2 ;;
  esac
done
BUILD_DIR=${BUILD_DIR:-build-release}
BUILD_TYPE=Release BUILD_DIR="$BUILD_DIR" bash scripts/build.sh -DCOVPLAN_BUILD_TESTS=OFF >/dev/null
BIN="$BUILD_DIR/bin"
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
PORT=$(free_port)
STORE=$(mktemp -d -t covplan-load.XXXXXX)
"$BIN"/covplan-server --port "$PORT" --metrics_port -1 --store_dir "$STORE" --threads 2 \
  --max_queue 4 --cache_mb "$CACHE_MB" 2>"$STORE/server.log" &
SERVER=$!
trap 'kill -TERM $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true; rm -rf "$STORE"' EXIT
for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
rss_kb() { awk '/VmRSS/ {print $2}' /proc/"$SERVER"/status; }
hwm_kb() { awk '/VmHWM/ {print $2}' /proc/"$SERVER"/status; }
# Warm-up: registers the map and caches its decomposition.
"$BIN"/covplan plan --map "$MAP" --server "127.0.0.1:$PORT" --out "$STORE/warm.json" >/dev/null
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); server: --threads 2 --max_queue 4 --cache_mb $CACHE_MB; deadline ${DEADLINE_MS} ms; ${DURATION} s per level; idle RSS after warm-up $(( $(rss_kb) / 1024 )) MiB"
echo
echo "| concurrency | requests | ok | RESOURCE_EXHAUSTED | other errors | ok/s | p50 ms | p95 ms | p99 ms | max ms | late | peak RSS MiB |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for c in 1 4 16; do
  out=$("$BIN"/covplan load --server "127.0.0.1:$PORT" --map "$MAP" --concurrency "$c" \
        --duration "$DURATION" --deadline-ms "$DEADLINE_MS")
  /usr/bin/python3 - "$out" "$c" "$DURATION" "$(( $(hwm_kb) / 1024 ))" <<'PY'
import json, sys
d = json.loads(sys.argv[1]); c = sys.argv[2]; dur = float(sys.argv[3])
codes = d.get("codes", {})
exhausted = codes.get("RESOURCE_EXHAUSTED", 0)
other = sum(v for k, v in codes.items() if k not in ("OK", "RESOURCE_EXHAUSTED"))
print(f"| {c} | {d['requests']} | {d['ok']} | {exhausted} | {other} | {d['ok']/dur:.1f} | "
      f"{d['p50_ms']:.0f} | {d['p95_ms']:.0f} | {d['p99_ms']:.0f} | {d['max_ms']:.0f} | {d['late']} | {sys.argv[4]} |")
PY
done
