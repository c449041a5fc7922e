#!/usr/bin/env bash
# Server memory with the decomposition cache at its budget: cycles distinct
# decompositions of the sample map (one per tool width) through a Release
# covplan-server with a small --cache_mb and prints, after each plan, the RSS
# and the cache's own byte gauge and eviction counter from /metrics.
#   scripts/bench/bench_cache_memory.sh [CACHE_MB]
set -euo pipefail
cd "$(dirname "$0")/../.."
CACHE_MB=${1:-16}
BUILD_DIR=${BUILD_DIR:-build-release}
BUILD_TYPE=Release BUILD_DIR="$BUILD_DIR" bash scripts/build.sh -DCOVPLAN_BUILD_TESTS=OFF >/dev/null
BIN="$BUILD_DIR/bin"
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
PORT=$(free_port); MPORT=$(free_port)
STORE=$(mktemp -d -t covplan-cache.XXXXXX)
"$BIN"/covplan-server --port "$PORT" --metrics_port "$MPORT" --store_dir "$STORE" --threads 2 \
  --cache_mb "$CACHE_MB" 2>"$STORE/server.log" &
SERVER=$!
trap 'kill -TERM $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true; rm -rf "$STORE"' EXIT
for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
metric() { curl -s "127.0.0.1:$MPORT/metrics" | awk -v m="$1" '$1 == m {print $2}'; }
echo "| tool width m | RSS MiB | cache bytes | cache entries | evictions |"
echo "|---|---|---|---|---|"
for tw in 0.30 0.32 0.34 0.36 0.38 0.40 0.42 0.45 0.5 0.6 0.7 0.8 1.0 0.31 0.33 0.35 0.37 0.39 0.41 0.43; do
  "$BIN"/covplan plan --map maps/sample_office.yaml --server "127.0.0.1:$PORT" --tool-width "$tw" \
    --time-limit 0.2 --out "$STORE/plan.json" >/dev/null
  echo "| $tw | $(( $(awk '/VmRSS/ {print $2}' /proc/$SERVER/status) / 1024 )) | $(metric covplan_artifact_cache_bytes) | $(metric covplan_artifact_cache_entries) | $(metric covplan_artifact_cache_evictions_total) |"
done
echo
echo "budget $((CACHE_MB * 1048576)) bytes; peak RSS (VmHWM) $(( $(awk '/VmHWM/ {print $2}' /proc/$SERVER/status) / 1024 )) MiB"
