#!/usr/bin/env bash
# The layer check: every #include "..." in planner/, api/, server/, client/,
# bench/ and fuzz/ must go to the file's own layer or to a lower one, in the
# order written down in layers.txt beside this script (which also says why
# each layer sits where it does).
#
#   bash scripts/check/layers.sh            # the repository this script is in
#   bash scripts/check/layers.sh ROOT       # another tree (the self-test's)
#   LAYERS=FILE bash scripts/check/layers.sh  # another layer order
#
# Exit 0 when every include follows the order; 1 with one line per violation
# (file:line: the two layers and the include), or a file or include in no
# layer; 2 on a usage error.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="${1:-$(cd "$here/../.." && pwd)}"
layers="${LAYERS:-$here/layers.txt}"
[[ -d "$root" ]] || { echo "layers.sh: no directory $root" >&2; exit 2; }
[[ -f "$layers" ]] || { echo "layers.sh: no layer file $layers" >&2; exit 2; }

checked=(planner api server client bench fuzz)
cd "$root"
files=()
for dir in "${checked[@]}"; do
  [[ -d "$dir" ]] || continue
  while IFS= read -r f; do files+=("$f"); done < <(find "$dir" -type f \( -name '*.h' -o -name '*.cc' \) | sort)
done
if ((${#files[@]} == 0)); then
  echo "layers.sh: no source file under $root" >&2
  exit 2
fi

awk -v layers="$layers" -v roots="${checked[*]}" '
  BEGIN {
    rank = 0
    while ((getline line < layers) > 0) {
      sub(/#.*/, "", line)
      n = split(line, names, /[ \t]+/)
      got = 0
      for (i = 1; i <= n; ++i) {
        if (names[i] == "") continue
        rank_of[names[i]] = rank
        got = 1
      }
      rank += got
    }
    split(roots, r, " ")
    for (i in r) root_dir[r[i]] = 1
    bad = 0
  }
  # The longest layer that is a path prefix of `path` ("" when none).
  function layer_of(path,    p, best) {
    best = ""
    for (p in rank_of)
      if ((index(path, p "/") == 1) && length(p) > length(best)) best = p
    return best
  }
  FNR == 1 {
    file_layer = layer_of(FILENAME)
    if (file_layer == "") {
      printf "%s: in no layer of %s\n", FILENAME, layers
      bad = 1
    }
  }
  /^[ \t]*#[ \t]*include[ \t]*"/ {
    if (file_layer == "") next
    inc = $0
    sub(/^[^"]*"/, "", inc)
    sub(/".*$/, "", inc)
    top = inc
    sub(/\/.*/, "", top)
    if (!(top in root_dir)) next  # third-party, generated or test headers
    to = layer_of(inc)
    if (to == "") {
      printf "%s:%d: includes \"%s\", which is in no layer of %s\n", FILENAME, FNR, inc, layers
      bad = 1
    } else if (to != file_layer && rank_of[to] >= rank_of[file_layer]) {
      printf "%s:%d: %s includes %s (\"%s\"): %s is %s %s in %s\n", FILENAME, FNR, file_layer, to,
             inc, to, (rank_of[to] == rank_of[file_layer] ? "a peer of" : "above"), file_layer,
             layers
      bad = 1
    }
  }
  END { exit bad }
' "${files[@]}" && { echo "layers.sh: ${#files[@]} files follow $layers"; exit 0; }
exit 1
