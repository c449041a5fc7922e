#!/usr/bin/env bash
# Held-out-sized buildings and small tools (docs/benchmarks.md section 14):
# the whole `covplan plan --local` process on every plain IPA
# building and the shipped maps at tool TOOL (0.8 m) with 2 threads, median
# wall of RUNS runs, and
# the estimated duration against a REF_S s `--tour-effort thorough` search
# of the same binary. With BEFORE set, the same run measures an older
# binary too (its --threads flag is used only if it has one).
#   AFTER=build/bin/covplan BEFORE=/tmp/old/covplan scripts/bench/bench_buildings.sh
#   TOOL=0.1 REF_S=60 RUNS=1 MAPS=../shared/data/maps/ipa/lab_f_scan.png scripts/bench/bench_buildings.sh
# Environment: AFTER (build/bin/covplan), BEFORE (unset), RUNS (3),
# BEFORE_RUNS (RUNS; runs of the before binary), REF_S
# (30; 0 skips the reference), TOOL (0.8), IPA_DIR, MAPS (all), SEEDS (unset:
# the default seed; else run k uses --seed SEEDS[k mod count]), OUT (raw JSON
# lines; default a temp file). The before and after runs alternate. Prints a
# markdown table with the median and the largest wall time and the largest
# peak RSS of each binary's runs. The IPA maps are read in place, never
# copied.
set -euo pipefail
cd "$(dirname "$0")/../.."
AFTER=${AFTER:-build/bin/covplan}
BEFORE=${BEFORE:-}
RUNS=${RUNS:-3}
BEFORE_RUNS=${BEFORE_RUNS:-$RUNS}
REF_S=${REF_S:-30}
TOOL=${TOOL:-0.8}
IPA=${IPA_DIR:-../shared/data/maps/ipa}
OUT=${OUT:-$(mktemp -t bench_buildings.XXXXXX.jsonl)}
[ -x "$AFTER" ] || { echo "bench_buildings: $AFTER not built" >&2; exit 2; }
maps=()
if [ -n "${MAPS:-}" ]; then
  read -r -a maps <<< "$MAPS"
else
  if [ -d "$IPA" ]; then
    for f in "$IPA"/*.png; do case "$f" in *_furnitures.png) ;; *) maps+=("$f") ;; esac; done
  else
    echo "bench_buildings: $IPA not found; shipped maps only" >&2
  fi
  maps+=(maps/sample_office.yaml maps/small_rooms.yaml maps/sample_yard.geojson)
fi
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
echo "raw results: $OUT" >&2
: > "$OUT"
/usr/bin/python3 - "$OUT" "$AFTER" "$BEFORE" "$RUNS" "$REF_S" "$TOOL" "$BEFORE_RUNS" "${SEEDS:-}" "${maps[@]}" <<'EOF'
import json, os, statistics, subprocess, sys, tempfile, time
out, after, before, runs, ref_s = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), float(sys.argv[5])
tool, before_runs, seeds = sys.argv[6], int(sys.argv[7]), sys.argv[8].split()
maps = sys.argv[9:]
tmp = tempfile.mkdtemp()

def has_threads(binary):
    h = subprocess.run([binary, "plan", "--help"], capture_output=True, text=True)
    return "--threads" in (h.stdout + h.stderr)

def plan(binary, m, extra):
    args = [binary, "plan", "--local", "--map", m, "--tool-width", tool, "--out", os.path.join(tmp, "p.json")]
    if m.endswith(".png"):
        args += ["--resolution", "0.05", "--free-thresh", "0.021"]
    log = open(os.path.join(tmp, "log"), "w+")
    t = time.perf_counter()
    p = subprocess.Popen(args + extra, stdout=log, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    rss_mib = usage.ru_maxrss / 1024.0  # KiB on Linux
    if os.waitstatus_to_exitcode(status) != 0:
        log.seek(0)
        return {"wall_s": wall, "rss_mib": rss_mib, "error": log.read().strip()[:300]}
    s = json.load(open(os.path.join(tmp, "p.json")))["stats"]
    return {"wall_s": wall, "rss_mib": rss_mib, "ranks": s["num_ranks"], "duration_s": s["estimated_duration_s"],
            "tour_solver": s["tour_solver"], "transitions_ms": s["transitions_ms"], "tour_ms": s["tour_ms"]}

bins = [("after", after)] + ([("before", before)] if before else [])
rows = []
with open(out, "w") as f:
    for m in maps:
        name = os.path.basename(m).split(".")[0]
        row = {"map": name}
        results = {label: [] for label, _ in bins}
        for k in range(max(runs, before_runs if before else 0)):
            for label, b in bins:
                if k >= (runs if label == "after" else before_runs):
                    continue
                extra = (["--threads", "2"] if has_threads(b) else []) + (["--seed", seeds[k % len(seeds)]] if seeds else [])
                r = plan(b, m, extra)
                r["seed"] = seeds[k % len(seeds)] if seeds else "default"
                f.write(json.dumps({"map": name, "bin": label, **r}) + "\n")
                results[label].append(r)
        for label, b in bins:
            thr = ["--threads", "2"] if has_threads(b) else []
            rs = results[label]
            ok = [r for r in rs if "error" not in r]
            if not ok:
                row[label] = {"error": rs[0]["error"]}
                continue
            row[label] = {"wall": statistics.median(r["wall_s"] for r in ok), "wall_max": max(r["wall_s"] for r in ok),
                          "ranks": ok[0]["ranks"],
                          "rss": max(r["rss_mib"] for r in ok),
                          "dur": statistics.median(r["duration_s"] for r in ok), "solver": ok[0]["tour_solver"]}
            if ref_s > 0 and label == "after":
                ref = plan(b, m, thr + ["--time-limit", str(ref_s), "--tour-effort", "thorough"])
                f.write(json.dumps({"map": name, "bin": label + "-ref", **ref}) + "\n")
                row["ref"] = ref.get("duration_s")
        rows.append(row)
        f.flush()
        print(f"  {name}: {row}", file=sys.stderr)

hdr = "| map | ranks | tour | wall (median of %d) | wall (max) | peak RSS | est. duration | gap to %g s search |" % (runs, ref_s)
sep = "|---|---:|---|---:|---:|---:|---:|---:|"
if before:
    hdr += " before: wall | before: wall (max) | before: peak RSS | before: est. duration |"
    sep += "---:|---:|---:|---:|"
print(hdr); print(sep)
walls, gaps = [], []
for r in rows:
    a = r.get("after", {})
    if "error" in a:
        line = f"| {r['map']} | – | – | error: {a['error']} | | | | |"
    else:
        gap = 100.0 * (a["dur"] - r["ref"]) / r["ref"] if r.get("ref") else None
        walls.append(a["wall"]); gaps.append(gap)
        line = (f"| {r['map']} | {a['ranks']} | {a['solver']} | {a['wall']:.2f} s | {a['wall_max']:.2f} s | {a['rss']:.0f} MiB | {a['dur']:.1f} s | "
                + (f"{gap:+.2f} %" if gap is not None else "–") + " |")
    if before:
        b = r.get("before", {})
        line += (f" error: {b['error'][:80]} | | | |" if "error" in b else f" {b['wall']:.2f} s | {b['wall_max']:.2f} s | {b['rss']:.0f} MiB | {b['dur']:.1f} s |")
    print(line)
if walls:
    g = [x for x in gaps if x is not None]
    print(f"\nafter: max wall {max(walls):.2f} s, {sum(w <= 1.0 for w in walls)}/{len(walls)} maps <= 1 s at tool {tool} m"
          + (f"; gap mean {statistics.mean(g):+.2f} %, max {max(g):+.2f} %" if g else ""))
EOF
