#!/usr/bin/env bash
# The whole test suite: installs dependencies, builds everything (tests,
# benchmarks, server, client) and runs every test with ctest.
#   scripts/test.sh                 # RelWithDebInfo build in build/
#   SANITIZE=1 scripts/test.sh      # ASan + UBSan build in build-asan/
# Needs nothing from ../shared: every fixture is generated or shipped here.
set -euo pipefail
cd "$(dirname "$0")/.."
extra=()
if [ "${SANITIZE:-0}" = "1" ]; then
  export BUILD_DIR=${BUILD_DIR:-build-asan}
  extra+=(-DCOVPLAN_SANITIZE=address,undefined -DCOVPLAN_BUILD_BENCHMARKS=OFF)
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
fi
BUILD_DIR=${BUILD_DIR:-build}
export BUILD_DIR
bash scripts/build.sh "${extra[@]}"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"${JOBS:-$(nproc)}" --timeout 600
