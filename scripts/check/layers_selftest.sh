#!/usr/bin/env bash
# The layer check's own test: on a small temporary tree it must pass while
# every include goes down, and fail, naming the file, line and include, once
# a planner header includes the assembly above it.
#
#   bash scripts/check/layers_selftest.sh   # exit 0: the checker works
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
tree="$(mktemp -d)"
trap 'rm -rf "$tree"' EXIT
mkdir -p "$tree/planner/engine" "$tree/planner/oarp" "$tree/planner/assembly"
printf '#include "absl/status/status.h"\n' > "$tree/planner/engine/engine.h"
printf '#include "planner/engine/engine.h"\n' > "$tree/planner/assembly/builtin_planners.h"
printf '// OARP\n#include "planner/engine/engine.h"\n' > "$tree/planner/oarp/oarp_planner.h"

fail() { echo "layers_selftest: $*" >&2; exit 1; }

if ! out="$(bash "$here/layers.sh" "$tree" 2>&1)"; then
  fail "the checker refused a tree whose includes all go down: $out"
fi

printf '#include "planner/assembly/builtin_planners.h"\n' >> "$tree/planner/oarp/oarp_planner.h"
rc=0
out="$(bash "$here/layers.sh" "$tree" 2>&1)" || rc=$?
[[ $rc -eq 1 ]] || fail "expected exit 1 for planner/oarp including planner/assembly, got $rc: $out"
expected='planner/oarp/oarp_planner.h:3: planner/oarp includes planner/assembly ("planner/assembly/builtin_planners.h")'
[[ "$out" == *"$expected"* ]] || fail "the message does not name the include; got: $out"
echo "layers_selftest: the checker passes a clean tree and names the upward include"
