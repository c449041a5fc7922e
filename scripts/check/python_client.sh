#!/usr/bin/env bash
# The Python client's tests (ctest: python.client): installs clients/python into a venv with
# pip, checks the package and tests with pyflakes (when installed), then runs pytest against
# the given covplan-server binary.
#   scripts/check/python_client.sh SERVER_BINARY [VENV_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
SERVER=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
VENV=$(bash scripts/python_env.sh "${2:-build/python-venv}")
if /usr/bin/python3 -m pyflakes --version >/dev/null 2>&1; then
  /usr/bin/python3 -m pyflakes clients/python
fi
cd clients/python/tests
COVPLAN_SERVER=$SERVER exec "$VENV/bin/python" -m pytest -q -p no:cacheprovider .
