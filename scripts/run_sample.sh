#!/usr/bin/env bash
# The main job: install dependencies, build, start covplan-server with its
# embedded defaults (on-disk map store under ./covplan-data, no external
# services), plan the shipped sample map through the server, print the
# figures and write plan.json and plan.svg; then plan the shipped office for
# a fleet of three robots (PlanFleet) and write fleet.json and fleet.svg; plan
# a lawn drawn in longitude/latitude (--crs EPSG:4326) and write its route
# back in longitude/latitude (lawn.geojson, lawn.csv, lawn_path.json);
# list the stored maps over the JSON API (--http_port); last, install the Python
# client into .venv and run its examples (plan_py.json, plan_py.svg; a robot
# driven through a Drive session). With WATCH=1 it then drives a simulated
# robot through the server at 10x real time (covplan simulate --watch) to
# watch live in the web console, and stops when it ends.
#   scripts/run_sample.sh [MAP] [extra `covplan plan` flags...]
#   WATCH=1 scripts/run_sample.sh
set -euo pipefail
cd "$(dirname "$0")/.."
MAP=${1:-maps/sample_office.yaml}
shift || true
OUT_DIR=${OUT_DIR:-.}

bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOVPLAN_BUILD_SERVER=ON >/dev/null
cmake --build build -j"$(nproc)" --target covplan-server covplan

free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
PORT=${PORT:-$(free_port)}
METRICS_PORT=${METRICS_PORT:-$(free_port)}
HTTP_PORT=${HTTP_PORT:-$(free_port)}
LOG=$(mktemp -t covplan-server.XXXXXX.log)
./build/bin/covplan-server --port "$PORT" --metrics_port "$METRICS_PORT" \
  --http_port "$HTTP_PORT" --store_dir ./covplan-data/maps 2>"$LOG" &
SERVER=$!
cleanup() { kill -TERM "$SERVER" 2>/dev/null || true; wait "$SERVER" 2>/dev/null || true; }
trap cleanup EXIT

# Wait (bounded) for the gRPC port to accept connections.
for _ in $(seq 1 100); do
  if (exec 3<>/dev/tcp/127.0.0.1/"$PORT") 2>/dev/null; then break; fi
  if ! kill -0 "$SERVER" 2>/dev/null; then echo "covplan-server exited:"; cat "$LOG"; exit 1; fi
  sleep 0.1
done
echo "covplan-server on 127.0.0.1:$PORT (metrics on :$METRICS_PORT, log $LOG)"
echo "JSON API on http://127.0.0.1:$HTTP_PORT/v1/<Method> (docs/json_api.md); console http://127.0.0.1:$HTTP_PORT/"

./build/bin/covplan plan --map "$MAP" --server "127.0.0.1:$PORT" \
  --out "$OUT_DIR/plan.json" --svg "$OUT_DIR/plan.svg" "$@"
echo "wrote $OUT_DIR/plan.json and $OUT_DIR/plan.svg"

# A fleet: three robots starting at three doors of the shipped office
# (FLEET=0 skips it).
if [ "${FLEET:-1}" = 1 ]; then
  ./build/bin/covplan plan --map maps/sample_office.yaml --server "127.0.0.1:$PORT" \
    --robot west=1.5,1.5 --robot east=20,1.5 --robot hall=10,10 \
    --out "$OUT_DIR/fleet.json" --svg "$OUT_DIR/fleet.svg"
  echo "wrote $OUT_DIR/fleet.json and $OUT_DIR/fleet.svg"
fi

# A lawn drawn on a web map (longitude/latitude, RFC 7946) planned through the same
# server: --crs EPSG:4326 projects it onto a local metric frame with PROJ; the route comes
# back in longitude/latitude (lawn.geojson) and as CSV waypoints and a nav_msgs/Path.
./build/bin/covplan plan --map maps/sample_lawn_lonlat.geojson --crs EPSG:4326 \
  --no-go maps/sample_lawn_lonlat_no_go.geojson --server "127.0.0.1:$PORT" \
  --out-geojson "$OUT_DIR/lawn.geojson" --out-csv "$OUT_DIR/lawn.csv" \
  --out-nav-path "$OUT_DIR/lawn_path.json" | grep -E '^(frame|ranks|duration)'
echo "wrote $OUT_DIR/lawn.geojson (lon/lat), lawn.csv and lawn_path.json"

# The same server over its JSON API: the maps stored so far.
echo "curl -X POST http://127.0.0.1:$HTTP_PORT/v1/ListMaps -d '{}':"
curl -sS --max-time 10 -H 'Content-Type: application/json' -X POST \
  "http://127.0.0.1:$HTTP_PORT/v1/ListMaps" -d '{}' |
  /usr/bin/python3 -c 'import json,sys; m=json.load(sys.stdin)["maps"]; print(f"  {len(m)} maps:", ", ".join(x["mapId"][:12] + " " + x.get("name","") for x in m))'

# The Python client (clients/python) against the same server: pip-installed into .venv on
# Debian's python3-grpcio (scripts/python_env.sh), then its two examples (PYTHON=0 skips).
if [ "${PYTHON:-1}" = 1 ]; then
  VENV=$(bash scripts/python_env.sh .venv)
  echo "python client: $VENV/bin/python clients/python/examples/plan_map.py"
  "$VENV/bin/python" clients/python/examples/plan_map.py --server "127.0.0.1:$PORT" \
    --map maps/sample_yard.geojson --no-go maps/sample_yard_no_go.geojson --out "$OUT_DIR/plan_py"
  "$VENV/bin/python" clients/python/examples/drive_robot.py --server "127.0.0.1:$PORT" \
    --map maps/sample_office.yaml
fi

# WATCH=1: a robot drives the furnished office through the server, live in the console.
if [ "${WATCH:-0}" = 1 ]; then
  echo "open http://127.0.0.1:$HTTP_PORT/ and pick the sample office: a robot drives it live"
  ./build/bin/covplan simulate --map maps/sample_office.yaml \
    --true-map maps/sample_office_furnished.yaml --server "127.0.0.1:$PORT" --watch 10 \
    >"$OUT_DIR/watch.json"
  echo "wrote $OUT_DIR/watch.json (the watched run's figures)"
fi
