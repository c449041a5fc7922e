#!/usr/bin/env bash
# A one-machine covplan cluster from Debian packages: 3 covplan-server
# replicas, the map-affine HAProxy router (plus a round-robin frontend on the
# same replicas, for comparison), PostgreSQL as the shared map store, and
# Prometheus scraping every replica with deploy/prometheus/covplan-rules.yml.
#
#   scripts/deploy/cluster.sh up         # start everything (idempotent per process)
#   scripts/deploy/cluster.sh status     # what runs, health, where
#   scripts/deploy/cluster.sh kill N     # SIGKILL replica N (1..3), for failure runs
#   scripts/deploy/cluster.sh start N    # start replica N again
#   scripts/deploy/cluster.sh down       # stop everything (SIGTERM: replicas drain)
#
# Environment: COVPLAN_CLUSTER_DIR (state, logs; default /tmp/covplan-cluster),
# COVPLAN_CLUSTER_PORT (base port, default 56100: router BASE, round robin
# BASE+5, router stats BASE+6, replicas BASE+1..3 with metrics BASE+11..13,
# PostgreSQL BASE+50 on a unix socket, Prometheus BASE+90),
# COVPLAN_BIN (default build/bin), CLUSTER_STORE=postgres|disk (default
# postgres when initdb is installed; disk: one store dir per replica, so a
# map registered on one replica is unknown to the others),
# CLUSTER_CACHE_MB (per replica, default 256), CLUSTER_THREADS (default 1).
# Needs haproxy, prometheus and postgresql: `up` installs them with apt-get
# (scripts/install-deps.sh --only) and builds covplan when build/bin has no
# server. Nothing here is used by the test suite or run_sample.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
DIR=${COVPLAN_CLUSTER_DIR:-/tmp/covplan-cluster}
BASE=${COVPLAN_CLUSTER_PORT:-56100}
BIN=${COVPLAN_BIN:-$ROOT/build/bin}
PG_BIN=${PG_BIN:-/usr/lib/postgresql/15/bin}
if [ "${1:-}" = up ]; then
  # On a fresh clone: the packages the cluster runs on, and the build.
  extra=(haproxy prometheus)
  [ "${CLUSTER_STORE:-}" = disk ] || extra+=(postgresql)
  bash "$ROOT/scripts/install-deps.sh" --only "${extra[@]}"
  if [ ! -x "$BIN/covplan-server" ]; then
    if [ -n "${COVPLAN_BIN:-}" ]; then
      echo "cluster: no covplan-server in COVPLAN_BIN=$BIN"
      exit 1
    fi
    echo "cluster: building covplan into build/ (scripts/build.sh; minutes on a fresh clone)"
    mkdir -p "$DIR"
    bash "$ROOT/scripts/build.sh" >"$DIR/build.log" 2>&1 ||
      { tail -20 "$DIR/build.log"; exit 1; }
  fi
fi
if [ -z "${CLUSTER_STORE:-}" ]; then
  if [ -x "$PG_BIN/initdb" ]; then CLUSTER_STORE=postgres; else CLUSTER_STORE=disk; fi
fi
CACHE_MB=${CLUSTER_CACHE_MB:-256}
THREADS=${CLUSTER_THREADS:-1}
REPLICAS=3
ROUTER_PORT=$BASE
RR_PORT=$((BASE + 5))
STATS_PORT=$((BASE + 6))
PG_PORT=$((BASE + 50))
PROM_PORT=$((BASE + 90))
PG_DIR=$DIR/pg
PG_CONNINFO="host=$PG_DIR port=$PG_PORT dbname=covplan user=covplan connect_timeout=2"
mkdir -p "$DIR"

grpc_port() { echo $((BASE + $1)); }
metrics_port() { echo $((BASE + 10 + $1)); }
alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
port_open() { (exec 3<>/dev/tcp/127.0.0.1/"$1") 2>/dev/null; }
wait_port() {  # port name pidfile
  for _ in $(seq 1 150); do
    if port_open "$1"; then return 0; fi
    if [ -n "${3:-}" ] && ! alive "$3"; then echo "$2 exited; log:"; tail -20 "$DIR/$2.log"; return 1; fi
    sleep 0.1
  done
  echo "$2 did not open port $1"; return 1
}
# PostgreSQL refuses to run as root: run its tools as the postgres user then.
as_pg() { if [ "$(id -u)" = 0 ]; then runuser -u postgres -- "$@"; else "$@"; fi; }

pg_up() {
  [ "$CLUSTER_STORE" = postgres ] || return 0
  if [ ! -f "$PG_DIR/data/PG_VERSION" ]; then
    mkdir -p "$PG_DIR"
    [ "$(id -u)" = 0 ] && chown postgres: "$PG_DIR"
    as_pg "$PG_BIN/initdb" -D "$PG_DIR/data" -U covplan -A trust >"$DIR/initdb.log" 2>&1
  fi
  if ! as_pg "$PG_BIN/pg_ctl" -D "$PG_DIR/data" status >/dev/null 2>&1; then
    as_pg "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -l "$PG_DIR/postgres.log" -w \
      -o "-k $PG_DIR -p $PG_PORT -c listen_addresses=''" start >/dev/null
    as_pg "$PG_BIN/createdb" -h "$PG_DIR" -p "$PG_PORT" -U covplan covplan 2>/dev/null || true
  fi
  echo "postgres on $PG_DIR/.s.PGSQL.$PG_PORT"
}

replica_up() {
  local n=$1 pidfile=$DIR/replica$1.pid
  if alive "$pidfile"; then return 0; fi
  local store_flags=(--store_dir "$DIR/replica$n/maps")
  if [ "$CLUSTER_STORE" = postgres ]; then
    store_flags+=(--map_store=postgres "--pg_conninfo=$PG_CONNINFO")
  fi
  mkdir -p "$DIR/replica$n"
  "$BIN/covplan-server" --port "$(grpc_port "$n")" --metrics_port "$(metrics_port "$n")" \
    --threads "$THREADS" --cache_mb "$CACHE_MB" --drain_notice_s 1 --drain_grace_s 5 --replica "r$n" \
    "${store_flags[@]}" >>"$DIR/replica$n.log" 2>&1 &
  echo $! >"$pidfile"
  wait_port "$(grpc_port "$n")" "replica$n" "$pidfile"
  echo "replica$n on 127.0.0.1:$(grpc_port "$n") (metrics :$(metrics_port "$n"), pid $(cat "$pidfile"))"
}

router_up() {
  local servers=""
  for n in $(seq 1 $REPLICAS); do
    servers+="    server r$n 127.0.0.1:$(grpc_port "$n") proto h2 check inter 500ms fall 2 rise 2"$'\n'
  done
  /usr/bin/python3 - "$ROOT/deploy/cluster/haproxy.cfg.in" "$DIR/haproxy.cfg" <<PY
import sys
s = open(sys.argv[1]).read()
for k, v in {"@DIR@": "$DIR", "@ROUTER_PORT@": "$ROUTER_PORT", "@RR_PORT@": "$RR_PORT",
             "@STATS_PORT@": "$STATS_PORT", "@SERVERS@\n": """$servers"""}.items():
    s = s.replace(k, v)
open(sys.argv[2], "w").write(s)
PY
  haproxy -c -q -f "$DIR/haproxy.cfg"
  if alive "$DIR/haproxy.pid"; then return 0; fi
  haproxy -f "$DIR/haproxy.cfg" -D -p "$DIR/haproxy.pid" >>"$DIR/haproxy.log" 2>&1
  wait_port "$ROUTER_PORT" haproxy
  echo "router on 127.0.0.1:$ROUTER_PORT (map-affine), :$RR_PORT (round robin), stats :$STATS_PORT/stats"
}

prometheus_up() {
  local targets
  targets=$(for n in $(seq 1 $REPLICAS); do printf "'127.0.0.1:%s'," "$(metrics_port "$n")"; done)
  sed -e "s|@RULES@|$ROOT/deploy/prometheus/covplan-rules.yml|" \
      -e "s|@REPLICA_TARGETS@|${targets%,}|" -e "s|@STATS_PORT@|$STATS_PORT|" \
      "$ROOT/deploy/cluster/prometheus.yml.in" >"$DIR/prometheus.yml"
  promtool check config "$DIR/prometheus.yml" >/dev/null
  if alive "$DIR/prometheus.pid"; then return 0; fi
  prometheus --config.file="$DIR/prometheus.yml" --storage.tsdb.path="$DIR/prometheus" \
    --web.listen-address="127.0.0.1:$PROM_PORT" >>"$DIR/prometheus.log" 2>&1 &
  echo $! >"$DIR/prometheus.pid"
  wait_port "$PROM_PORT" prometheus "$DIR/prometheus.pid"
  echo "prometheus on http://127.0.0.1:$PROM_PORT"
}

stop_pidfile() {  # pidfile [signal]
  if alive "$1"; then
    local pid; pid=$(cat "$1")
    kill "-${2:-TERM}" "$pid" 2>/dev/null || true
    for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  fi
  rm -f "$1"
}

case "${1:-}" in
  up)
    echo "cluster in $DIR, store: $CLUSTER_STORE"
    pg_up
    for n in $(seq 1 $REPLICAS); do replica_up "$n"; done
    router_up
    prometheus_up
    ;;
  start) replica_up "${2:?replica number}" ;;
  kill)
    pidfile=$DIR/replica${2:?replica number}.pid
    alive "$pidfile" && kill -KILL "$(cat "$pidfile")" && echo "replica$2 killed (SIGKILL)"
    rm -f "$pidfile"
    ;;
  down)
    stop_pidfile "$DIR/prometheus.pid"
    stop_pidfile "$DIR/haproxy.pid"
    for n in $(seq 1 $REPLICAS); do stop_pidfile "$DIR/replica$n.pid"; done
    if [ "$CLUSTER_STORE" = postgres ] && [ -f "$PG_DIR/data/PG_VERSION" ]; then
      as_pg "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m fast stop >/dev/null 2>&1 || true
    fi
    echo "cluster stopped (state kept in $DIR)"
    ;;
  status)
    for n in $(seq 1 $REPLICAS); do
      if alive "$DIR/replica$n.pid"; then s=up; else s=down; fi
      echo "replica$n $s 127.0.0.1:$(grpc_port "$n") metrics :$(metrics_port "$n")"
    done
    if alive "$DIR/haproxy.pid"; then s=up; else s=down; fi
    echo "router $s 127.0.0.1:$ROUTER_PORT (affine) :$RR_PORT (round robin)"
    if [ -S "$DIR/haproxy.sock" ] && command -v socat >/dev/null; then
      echo "show servers state" | socat - "unix:$DIR/haproxy.sock" | awk 'NR>2 {print "  " $2 "/" $4 " state " $6}'
    fi
    if alive "$DIR/prometheus.pid"; then s=up; else s=down; fi
    echo "prometheus $s http://127.0.0.1:$PROM_PORT"
    if [ "$CLUSTER_STORE" = postgres ]; then
      if as_pg "$PG_BIN/pg_ctl" -D "$PG_DIR/data" status >/dev/null 2>&1; then s=up; else s=down; fi
      echo "postgres $s $PG_DIR port $PG_PORT"
    fi
    ;;
  *) sed -n '2,22p' "$0"; exit 2 ;;
esac
