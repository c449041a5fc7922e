#!/usr/bin/env bash
# The whole test suite: installs dependencies, builds everything (tests,
# benchmarks, server, client) and runs every test with ctest.
#   scripts/test.sh                 # RelWithDebInfo build in build/
#   SANITIZE=1 scripts/test.sh      # only the ASan + UBSan build and suite, in build-asan/
#   FULL=1 scripts/test.sh          # what CI runs (CI=true does the same):
#     1. build/ with -Werror (COVPLAN_WERROR) and the whole suite, format check included
#     2. build-asan/ (ASan + UBSan, no benchmarks) and the whole suite again
#     3. each fuzzer for FUZZ_SECONDS (default 60) from fuzz/corpus (scripts/check/fuzz.sh)
# Each phase prints its wall time. Needs nothing from ../shared: every fixture is generated or
# shipped here.
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
if [ "${CI:-}" = true ] || [ "${FULL:-0}" = 1 ]; then full=1; fi
# The test-only packages: Debian's Chromium, its driver and Selenium for the console's
# browser test (tests/console; it skips without them outside CI); pip, venv, the gRPC and protobuf
# runtime, numpy and pytest for the Python client's tests (tests/python). build.sh installs the rest.
bash scripts/install-deps.sh --only chromium chromium-driver python3-selenium python3-venv python3-pip \
  python3-grpcio python3-protobuf python3-numpy python3-pytest python3-pyflakes python3-shapely \
  python3-pyproj

# suite DIR [cmake args...]: builds into DIR and runs every test there.
suite() {
  local dir=$1
  shift
  BUILD_DIR=$dir bash scripts/build.sh "$@"
  ctest --test-dir "$dir" --output-on-failure -j"${JOBS:-$(nproc)}" --timeout 600
}

# phase NAME COMMAND...: runs one phase and prints how long it took.
phase() {
  local name=$1 start=$SECONDS
  shift
  echo "test.sh: phase $name"
  "$@"
  echo "test.sh: phase $name passed in $((SECONDS - start)) s"
}

# asan DIR: the ASan + UBSan build (-Werror stays off: the sanitizers change what gcc warns of).
asan() {
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1} \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    suite "$1" -DCOVPLAN_SANITIZE=address,undefined \
    -DCOVPLAN_BUILD_BENCHMARKS=OFF -DCOVPLAN_WERROR=OFF
}

if [ "${SANITIZE:-0}" = 1 ] && [ "$full" = 0 ]; then
  phase sanitize asan "${BUILD_DIR:-build-asan}"
  exit 0
fi
werror=OFF
[ "$full" = 1 ] && werror=ON
phase suite suite "${BUILD_DIR:-build}" -DCOVPLAN_WERROR=$werror
if [ "$full" = 1 ]; then
  phase sanitize asan build-asan
  phase fuzz bash scripts/check/fuzz.sh "${FUZZ_SECONDS:-60}"
fi
