#!/usr/bin/env bash
# kill -9 storm: ROUNDS times, start covplan-server on one store, run
# CLIENTS concurrent `covplan plan --server` loops (each a PutMap, then a
# Plan) over distinct maps, SIGKILL the server at a random moment, restart
# it and check that every map whose PutMap was acknowledged (its plan.json
# names the map_id) is indexed intact, and that nothing is corrupted.
#   scripts/chaos/kill9_storm.sh [ROUNDS] [CLIENTS]
# Uses built binaries: BIN (default build-h/bin).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROUNDS=${1:-6}
CLIENTS=${2:-4}
BIN=${BIN:-build-h/bin}
WORK=$(mktemp -d -t covplan-storm.XXXXXX)
STORE="$WORK/store"
SERVER=
trap '[ -n "$SERVER" ] && kill -9 $SERVER 2>/dev/null; rm -rf "$WORK"' EXIT
/usr/bin/python3 scripts/maps/gen_bench_maps.py "$WORK" 200 200 150
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
start_server() {
  PORT=$(free_port)
  "$BIN"/covplan-server --port "$PORT" --metrics_port -1 --store_dir "$STORE" 2>>"$WORK/server.log" &
  SERVER=$!
  for _ in $(seq 1 200); do grep -q "map store indexed" "$WORK/server.log" 2>/dev/null && break; sleep 0.05; done
}
acked=0; lost=0; corrupted=0; next=0
for round in $(seq 1 "$ROUNDS"); do
  : > "$WORK/server.log"
  start_server
  pids=()
  for c in $(seq 1 "$CLIENTS"); do
    (
      for i in $(seq 0 9); do
        k=$(( (next + c * 10 + i) % 200 ))
        "$BIN"/covplan plan --map "$WORK/m$k.yaml" --server "127.0.0.1:$PORT" --tool-width 0.4 \
          --time-limit 0.05 --out "$WORK/ack.$round.$c.$i.json" >/dev/null 2>&1 || true
      done
    ) &
    pids+=($!)
  done
  sleep "0.$(( RANDOM % 9 + 1 ))"
  kill -9 "$SERVER"; wait "$SERVER" 2>/dev/null || true
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  next=$(( next + CLIENTS * 10 ))
  : > "$WORK/server.log"
  start_server
  line=$(grep "map store indexed" "$WORK/server.log" || true)
  c=$(echo "$line" | sed -n 's/.*corrupted=\([0-9]*\).*/\1/p')
  corrupted=$(( corrupted + ${c:-0} ))
  for f in "$WORK"/ack."$round".*.json; do
    [ -e "$f" ] || continue
    id=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["map_id"])' "$f")
    acked=$((acked + 1))
    [ -f "$STORE/$id.map" ] || { lost=$((lost + 1)); echo "round $round: acknowledged map $id missing"; }
  done
  echo "round $round: $line"
  kill -TERM "$SERVER"; wait "$SERVER" 2>/dev/null || true; SERVER=
done
echo "acknowledged maps checked: $acked, missing: $lost, corrupted after restarts: $corrupted"
[ "$lost" -eq 0 ] && [ "$corrupted" -eq 0 ]
