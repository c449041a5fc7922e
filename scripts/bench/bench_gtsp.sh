#!/usr/bin/env bash
# GTSP solver quality benchmark on the GTSPLIB instances.
#
# Runs the `gtsp` CLI subcommand (it builds nothing itself) on every *.gtsp
# file of the data directory, at each time limit, with several seeds, and
# prints a markdown table of gaps to the best-known values.
#
#   scripts/bench/bench_gtsp.sh [--data DIR] [--limits "1 10"] [--seeds 5]
#                         [--threads 1] [--bin "CMD"] [--raw FILE] [--only REGEX]
#
# The solver command defaults to `covplan gtsp` from the first build found
# is built (build-release/ first, then build/).
set -euo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
data="$root/../shared/data/gtsp"
limits="1 10"
seeds=5
threads=1
bin=""
raw=""
only="."
while [[ $# -gt 0 ]]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --limits) limits="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --raw) raw="$2"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "bench_gtsp.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

if [[ -z "$bin" ]]; then
  for cand in "$root"/build-release/bin/covplan "$root"/build/bin/covplan; do
    if [[ -x "$cand" ]]; then bin="$cand gtsp"; break; fi
  done
fi
if [[ -z "$bin" ]]; then
  echo "bench_gtsp.sh: no covplan binary found; run scripts/build.sh first" >&2
  exit 2
fi
[[ -f "$data/best_known.csv" ]] || { echo "bench_gtsp.sh: $data/best_known.csv not found" >&2; exit 2; }

[[ -n "$raw" ]] || raw="$(mktemp /tmp/bench_gtsp.XXXXXX.tsv)"
: > "$raw"
echo "bench_gtsp.sh: solver '$bin', raw results in $raw" >&2

# Instances in increasing size (the name's digits after the set count).
mapfile -t files < <(ls "$data"/*.gtsp | grep -E "$only" | awk -F/ '{n=$NF; sub(/\.gtsp$/,"",n); m=n; sub(/^[0-9]+[a-zA-Z]+/,"",m); print m"\t"$0}' | sort -n | cut -f2)
for f in "${files[@]}"; do
  name="$(basename "$f" .gtsp)"
  for limit in $limits; do
    for ((seed = 1; seed <= seeds; seed++)); do
      json="$($bin "$f" --time-limit "$limit" --seed "$seed" --threads "$threads")"
      /usr/bin/python3 -c 'import json,sys; d=json.loads(sys.argv[1]); print("\t".join([sys.argv[2], sys.argv[3], sys.argv[4], str(d["cost"]), str(d["time_s"]), str(len(d["tour"]))]))' \
        "$json" "$name" "$limit" "$seed" >> "$raw"
      echo "  $name limit=${limit}s seed=$seed: $(tail -1 "$raw" | cut -f4,5)" >&2
    done
  done
done

/usr/bin/python3 - "$raw" "$data/best_known.csv" "$limits" <<'EOF'
import collections, csv, sys
raw, known_csv, limits = sys.argv[1], sys.argv[2], [float(x) for x in sys.argv[3].split()]
known = {r["instance"].lower(): r for r in csv.DictReader(open(known_csv))}
runs = collections.defaultdict(list)
order = []
for line in open(raw):
    name, limit, seed, cost, time_s, sets = line.rstrip("\n").split("\t")
    if name not in order:
        order.append(name)
    runs[(name, float(limit))].append((int(cost), float(time_s)))
fmt = lambda x: f"{x:.2f}"
head = "| instance | nodes | sets | best_known |"
sep = "|---|---:|---:|---:|"
for l in limits:
    head += f" mean gap % @{l:g}s | worst gap % @{l:g}s | mean time s @{l:g}s |"
    sep += "---:|---:|---:|"
print(head)
print(sep)
summary = collections.defaultdict(list)
for name in order:
    k = known[name.lower()]
    best = int(k["best_known"])
    row = f"| {name} | {k['nodes']} | {k['sets']} | {best} |"
    for l in limits:
        rs = runs.get((name, l), [])
        if not rs:
            row += " - | - | - |"
            continue
        gaps = [100.0 * (c - best) / best for c, _ in rs]
        mean_gap = sum(gaps) / len(gaps)
        summary[l].append((int(k["nodes"]), mean_gap))
        row += f" {mean_gap:.3f} | {max(gaps):.3f} | {fmt(sum(t for _, t in rs) / len(rs))} |"
    print(row)
print()
for l in limits:
    s = summary[l]
    small = [g for n, g in s if n <= 500]
    large = [g for n, g in s if n > 500]
    line = f"- @{l:g}s: mean of mean gaps {sum(g for _, g in s) / max(1, len(s)):.3f}%"
    if small:
        line += f"; <=500 nodes: mean {sum(small) / len(small):.3f}%, max {max(small):.3f}%"
    if large:
        line += f"; >500 nodes: mean {sum(large) / len(large):.3f}%, max {max(large):.3f}%"
    print(line)
EOF
