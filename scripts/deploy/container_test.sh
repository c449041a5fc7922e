#!/usr/bin/env bash
# Builds the covplan image without a Docker daemon or registry and runs it:
#   1. a Debian 12 base image made locally: debootstrap --variant=minbase
#      into a directory, imported with buildah (cached as
#      localhost/covplan-debian:bookworm-slim, ~30 MB of packages from the
#      Debian mirror apt already uses; docs, man pages and locales dropped
#      as in debian:12-slim);
#   2. buildah bud --isolation chroot --format docker (HEALTHCHECK is a
#      Docker-format field) with that base for both stages;
#   3. the server from the image, `buildah run --isolation chroot` on the
#      host network, as the image's non-root user; `covplan health` (the
#      image's HEALTHCHECK command) must say SERVING, and `covplan plan` from
#      inside the image plans the shipped maps/small_rooms.yaml through it;
#      the reply is checked;
#   4. prints the image size, user and health check.
#
#   sudo bash scripts/deploy/container_test.sh        # root, or rootless buildah
# Installs buildah and debootstrap with apt-get when they are missing.
# Exit 0 pass, 1 fail, 77 skipped (buildah / debootstrap could not be
# installed). Not part of scripts/test.sh: it compiles the whole project
# inside the build stage (tens of minutes on 2 cores), see docs/deploy.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
if ! command -v buildah >/dev/null || ! command -v debootstrap >/dev/null; then
  bash scripts/install-deps.sh --only buildah debootstrap || true
fi
for tool in buildah debootstrap; do
  command -v "$tool" >/dev/null || { echo "SKIPPED: $tool could not be installed (apt-get install buildah debootstrap)"; exit 77; }
done
BASE_IMAGE=${BASE_IMAGE:-localhost/covplan-debian:bookworm-slim}
IMAGE=${IMAGE:-localhost/covplan-server:test}
MIRROR=${MIRROR:-http://deb.debian.org/debian}
PORT=${PORT:-56400}
METRICS_PORT=${METRICS_PORT:-56401}
WORK=$(mktemp -d -t covplan-container.XXXXXX)
CTR=""
SERVER_PID=""
cleanup() {
  if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then
    kill -TERM "$SERVER_PID"; sleep 2; kill -KILL "$SERVER_PID" 2>/dev/null || true
  fi
  [ -n "$CTR" ] && buildah rm "$CTR" >/dev/null 2>&1 || true
  rm -rf "$WORK"
}
trap cleanup EXIT

if ! buildah inspect --type image "$BASE_IMAGE" >/dev/null 2>&1; then
  echo "== base image: debootstrap --variant=minbase bookworm ($MIRROR)"
  debootstrap --variant=minbase bookworm "$WORK/rootfs" "$MIRROR" >"$WORK/debootstrap.log" 2>&1 ||
    { tail -20 "$WORK/debootstrap.log"; exit 1; }
  # apt in the image: the same suites as the host, no caches in the base.
  printf 'deb %s bookworm main\ndeb %s bookworm-updates main\ndeb http://deb.debian.org/debian-security bookworm-security main\n' \
    "$MIRROR" "$MIRROR" >"$WORK/rootfs/etc/apt/sources.list"
  # Slim like debian:12-slim: no docs, man pages or translations, now or in
  # packages installed later (dpkg path excludes).
  mkdir -p "$WORK/rootfs/etc/dpkg/dpkg.cfg.d"
  printf '%s\n' 'path-exclude /usr/share/doc/*' 'path-include /usr/share/doc/*/copyright' \
    'path-exclude /usr/share/man/*' 'path-exclude /usr/share/info/*' \
    'path-exclude /usr/share/locale/*' 'path-exclude /usr/share/lintian/*' \
    >"$WORK/rootfs/etc/dpkg/dpkg.cfg.d/covplan-slim"
  find "$WORK/rootfs/usr/share/doc" -type f ! -name copyright -delete
  rm -rf "$WORK/rootfs/usr/share/man/"* "$WORK/rootfs/usr/share/info/"* "$WORK/rootfs/usr/share/locale/"* \
    "$WORK/rootfs/var/cache/apt/"*.bin "$WORK/rootfs/var/cache/apt/archives/"*.deb \
    "$WORK/rootfs/var/lib/apt/lists/"* "$WORK/rootfs/var/log/"*.log
  base=$(buildah from scratch)
  buildah copy "$base" "$WORK/rootfs" / >/dev/null
  buildah config --env PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    --cmd /bin/bash "$base"
  buildah commit --quiet "$base" "$BASE_IMAGE" >/dev/null
  buildah rm "$base" >/dev/null
  rm -rf "$WORK/rootfs"
fi
echo "== base: $BASE_IMAGE ($(buildah images --format '{{.Size}}' "$BASE_IMAGE" | head -1))"

echo "== buildah bud --isolation chroot (log $WORK/bud.log)"
start=$(date +%s)
buildah bud --isolation chroot --format docker --layers \
  --build-arg BASE="$BASE_IMAGE" --build-arg RUNTIME_BASE="$BASE_IMAGE" \
  -t "$IMAGE" . >"$WORK/bud.log" 2>&1 || { tail -40 "$WORK/bud.log"; cp "$WORK/bud.log" /tmp/covplan-bud.log; exit 1; }
echo "built in $(( $(date +%s) - start )) s"

CTR=$(buildah from "$IMAGE")
MNT=$(buildah mount "$CTR")
user=$(buildah inspect --format '{{.OCIv1.Config.User}}' "$IMAGE")
# The server from the image, its default user, host network.
buildah copy --chown 10001:10001 "$CTR" maps/small_rooms.yaml maps/small_rooms.png /data/ >/dev/null
buildah run --isolation chroot --network host "$CTR" -- /bin/sh -c \
  "/usr/local/bin/covplan-server --address=127.0.0.1 --port=$PORT --metrics_port=$METRICS_PORT \
     --store_dir=/data/maps --drain_notice_s=0 & echo \$! > /data/server.pid; wait" \
  >"$WORK/server.log" 2>&1 &
for _ in $(seq 1 100); do
  [ -s "$MNT/data/server.pid" ] && SERVER_PID=$(cat "$MNT/data/server.pid") && break
  sleep 0.1
done
[ -n "$SERVER_PID" ] || { echo "server did not start"; cat "$WORK/server.log"; exit 1; }
run() { buildah run --isolation chroot --network host "$CTR" -- "$@"; }
healthy=""
for _ in $(seq 1 50); do
  if health=$(run /usr/local/bin/covplan health --server "127.0.0.1:$PORT" --timeout-ms 500 2>/dev/null); then
    healthy=$health; break
  fi
  sleep 0.2
done
[ "$healthy" = SERVING ] || { echo "health: '${health:-}'"; cat "$WORK/server.log"; exit 1; }
echo "== health (the image's HEALTHCHECK command): $healthy"
server_user=$(stat -c %u "/proc/$SERVER_PID")
run /usr/local/bin/covplan plan --map /data/small_rooms.yaml --server "127.0.0.1:$PORT" \
  --out /data/plan.json | tee "$WORK/plan.txt"
/usr/bin/python3 - "$MNT/data/plan.json" <<'PY'
import json, sys
plan = json.load(open(sys.argv[1]))
stats = plan["stats"]
assert plan["map_id"] and len(plan["map_id"]) == 64, "no map id"
assert len(plan["path"]) > 10, "path too short"
assert stats["num_ranks"] > 0, "no ranks"
assert stats["covered_free_area_ratio"] > 0.8, stats["covered_free_area_ratio"]
print("reply checked: %d ranks, %d waypoints, coverage %.3f" %
      (stats["num_ranks"], len(plan["path"]), stats["covered_free_area_ratio"]))
PY
[ "$server_user" = 10001 ] || { echo "server runs as uid $server_user, not 10001"; exit 1; }
echo "== image $IMAGE"
echo "size:        $(buildah images --format '{{.Size}}' "$IMAGE" | head -1)"
echo "user:        $user (server process uid $server_user)"
echo "healthcheck: $(buildah inspect --format '{{.Docker.Config.Healthcheck.Test}}' "$IMAGE")"
echo "binaries:    $(ls "$MNT/usr/local/bin" | tr '\n' ' ')"
echo "PASSED: container_test"
