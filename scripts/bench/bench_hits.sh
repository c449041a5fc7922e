#!/usr/bin/env bash
# Repeated identical Plan requests against one covplan-server (remembered
# plans): starts the server from BIN_DIR, plans the shipped office once
# (cold) and once more (the first hit), then runs `covplan load` for 10 s at
# concurrency 1, 4 and 16 with identical requests and prints one line each.
#
#   scripts/bench/bench_hits.sh [BIN_DIR (build/bin)] [TOOL (0.8)] [PORT (50181)]
# EXTRA="--full-replies" decodes every reply in the client.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
bin="${1:-$root/build/bin}"; tool="${2:-0.8}"; port="${3:-50181}"
store="$(mktemp -d /tmp/bench_hits.XXXXXX)"
"$bin/covplan-server" --port "$port" --metrics_port 0 --store_dir "$store/maps" > "$store/server.log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null; rm -rf "$store"' EXIT
sleep 1.5
cd "$root"
"$bin/covplan" load --server "127.0.0.1:$port" --map maps/sample_office.yaml --tool-width "$tool" \
  --concurrency 1 --requests 2 --duration 30 --deadline-ms 5000 > /dev/null
for c in 1 4 16; do
  # shellcheck disable=SC2086
  "$bin/covplan" load --server "127.0.0.1:$port" --map maps/sample_office.yaml --tool-width "$tool" \
    --concurrency "$c" --duration 10 --deadline-ms 1000 --seed $((100 + c)) ${EXTRA:-} |
    /usr/bin/python3 -c "import json,sys; d=json.load(sys.stdin); print('tool=$tool c=$c ok=%d/%d rps=%.0f p50=%.2f p99=%.2f late=%d sources=%s' % (d['ok'], d['requests'], d['throughput_rps'], d['p50_ms'], d['p99_ms'], d['late'], d['plan_sources']))"
done
