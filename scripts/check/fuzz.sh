#!/bin/sh
# Builds the fuzzers with clang (ASan + UBSan + libFuzzer) in their own build directory, only
# the fuzz targets and what they link, and runs each for N seconds (default 60) from its seeds:
#   map_reader_fuzzer    PGM/PNG and map_server YAML     fuzz/corpus/
#   geojson_fuzzer       GeoJSON polygons and geometry   fuzz/corpus/geojson/
#   plan_request_fuzzer  PlanRequest bytes -> api/ conversion   fuzz/corpus/plan_request/
#
#   scripts/check/fuzz.sh [SECONDS] [extra libFuzzer flags...]
#
# New inputs go to fuzz/corpus-run/ (ignored by git); the seeds in fuzz/corpus/ are read but
# not modified. A crash stops the run with a non-zero exit and lands in $build/artifacts/.
# Needs clang and libclang-rt-14-dev (scripts/install-deps.sh installs them).
set -eu
seconds=${1:-60}
[ $# -gt 0 ] && shift
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${COVPLAN_FUZZ_BUILD_DIR:-$root/build-fuzz}
jobs=${JOBS:-2}

# The server stays on for the generated protos the PlanRequest fuzzer needs; nothing but the
# fuzz targets (and the libraries they link) is built.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOVPLAN_FUZZ=ON \
  -DCOVPLAN_BUILD_SERVER=ON -DCOVPLAN_BUILD_TESTS=OFF -DCOVPLAN_BUILD_BENCHMARKS=OFF >/dev/null
ninja -C "$build" -j "$jobs" map_reader_fuzzer geojson_fuzzer plan_request_fuzzer

# fuzz NAME RUN_SUBDIR SEED_DIR [flags]: runs one fuzzer for $seconds from its seeds.
fuzz() {
  name=$1 run=$root/fuzz/corpus-run/$2 seeds=$3
  shift 3
  mkdir -p "$run" "$build/artifacts"
  echo "fuzz: $name for ${seconds}s"
  "$build/bin/$name" "$run" "$seeds" -max_total_time="$seconds" -max_len=65536 \
    -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$build/artifacts/$name-" \
    "$@"
}
fuzz map_reader_fuzzer map_reader "$root/fuzz/corpus" "$@"
fuzz geojson_fuzzer geojson "$root/fuzz/corpus/geojson" "$@"
fuzz plan_request_fuzzer plan_request "$root/fuzz/corpus/plan_request" "$@"
