#!/usr/bin/env bash
# Installs every Debian 12 package covplan needs to build, test and run.
# Idempotent: skips apt entirely when everything is already present.
#   scripts/install-deps.sh                      # the build's packages
#   scripts/install-deps.sh haproxy prometheus   # those and these
#   scripts/install-deps.sh --only buildah       # only these (scripts/deploy/*)
set -euo pipefail
ONLY=0
if [ "${1:-}" = --only ]; then
  ONLY=1
  shift
fi

PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev libglpk-dev glpk-utils libeigen3-dev libboost-graph-dev
  libyaml-cpp-dev libpng-dev libgtest-dev libgmock-dev libbenchmark-dev
  prometheus-cpp-dev libcivetweb-dev libpq-dev libproj-dev curl python3
  openssl  # test certificates for server_tls_test
)
# Tools of the checks CI runs (scripts/test.sh with CI=true): clang + the libFuzzer runtime for
# the fuzz run, clang-format 14 for the format test. Required in CI, optional elsewhere (the
# format test skips and scripts/check/fuzz.sh cannot run without them).
OPTIONAL=(clang libclang-rt-14-dev clang-format)
if [ "${CI:-}" = true ]; then
  PKGS+=("${OPTIONAL[@]}")
  OPTIONAL=()
fi
# COVPLAN_MINIMAL=1 (the container's build stage): only what the build needs.
[ "${COVPLAN_MINIMAL:-0}" = 1 ] && OPTIONAL=()
# Optional tools for the deploy checks (tests deploy.*: promtool, haproxy -c,
# the manifest validator's npm packages; each check skips without them).
# Only in CI (CI=true) or when asked (COVPLAN_DEPLOY_TOOLS=1): the Debian
# prometheus package starts a daemon where systemd runs, which the README's
# first command must not do.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
DEPLOY_TOOLS=()
if [ "$ONLY" = 1 ]; then
  PKGS=("$@")
  OPTIONAL=()
else
  PKGS+=("$@")
fi
if [ "$ONLY" = 0 ] && { [ "${CI:-}" = true ] || [ "${COVPLAN_DEPLOY_TOOLS:-0}" = 1 ]; }; then
  DEPLOY_TOOLS=(prometheus haproxy)
  if command -v npm >/dev/null && [ ! -d "$ROOT/deploy/kubernetes/validator/node_modules" ]; then
    (cd "$ROOT/deploy/kubernetes/validator" && npm ci --no-audit --no-fund --silent) ||
      echo "install-deps: npm ci in deploy/kubernetes/validator failed; deploy.kubernetes will skip"
  fi
fi

missing=()
for p in "${PKGS[@]}" "${OPTIONAL[@]}" "${DEPLOY_TOOLS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${PKGS[@]}" >/dev/null
# Optional packages: do not fail the install if unavailable.
[ ${#OPTIONAL[@]} -eq 0 ] || $SUDO apt-get install -y -qq --no-install-recommends "${OPTIONAL[@]}" >/dev/null || \
  echo "install-deps: optional packages (${OPTIONAL[*]}) not installed; no fuzzing, format test skips"
[ ${#DEPLOY_TOOLS[@]} -eq 0 ] || $SUDO apt-get install -y -qq --no-install-recommends "${DEPLOY_TOOLS[@]}" >/dev/null || \
  echo "install-deps: ${DEPLOY_TOOLS[*]} not installed; the deploy.rules and deploy.router checks skip"
echo "install-deps: done"
