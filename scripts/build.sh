#!/usr/bin/env bash
# Installs dependencies (Debian 12, apt-get) and builds covplan into build/.
#   scripts/build.sh [extra cmake args...]
# BUILD_DIR and BUILD_TYPE may be overridden from the environment.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
BUILD_TYPE=${BUILD_TYPE:-RelWithDebInfo}
JOBS=${JOBS:-$(nproc)}
bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" -DCOVPLAN_BUILD_SERVER=ON -DCOVPLAN_BUILD_TESTS=ON "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$JOBS"
