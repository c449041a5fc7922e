#!/bin/sh
# Builds the map reader and GeoJSON fuzzers with clang (ASan + UBSan +
# libFuzzer) in their own build directory and runs each for N seconds
# (default 60), the map reader first.
#
#   scripts/fuzz.sh [SECONDS] [extra libFuzzer flags...]
#
# New inputs go to fuzz/corpus-run/ (GeoJSON: fuzz/corpus-run/geojson/; ignored
# by git); the seeds in fuzz/corpus/ are read but not modified. Crashes land in
# $build/artifacts/.
set -eu
seconds=${1:-60}
[ $# -gt 0 ] && shift
root=$(cd "$(dirname "$0")/.." && pwd)
build=${COVPLAN_FUZZ_BUILD_DIR:-$root/build-fuzz}
jobs=${JOBS:-2}

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOVPLAN_FUZZ=ON \
  -DCOVPLAN_BUILD_SERVER=OFF -DCOVPLAN_BUILD_TESTS=OFF -DCOVPLAN_BUILD_BENCHMARKS=OFF
ninja -C "$build" -j "$jobs" map_reader_fuzzer geojson_fuzzer

mkdir -p "$root/fuzz/corpus-run" "$root/fuzz/corpus-run/geojson" "$build/artifacts"
"$build/bin/map_reader_fuzzer" "$root/fuzz/corpus-run" "$root/fuzz/corpus" \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
  -artifact_prefix="$build/artifacts/" "$@"
exec "$build/bin/geojson_fuzzer" "$root/fuzz/corpus-run/geojson" "$root/fuzz/corpus/geojson" \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
  -artifact_prefix="$build/artifacts/geojson-" "$@"
