#!/usr/bin/env bash
# Fails when a tracked C++ file (.cc, .h) drifts from .clang-format, naming each such file.
#   scripts/check/format.sh            # check the tree (ctest runs it as test format)
#   scripts/check/format.sh --fix      # rewrite the drifting files in place
# The style is clang-format 14's (Debian 12's clang-format); another version may format
# differently, so clang-format-14 is preferred when both are installed. Without clang-format the
# check skips (exit 77, ctest's skip code), except in CI (CI=true), where it fails.
set -euo pipefail
cd "$(dirname "$0")/../.."

fmt=""
for candidate in clang-format-14 clang-format; do
  if command -v "$candidate" >/dev/null; then
    fmt=$candidate
    break
  fi
done
if [ -z "$fmt" ]; then
  if [ "${CI:-}" = true ]; then
    echo "format: clang-format not found (scripts/install-deps.sh installs it in CI)" >&2
    exit 1
  fi
  echo "format: SKIPPED: clang-format not installed (apt-get install clang-format)"
  exit 77
fi

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cc' '*.h')
else  # a source tree without git (e.g. an unpacked archive)
  mapfile -t files < <(find . -path './build*' -prune -o -path ./node_modules -prune -o \
    -type f \( -name '*.cc' -o -name '*.h' \) -print | sed 's|^\./||' | sort)
fi

if [ "${1:-}" = --fix ]; then
  "$fmt" -i -- "${files[@]}"
  echo "format: ${#files[@]} files formatted with $("$fmt" --version)"
  exit 0
fi

# One clang-format for all files; each violation is reported as FILE:LINE:COL: error: ...
rc=0
out=$("$fmt" --dry-run -Werror -- "${files[@]}" 2>&1) || rc=$?
mapfile -t drift < <(printf '%s\n' "$out" |
  sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: .*clang-format-violations.*/\1/p' | uniq)
if [ ${#drift[@]} -gt 0 ]; then
  echo "format: ${#drift[@]} of ${#files[@]} files differ from .clang-format ($("$fmt" --version)):"
  printf '  %s\n' "${drift[@]}"
  echo "format: fix with: bash scripts/check/format.sh --fix (or clang-format -i FILE)"
  exit 1
fi
if [ "$rc" -ne 0 ]; then
  printf 'format: %s failed:\n%s\n' "$fmt" "$out" >&2
  exit 1
fi
echo "format: ${#files[@]} files match .clang-format"
