#!/usr/bin/env bash
# Store corruption kinds: stores 8 maps through covplan-server, stops it,
# damages six map files in six ways (payload byte flipped, truncated to half,
# header cut, bad magic, emptied, another map's file under this name), plants
# a FIFO and a symlink under map names and a leftover temporary file, then
# restarts the server and checks: it starts at once, the six are reported
# corrupted and the two intact maps indexed, the FIFO and symlink are
# skipped, the temporary file is gone; one `covplan plan` (PutMap) of a
# damaged map repairs it.
#   scripts/chaos/corrupt_store.sh        (BIN default build-h/bin)
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=${BIN:-build-h/bin}
WORK=$(mktemp -d -t covplan-corrupt.XXXXXX)
STORE="$WORK/store"
SERVER=
trap '[ -n "$SERVER" ] && kill -9 $SERVER 2>/dev/null; rm -rf "$WORK"' EXIT
/usr/bin/python3 scripts/maps/gen_bench_maps.py "$WORK" 8 200 150
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
start_server() {
  : > "$WORK/server.log"
  PORT=$(free_port)
  local t0=$(date +%s%N)
  "$BIN"/covplan-server --port "$PORT" --metrics_port -1 --store_dir "$STORE" 2>"$WORK/server.log" &
  SERVER=$!
  for _ in $(seq 1 100); do grep -q "map store indexed" "$WORK/server.log" && break; sleep 0.05; done
  echo "start-up to indexed: $(( ($(date +%s%N) - t0) / 1000000 )) ms"
}
stop_server() { kill -TERM "$SERVER"; wait "$SERVER" 2>/dev/null || true; SERVER=; }
plan() { "$BIN"/covplan plan --map "$WORK/m$1.yaml" --server "127.0.0.1:$PORT" --tool-width 0.4 \
           --time-limit 0.05 --out "$WORK/p$1.json" >/dev/null; }
id_of() { /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["map_id"])' "$WORK/p$1.json"; }
start_server
for k in $(seq 0 7); do plan "$k"; done
stop_server
ids=(); for k in $(seq 0 7); do ids+=("$(id_of "$k")"); done
f() { echo "$STORE/${ids[$1]}.map"; }
/usr/bin/python3 - "$(f 0)" <<'PY'
import sys
p = sys.argv[1]; b = bytearray(open(p, "rb").read()); b[-20] ^= 0x55; open(p, "wb").write(b)
PY
truncate -s "$(( $(stat -c %s "$(f 1)") / 2 ))" "$(f 1)"        # truncated
truncate -s 10 "$(f 2)"                                           # header cut
printf 'X' | dd of="$(f 3)" bs=1 count=1 conv=notrunc 2>/dev/null # bad magic
: > "$(f 4)"                                                      # emptied
cp "$(f 6)" "$(f 5)"                                              # another map's file
mkfifo "$STORE/$(printf 'a%.0s' $(seq 64)).map"
ln -s /etc/hostname "$STORE/$(printf 'b%.0s' $(seq 64)).map"
echo junk > "$STORE/${ids[7]}.map.tmp.1.1"
start_server
line=$(grep "map store indexed" "$WORK/server.log")
echo "$line"
fail=0
echo "$line" | grep -q "maps=2 corrupted=6" || { echo "FAIL: expected maps=2 corrupted=6"; fail=1; }
[ -e "$STORE/${ids[7]}.map.tmp.1.1" ] && { echo "FAIL: temporary file left"; fail=1; }
plan 0 && echo "PutMap of the damaged map 0: OK"
stop_server
start_server
grep "map store indexed" "$WORK/server.log" | grep -q "maps=3 corrupted=5" \
  && echo "after one PutMap: maps=3 corrupted=5 (repaired)" || { echo "FAIL: not repaired"; fail=1; }
stop_server
exit $fail
