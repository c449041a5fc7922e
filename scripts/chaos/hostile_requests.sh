#!/usr/bin/env bash
# The hostile-request generator against a real covplan-server: COUNT seeded
# random requests to every RPC (garbage and extreme images and YAML, ids of
# every length, page tokens, NaN/inf robot models and zones); fails if any
# reply is INTERNAL / UNKNOWN / UNAVAILABLE or carries a message over 1.1 KB,
# or if the server cannot plan or drain afterwards. Prints the outcomes.
#   scripts/chaos/hostile_requests.sh [COUNT] [SEED]     (BIN default build-h/bin)
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=${BIN:-build-h/bin}
COVPLAN_HOSTILE_COUNT=${1:-2000} COVPLAN_HOSTILE_SEED=${2:-1} "$BIN"/hostile_requests_test \
  | grep -v '^ts='
