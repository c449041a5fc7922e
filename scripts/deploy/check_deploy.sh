#!/usr/bin/env bash
# Offline checks of the deployment files, one per argument (the ctest tests
# deploy.* call them). Exit 0 pass, 1 fail, 77 skipped because a tool is
# not installed (the reason is printed).
#   scripts/deploy/check_deploy.sh rules        # promtool check rules + test rules
#   scripts/deploy/check_deploy.sh dashboard    # Grafana JSON vs exported metrics
#   scripts/deploy/check_deploy.sh kubernetes   # kubectl kustomize every overlay, validate every object
#   scripts/deploy/check_deploy.sh router       # haproxy -c on both router configs
# Tools: promtool (Debian: prometheus), haproxy, kubectl (not in Debian 12:
# its built-in kustomize renders), node + deploy/kubernetes/validator's npm
# packages (npm ci --prefix deploy/kubernetes/validator).
set -uo pipefail
cd "$(dirname "$0")/../.."
skip() { echo "SKIPPED: $*"; exit 77; }

case "${1:-}" in
  rules)
    command -v promtool >/dev/null || skip "promtool not installed (apt-get install prometheus)"
    promtool check rules deploy/prometheus/covplan-rules.yml || exit 1
    (cd deploy/prometheus && promtool test rules covplan-rules.test.yml) || exit 1
    ;;
  dashboard)
    /usr/bin/python3 scripts/deploy/check_dashboard.py || exit 1
    # The checker must catch a metric the server does not export.
    tmp=$(mktemp)
    sed 's/covplan_worker_queue_depth/covplan_worker_queue_dpth/' deploy/grafana/covplan-dashboard.json >"$tmp"
    if /usr/bin/python3 scripts/deploy/check_dashboard.py "$tmp" >/dev/null; then
      rm -f "$tmp"; echo "checker accepted an unknown metric"; exit 1
    fi
    rm -f "$tmp"
    ;;
  kubernetes)
    command -v kubectl >/dev/null || skip "kubectl (for kustomize rendering) not installed; Debian 12 ships neither kubectl nor kustomize"
    command -v node >/dev/null || skip "node not installed (apt-get install nodejs npm)"
    [ -d deploy/kubernetes/validator/node_modules/kubernetes-models ] ||
      skip "validator packages missing: npm ci --prefix deploy/kubernetes/validator"
    rc=0
    for dir in deploy/kubernetes/base deploy/kubernetes/overlays/*/; do
      printf '%s: ' "${dir%/}"
      out=$(kubectl kustomize "$dir" 2>&1) || { echo "kustomize failed: $out"; rc=1; continue; }
      printf '%s\n' "$out" | node deploy/kubernetes/validator/validate.mjs || rc=1
    done
    # The validator must reject what the API server would: a wrong type.
    if printf 'apiVersion: apps/v1\nkind: Deployment\nmetadata: {name: x}\nspec: {replicas: "3", selector: {}, template: {}}\n' |
        node deploy/kubernetes/validator/validate.mjs >/dev/null; then
      echo "validator accepted replicas: \"3\""; rc=1
    fi
    [ "$rc" = 0 ] || exit 1
    ;;
  router)
    command -v haproxy >/dev/null || skip "haproxy not installed (apt-get install haproxy)"
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    servers=$(printf '    server r%d 127.0.0.1:%d proto h2 check\n' 1 56101 2 56102 3 56103)
    /usr/bin/python3 - "$tmp" "$servers" <<'PY' || exit 1
import sys
tmp, servers = sys.argv[1], sys.argv[2] + "\n"
s = open("deploy/cluster/haproxy.cfg.in").read()
for k, v in {"@DIR@": tmp, "@ROUTER_PORT@": "56100", "@RR_PORT@": "56105",
             "@STATS_PORT@": "56106", "@SERVERS@\n": servers}.items():
    s = s.replace(k, v)
open(tmp + "/haproxy.cfg", "w").write(s)
PY
    grep -q "balance hdr(x-covplan-map-id)" "$tmp/haproxy.cfg" || { echo "no header hashing"; exit 1; }
    haproxy -c -f "$tmp/haproxy.cfg" || exit 1
    haproxy -c -f deploy/kubernetes/base/haproxy.cfg || exit 1
    ;;
  *) sed -n '2,12p' "$0"; exit 2 ;;
esac
echo "PASSED: $1"
