#!/usr/bin/env bash
# Same plans before and after a change: plans every shipped map and the plain
# IPA buildings with each planner through `covplan plan --local`, one thread
# and a fixed seed, with two binaries, and compares the plan JSON with the
# timing fields and the plan id left out. A search that converged is
# deterministic for its seed, so any difference is a change of behaviour; a
# search that its time limit stopped is marked, since where it stops depends
# on the machine.
#   BEFORE=/tmp/old/bin/covplan scripts/bench/same_plans.sh
# Environment: BEFORE (required), AFTER (build/bin/covplan), TOOL (0.8),
# SEED (1), PLANNERS ("oarp stc boustrophedon"), IPA_DIR
# (../shared/data/maps/ipa; skipped when absent), MAPS (default: shipped maps
# plus the plain IPA maps). Prints a markdown table; exits 1 if any
# converged plan differs. The IPA maps are read in place, never copied.
set -euo pipefail
cd "$(dirname "$0")/../.."
BEFORE=${BEFORE:?set BEFORE to the covplan binary to compare against}
AFTER=${AFTER:-build/bin/covplan}
TOOL=${TOOL:-0.8}
SEED=${SEED:-1}
PLANNERS=${PLANNERS:-oarp stc boustrophedon}
IPA=${IPA_DIR:-../shared/data/maps/ipa}
for b in "$BEFORE" "$AFTER"; do [ -x "$b" ] || { echo "same_plans: $b not built" >&2; exit 2; }; done
maps=()
if [ -n "${MAPS:-}" ]; then
  read -r -a maps <<< "$MAPS"
else
  maps=(maps/sample_office.yaml maps/small_rooms.yaml maps/sample_yard.geojson)
  if [ -d "$IPA" ]; then
    for f in "$IPA"/*.png; do case "$f" in *_furnitures.png) ;; *) maps+=("$f") ;; esac; done
  else
    echo "same_plans: $IPA not found; shipped maps only" >&2
  fi
fi
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%FT%TZ)" >&2
exec /usr/bin/python3 - "$BEFORE" "$AFTER" "$TOOL" "$SEED" "$PLANNERS" "${maps[@]}" <<'PY'
import json, os, subprocess, sys, tempfile, time
before, after, tool, seed, planners = sys.argv[1:6]
maps = sys.argv[6:]
tmp = tempfile.mkdtemp()

def strip(node):
    """The plan without what depends on the clock or the call."""
    if isinstance(node, dict):
        return {k: strip(v) for k, v in node.items()
                if not (k.endswith("_ms") or k in ("plan_id", "decomposition_cached"))}
    if isinstance(node, list):
        return [strip(v) for v in node]
    return node

def plan(binary, m, planner, tag):
    out = os.path.join(tmp, tag + ".json")
    args = [binary, "plan", "--local", "--map", m, "--tool-width", tool, "--seed", seed,
            "--threads", "1", "--planner", planner, "--out", out]
    if m.endswith(".png") and not os.path.exists(m[:-4] + ".yaml"):
        args += ["--resolution", "0.05", "--free-thresh", "0.021"]
    t = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        return None, wall, (r.stderr or r.stdout).strip().splitlines()[-1:]
    with open(out) as f:
        return json.load(f), wall, None

differ = 0
print("| map | planner | elements | duration before s | duration after s | termination | wall before s | wall after s | same plan |")
print("|---|---|---:|---:|---:|---|---:|---:|---|")
for m in maps:
    for p in planners.split():
        a, wa, ea = plan(before, m, p, "before")
        b, wb, eb = plan(after, m, p, "after")
        name = os.path.basename(m)
        if a is None or b is None:
            same = "error both" if (a is None and b is None and ea == eb) else "DIFFERS (error)"
            if same != "error both":
                differ += 1
            print(f"| {name} | {p} | | | | {ea or eb} | {wa:.2f} | {wb:.2f} | {same} |")
            continue
        st_a, st_b = a.get("stats", {}), b.get("stats", {})
        term = a.get("termination", {})
        converged = term.get("reason", "") in ("", "CONVERGED") and not st_a.get("tour_cut_short")
        identical = strip(a) == strip(b)
        if identical:
            same = "yes"
        elif converged:
            same = "DIFFERS"
            differ += 1
        else:
            same = "differs (time limit bound)"
        elements = st_a.get("num_ranks") or len(a.get("sweeps", []))
        print(f"| {name} | {p} | {elements} | {st_a.get('estimated_duration_s', 0):.1f} | "
              f"{st_b.get('estimated_duration_s', 0):.1f} | {term.get('reason', '?')} | {wa:.2f} | {wb:.2f} | {same} |")
sys.exit(1 if differ else 0)
PY
