#!/usr/bin/env bash
# Cache locality and failover through the map-affine router, on the
# one-machine cluster (scripts/deploy/cluster.sh). Prints one JSON line per phase
# and a per-replica hit-rate table; docs/benchmarks.md §11 quotes a run.
#
#   COVPLAN_BIN=build-rel/bin bash scripts/bench/bench_cluster.sh
#
# Phases (each starts every replica fresh, so caches are cold):
#   direct    one cached map straight to replica 1 vs through the router:
#             the router's overhead per request;
#   affine    MAPS generated maps (Zipf skew ZIPF) through the map-affine
#             frontend;
#   rr        the same workload through the round-robin frontend;
#   failover  affine again, replica 2 SIGKILLed KILL_AT s into the run and
#             restarted RESTART_AT s in; afterwards every acknowledged map
#             is checked in the database.
# Environment: MAPS (24), ZIPF (0.8), DURATION (30 s), CONCURRENCY (4),
# DEADLINE_MS (1000), TOOL (0.4 m), CACHE_MB (3 per replica: below the
# working set of all maps, above a third of it), KILL_AT (10), RESTART_AT (20).
set -euo pipefail
cd "$(dirname "$0")/../.."
export COVPLAN_BIN=${COVPLAN_BIN:-$PWD/build/bin}
export COVPLAN_CLUSTER_DIR=${COVPLAN_CLUSTER_DIR:-/tmp/covplan-cluster}
export CLUSTER_CACHE_MB=${CACHE_MB:-3}
BASE=${COVPLAN_CLUSTER_PORT:-56100}
MAPS=${MAPS:-24}
ZIPF=${ZIPF:-0.8}
DURATION=${DURATION:-30}
CONCURRENCY=${CONCURRENCY:-4}
DEADLINE_MS=${DEADLINE_MS:-1000}
TOOL=${TOOL:-0.4}
KILL_AT=${KILL_AT:-10}
RESTART_AT=${RESTART_AT:-20}
MAP_DIR=$COVPLAN_CLUSTER_DIR/load-maps
CLUSTER="bash scripts/deploy/cluster.sh"
COVPLAN=$COVPLAN_BIN/covplan

/usr/bin/python3 scripts/maps/gen_load_maps.py --out "$MAP_DIR" --count "$MAPS" --seed 1
$CLUSTER up >/dev/null

restart_replicas() {
  for n in 1 2 3; do $CLUSTER kill "$n" >/dev/null || true; done
  for n in 1 2 3; do $CLUSTER start "$n" >/dev/null; done
  sleep 1.5  # router health checks (inter 500ms, rise 2) see them up
}
# "hits misses" of replica N's artifact cache.
cache_counts() {
  curl -s "127.0.0.1:$((BASE + 10 + $1))/metrics" |
    awk '/^covplan_artifact_cache_hits_total/ {h=$2} /^covplan_artifact_cache_misses_total/ {m=$2}
         /^covplan_requests_total\{code="OK",method="Plan"\}/ {p=$2}
         END {printf "%d %d %d\n", h, m, p}'
}
hit_table() {  # label
  for n in 1 2 3; do
    read -r h m p < <(cache_counts "$n")
    awk -v l="$1" -v n="$n" -v h="$h" -v m="$m" -v p="$p" 'BEGIN {
      printf "%-9s replica%d  plans %5d  lookups %6d  hit rate %.3f\n", l, n, p, h + m, (h + m) ? h / (h + m) : 0 }'
  done
}
# The load report without its map id list (kept in $COVPLAN_CLUSTER_DIR/last-load.json).
short() { tee "$COVPLAN_CLUSTER_DIR/last-load.json" | sed 's/, "map_ids": \[[^]]*\]//'; }
load() {  # server [extra...]
  "$COVPLAN" load --server "$1" --maps "$MAP_DIR" --zipf "$ZIPF" --seed 7 \
    --concurrency "$CONCURRENCY" --duration "$DURATION" --deadline-ms "$DEADLINE_MS" \
    --tool-width "$TOOL" --tour greedy "${@:2}" | short
}

echo "== direct vs router: one cached map, concurrency 1, 10 s each"
restart_replicas
ONE=$MAP_DIR/site_000.yaml
"$COVPLAN" load --server "127.0.0.1:$((BASE + 1))" --map "$ONE" --concurrency 1 --duration 2 \
  --tool-width "$TOOL" --tour greedy >/dev/null  # warm replica 1
printf 'direct  '; "$COVPLAN" load --server "127.0.0.1:$((BASE + 1))" --map "$ONE" --concurrency 1 \
  --duration 10 --tool-width "$TOOL" --tour greedy | short
printf 'router  '; "$COVPLAN" load --server "127.0.0.1:$BASE" --map "$ONE" --concurrency 1 \
  --duration 10 --tool-width "$TOOL" --tour greedy | short

echo "== affine: $MAPS maps, zipf $ZIPF, ${DURATION}s, concurrency $CONCURRENCY, cache ${CLUSTER_CACHE_MB} MiB/replica"
restart_replicas
printf 'affine  '; load "127.0.0.1:$BASE"
hit_table affine

echo "== round robin: the same workload"
restart_replicas
printf 'rr      '; load "127.0.0.1:$((BASE + 5))"
hit_table rr

echo "== failover: affine, replica2 SIGKILL at ${KILL_AT}s, restarted at ${RESTART_AT}s"
restart_replicas
T0=$(date +%s)
( sleep "$KILL_AT"; $CLUSTER kill 2; sleep "$((RESTART_AT - KILL_AT))"; $CLUSTER start 2 ) &
KILLER=$!
printf 'failover '; load "127.0.0.1:$BASE"
cp "$COVPLAN_CLUSTER_DIR/last-load.json" "$COVPLAN_CLUSTER_DIR/failover.json"
wait "$KILLER"
hit_table failover
echo "== after the failover: hit rate over 10 more seconds of the same load"
declare -A before
for n in 1 2 3; do before[$n]=$(cache_counts "$n"); done
printf 'recovered '; DURATION=10 load "127.0.0.1:$BASE"
for n in 1 2 3; do
  read -r h0 m0 p0 <<<"${before[$n]}"
  read -r h m p < <(cache_counts "$n")
  awk -v n="$n" -v h=$((h - h0)) -v m=$((m - m0)) -v p=$((p - p0)) 'BEGIN {
    printf "recovered replica%d  plans %5d  lookups %6d  hit rate %.3f\n", n, p, h + m, (h + m) ? h / (h + m) : 0 }'
done
sleep 4  # one more scrape
echo "== timeline from Prometheus (10 s windows, every 5 s; t from the failover run's start)"
/usr/bin/python3 - "http://127.0.0.1:$((BASE + 90))" "$T0" "$(date +%s)" <<'PY'
import json, sys, urllib.parse, urllib.request
url, t0, t1 = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
def series(q):
    args = urllib.parse.urlencode({"query": q, "start": t0, "end": t1, "step": 5})
    data = json.load(urllib.request.urlopen(url + "/api/v1/query_range?" + args, timeout=10))
    return {r["metric"].get("instance", "all"): {int(float(t)): float(v) for t, v in r["values"]}
            for r in data["data"]["result"]}
plans = series('sum by (instance) (rate(covplan_requests_total{job="covplan",method="Plan"}[10s]))')
hits = 'sum(rate(covplan_artifact_cache_hits_total{job="covplan"}[10s]))'
miss = 'sum(rate(covplan_artifact_cache_misses_total{job="covplan"}[10s]))'
ratio = series("%s / (%s + %s)" % (hits, hits, miss)).get("all", {})
instances = sorted(plans)
print("t_s  " + "  ".join("%s plans/s" % i.split(":")[-1] for i in instances) + "  hit_ratio")
for t in range(t0, t1 + 1, 5):
    row = ["%4d" % (t - t0)] + ["%14.1f" % plans[i][t] if t in plans[i] else "%14s" % "-" for i in instances]
    row.append("%9.3f" % ratio[t] if t in ratio else "%9s" % "-")
    print("  ".join(row))
PY
if [ -S "$COVPLAN_CLUSTER_DIR/pg/.s.PGSQL.$((BASE + 50))" ]; then
  AS=""; [ "$(id -u)" = 0 ] && AS="runuser -u postgres --"
  intact=$($AS psql -h "$COVPLAN_CLUSTER_DIR/pg" -p $((BASE + 50)) -U covplan -d covplan -Atc \
    "SELECT count(*) FROM covplan_maps WHERE encode(sha256(payload), 'hex') = sha256
       AND map_id IN ($(grep -o '"map_ids": \[[^]]*\]' "$COVPLAN_CLUSTER_DIR/failover.json" |
                        sed -e 's/"map_ids": \[//' -e 's/\]//' -e "s/\"/'/g"))")
  echo "acknowledged maps: $MAPS, intact in the database after the run: $intact"
fi
