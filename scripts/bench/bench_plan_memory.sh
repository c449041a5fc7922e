#!/usr/bin/env bash
# Remembered plans (docs/benchmarks.md §12): the same Release covplan-server,
# first with --plan_memory=false ("before": every request searches, with
# no plan memory), then with it on ("after"). For each: one warm-up Plan
# (per-map artifacts cached; after: the first plan remembered), then
# `covplan load` at concurrency 1, 4 and 16 with identical requests and with
# --random-start, then 40 random starts at concurrency 1 with one fixed seed
# (the same poses in both modes: a paired duration comparison).
#   scripts/bench/bench_plan_memory.sh OUTDIR [MAP] [TOOL] [DEADLINE_MS] [SECONDS]
# Only 127.0.0.1 is contacted; every load run is bounded.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
MAP=${2:-maps/sample_office.yaml}
TOOL=${3:-0.8}
DEADLINE=${4:-1000}
DUR=${5:-10}
BIN=${BIN:-build-rel/bin}
PORT=50171
METRICS=9471
mkdir -p "$OUT"
for mode in before after; do
  flag=--plan_memory=$([ $mode = before ] && echo false || echo true)
  rm -rf "$OUT/store-$mode"
  "$BIN/covplan-server" --port $PORT --metrics_port $METRICS --store_dir "$OUT/store-$mode" $flag \
    > "$OUT/server-$mode.log" 2>&1 &
  spid=$!
  trap 'kill $spid 2>/dev/null' EXIT
  sleep 1.5
  load() { "$BIN/covplan" load --server 127.0.0.1:$PORT --map "$MAP" --tool-width "$TOOL" "$@"; }
  for variant in identical random; do
    extra=$([ $variant = random ] && echo --random-start || true)
    load --concurrency 1 --requests 1 --duration 30 --deadline-ms 5000 > /dev/null
    for c in 1 4 16; do
      load --concurrency $c --duration "$DUR" --deadline-ms "$DEADLINE" --seed $((100 + c)) $extra \
        > "$OUT/$mode-$variant-c$c.json"
      echo "$mode $variant c=$c $(cat "$OUT/$mode-$variant-c$c.json")"
    done
  done
  load --concurrency 1 --requests 40 --duration 300 --deadline-ms "$DEADLINE" --seed 7 --random-start \
    > "$OUT/$mode-paired.json"
  echo "$mode paired $(cat "$OUT/$mode-paired.json")"
  curl -s "127.0.0.1:$METRICS/metrics" | grep '^covplan_plan_source_total' > "$OUT/metrics-$mode.txt" || true
  kill $spid
  wait $spid 2>/dev/null || true
done
