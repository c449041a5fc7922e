#!/usr/bin/env bash
# Resident memory of covplan-server against its budgets: plans N distinct
# generated maps in turn (each a new set of per-map artifacts) through one
# server with a small --cache_mb, and prints RSS, the cache's byte gauge and
# the high-water mark every 20 maps.
#   scripts/bench/bench_server_memory.sh [CACHE_MB] [N_MAPS]
# Uses already-built binaries: BIN (default build-h/bin); SERVER_BIN
# overrides the server (e.g. an older build for a before/after figure).
set -euo pipefail
cd "$(dirname "$0")/../.."
CACHE_MB=${1:-16}
N=${2:-280}
THREADS=${THREADS:-2}
BIN=${BIN:-build-h/bin}
SERVER_BIN=${SERVER_BIN:-$BIN/covplan-server}
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
WORK=$(mktemp -d -t covplan-mem.XXXXXX)
# N distinct maps: walled floors of WIDTH x HEIGHT px at 0.05 m (default
# 600 x 400: 30 m x 20 m) with seeded random furniture.
WIDTH=${WIDTH:-600}
HEIGHT=${HEIGHT:-400}
/usr/bin/python3 scripts/maps/gen_bench_maps.py "$WORK" "$N" "$WIDTH" "$HEIGHT"
PORT=$(free_port); MPORT=$(free_port)
"$SERVER_BIN" --port "$PORT" --metrics_port "$MPORT" --store_dir "$WORK/store" --threads "$THREADS" \
  --cache_mb "$CACHE_MB" 2>"$WORK/server.log" &
SERVER=$!
trap 'kill -TERM $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true; rm -rf "$WORK"' EXIT
for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
sleep 0.5
metric() { curl -s "127.0.0.1:$MPORT/metrics" | awk -v m="$1" '$1 == m {print $2}'; }
rss() { echo $(( $(awk "/$1/ {print \$2}" /proc/$SERVER/status) / 1024 )); }
echo "server $SERVER_BIN, --cache_mb $CACHE_MB --threads $THREADS, $N maps of $WIDTH x $HEIGHT px, tool 0.3 m"
echo "| maps planned | RSS MiB | peak RSS MiB | cache MiB |"
echo "|---|---|---|---|"
echo "| 0 | $(rss VmRSS) | $(rss VmHWM) | 0 |"
for k in $(seq 0 $((N - 1))); do
  "$BIN"/covplan plan --map "$WORK/m$k.yaml" --server "127.0.0.1:$PORT" --tool-width 0.3 \
    --time-limit 0.2 --out "$WORK/plan.json" >/dev/null
  if (( (k + 1) % 20 == 0 )); then
    cache=$(metric covplan_artifact_cache_bytes)
    echo "| $((k + 1)) | $(rss VmRSS) | $(rss VmHWM) | $(/usr/bin/python3 -c "print(round(${cache:-0} / 1048576, 1))") |"
  fi
done
