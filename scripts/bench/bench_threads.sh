#!/usr/bin/env bash
# One thread against two on one map, seed by seed (interleaved):
#   scripts/bench/bench_threads.sh [BIN] [MAP] [TOOL] [SEEDS]
# defaults: build/bin/covplan, ../shared/data/maps/ipa/lab_a_scan.png, 0.3, "1 2 3 4 5 6 7 8".
# Prints "threads seed duration_s wall_s" per run, then the mean per thread count.
# The IPA maps are read in place (0.05 m/px, --free-thresh 0.021).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
bin="${1:-$root/build/bin/covplan}"
map="${2:-$root/../shared/data/maps/ipa/lab_a_scan.png}"
tool="${3:-0.3}"
seeds="${4:-1 2 3 4 5 6 7 8}"
out="$(mktemp -d /tmp/bench_threads.XXXXXX)"
for seed in $seeds; do
  for t in 1 2; do
    s=$(date +%s.%N)
    report=$("$bin" plan --local --map "$map" --resolution 0.05 --free-thresh 0.021 \
      --tool-width "$tool" --threads "$t" --seed "$seed" --out "$out/plan.json" 2>&1)
    e=$(date +%s.%N)
    d=$(awk '/^duration/{print $2}' <<<"$report")
    echo "$t $seed $d $(awk -v s="$s" -v e="$e" 'BEGIN{printf "%.3f", e - s}')"
  done
done | tee "$out/runs.txt"
awk '{n[$1]++; d[$1]+=$3; w[$1]+=$4} END {for (t in n) printf "threads %s: duration mean %.1f s, wall mean %.2f s over %d runs\n", t, d[t]/n[t], w[t]/n[t], n[t]}' "$out/runs.txt"
rm -rf "$out"
