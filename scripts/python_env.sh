#!/usr/bin/env bash
# A venv with the covplan Python client installed (clients/python), on Debian's python3-grpcio,
# python3-protobuf and python3-numpy (system site packages: PyPI is not needed). The venv's
# pip.conf turns build isolation off (an isolated build would fetch setuptools from PyPI), so
# a plain `pip install ./clients/python` works in it too. Prints the venv's directory.
#   scripts/python_env.sh [VENV_DIR]          # default ./.venv
#   VENV=$(bash scripts/python_env.sh) && "$VENV/bin/python" clients/python/examples/plan_map.py
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${1:-.venv}
bash scripts/install-deps.sh --only python3-venv python3-pip python3-grpcio python3-protobuf \
  python3-numpy python3-pytest python3-pyproj python3-shapely protobuf-compiler \
  protobuf-compiler-grpc >&2
if [ ! -x "$VENV/bin/python" ]; then
  /usr/bin/python3 -m venv --system-site-packages "$VENV" >&2
fi
# pip reads a "no-" option from a config file inverted: "no-build-isolation = false" turns
# build isolation OFF. no-index: only Debian's packages and local directories are installable
# here (PyPI is not reachable); drop it from the venv's pip.conf where PyPI is.
printf '[global]\nno-build-isolation = false\nno-index = true\ndisable-pip-version-check = true\n' \
  > "$VENV/pip.conf"
# A build directory of its own, so concurrent installs (two test trees) never share one.
BUILD_DIR=$(mktemp -d -t covplan-pybuild.XXXXXX)
trap 'rm -rf "$BUILD_DIR"' EXIT
cp -r clients/python/. "$BUILD_DIR/"
rm -rf "$BUILD_DIR/build" "$BUILD_DIR"/*.egg-info
COVPLAN_PROTO_DIR="$PWD/proto" "$VENV/bin/pip" install --quiet --force-reinstall --no-deps \
  "$BUILD_DIR" >&2
cd "$VENV" && pwd
