#!/usr/bin/env bash
# Resident memory of covplan-server against its budgets: plans N distinct
# generated maps in turn (each a new set of per-map artifacts) through one
# server with a small --cache_mb, and prints RSS, the cache's byte gauge and
# the high-water mark every 20 maps.
#   scripts/bench_server_memory.sh [CACHE_MB] [N_MAPS]
# Uses already-built binaries: BIN (default build-h/bin); SERVER_BIN
# overrides the server (e.g. an older build for a before/after figure).
set -euo pipefail
cd "$(dirname "$0")/.."
CACHE_MB=${1:-16}
N=${2:-280}
THREADS=${THREADS:-2}
BIN=${BIN:-build-h/bin}
SERVER_BIN=${SERVER_BIN:-$BIN/covplan-server}
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
WORK=$(mktemp -d -t covplan-mem.XXXXXX)
# N distinct maps: a 30 m x 20 m walled floor (600 x 400 px at 0.05 m) with
# seeded random furniture.
/usr/bin/python3 - "$WORK" "$N" <<'PY'
import random, sys
out, n = sys.argv[1], int(sys.argv[2])
W, H = 600, 400
for k in range(n):
    rng = random.Random(k)
    px = bytearray([254]) * (W * H)
    def box(x0, y0, x1, y1):
        for y in range(max(0, y0), min(H, y1)):
            px[y * W + max(0, x0): y * W + min(W, x1)] = bytes([0]) * (min(W, x1) - max(0, x0))
    box(0, 0, W, 6); box(0, H - 6, W, H); box(0, 0, 6, H); box(W - 6, 0, W, H)
    for _ in range(60):
        x, y = rng.randrange(20, W - 60), rng.randrange(20, H - 60)
        box(x, y, x + rng.randrange(8, 40), y + rng.randrange(8, 40))
    with open(f"{out}/m{k}.pgm", "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (W, H)); f.write(px)
    with open(f"{out}/m{k}.yaml", "w") as f:
        f.write(f"image: m{k}.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
PY
PORT=$(free_port); MPORT=$(free_port)
"$SERVER_BIN" --port "$PORT" --metrics_port "$MPORT" --store_dir "$WORK/store" --threads "$THREADS" \
  --cache_mb "$CACHE_MB" 2>"$WORK/server.log" &
SERVER=$!
trap 'kill -TERM $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true; rm -rf "$WORK"' EXIT
for _ in $(seq 1 100); do (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null && break; sleep 0.1; done
sleep 0.5
metric() { curl -s "127.0.0.1:$MPORT/metrics" | awk -v m="$1" '$1 == m {print $2}'; }
rss() { echo $(( $(awk "/$1/ {print \$2}" /proc/$SERVER/status) / 1024 )); }
echo "server $SERVER_BIN, --cache_mb $CACHE_MB --threads $THREADS, $N maps of 600 x 400 px, tool 0.3 m"
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
