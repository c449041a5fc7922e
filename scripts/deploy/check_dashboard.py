#!/usr/bin/python3
"""Checks the Grafana dashboard against what covplan-server exports.

    /usr/bin/python3 scripts/deploy/check_dashboard.py [DASHBOARD] [--rules RULES] [--source DIR]
        [--prometheus http://127.0.0.1:56190]

Structure: a JSON object with a uid, a title, panels each with a unique id,
a title, a gridPos and at least one target with a refId and an expr.
Metrics: every metric name in every expr is one the server exports (the
names registered in server/*.cc, with _bucket/_sum/_count for histograms),
a recording rule defined in the rules file, or Prometheus' own `up`.
Also the panels cover the required topics (latency, throughput, deadline
misses, cache hit rate, queue depth, memory). With --prometheus (a live
one, e.g. scripts/deploy/cluster.sh's), every query is also run there and must
return data. Exits 1 naming each problem.
"""

import argparse
import json
import os
import re
import sys
import urllib.parse
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# PromQL words that look like identifiers but are not metric names.
PROMQL_WORDS = {
    "sum", "avg", "min", "max", "count", "rate", "irate", "increase", "by", "without",
    "histogram_quantile", "on", "ignoring", "group_left", "group_right", "and", "or",
    "unless", "offset", "bool", "topk", "bottomk", "quantile", "stddev", "abs", "round",
    "clamp_min", "clamp_max", "delta", "deriv", "time", "vector", "scalar", "le",
    "avg_over_time", "max_over_time", "min_over_time", "label_replace", "inf", "nan",
}
TOPICS = {
    "latency": "latency", "throughput": "throughput", "deadline": "deadline misses",
    "hit ratio": "cache hit rate", "queue": "queue depth", "memory": "memory",
}


def exported_metrics(source):
    names = set()
    for sub in ("server",):
        d = os.path.join(source, sub)
        for f in sorted(os.listdir(d)):
            if not f.endswith(".cc"):
                continue
            text = open(os.path.join(d, f)).read()
            for m in re.finditer(r'"(covplan_[a-z0-9_]+)"', text):
                names.add(m.group(1))
            # Histograms registered with BuildHistogram().Name("x").
            for m in re.finditer(r'BuildHistogram\(\)\s*\.Name\("(covplan_[a-z0-9_]+)"\)', text):
                for suffix in ("_bucket", "_sum", "_count"):
                    names.add(m.group(1) + suffix)
    return names


def recording_rules(path):
    return set(re.findall(r"^\s*-?\s*record:\s*([A-Za-z_:][A-Za-z0-9_:]*)", open(path).read(), re.M))


def metric_names(expr):
    # Drop label matchers {...}, strings, durations [..] and by/without (..).
    e = re.sub(r'"[^"]*"', '""', expr)
    e = re.sub(r"\{[^}]*\}", "", e)
    e = re.sub(r"\[[^\]]*\]", "", e)
    e = re.sub(r"\b(by|without|on|ignoring)\s*\([^)]*\)", "", e)
    out = []
    for m in re.finditer(r"[A-Za-z_:][A-Za-z0-9_:]*", e):
        word = m.group(0)
        rest = e[m.end():].lstrip()
        if word in PROMQL_WORDS or rest.startswith("("):
            continue
        out.append(word)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dashboard", nargs="?", default=os.path.join(ROOT, "deploy/grafana/covplan-dashboard.json"))
    ap.add_argument("--rules", default=os.path.join(ROOT, "deploy/prometheus/covplan-rules.yml"))
    ap.add_argument("--source", default=ROOT)
    ap.add_argument("--prometheus", help="base URL of a live Prometheus to run every query on")
    args = ap.parse_args()
    problems = []
    try:
        dash = json.load(open(args.dashboard))
    except (OSError, ValueError) as e:
        print("check_dashboard: %s: %s" % (args.dashboard, e))
        return 1
    known = exported_metrics(args.source) | recording_rules(args.rules) | {"up"}
    for key in ("uid", "title", "panels"):
        if key not in dash:
            problems.append("dashboard has no %r" % key)
    ids = set()
    titles = []
    for i, p in enumerate(dash.get("panels", [])):
        where = "panel %d (%s)" % (i, p.get("title", "?"))
        for key in ("id", "title", "gridPos", "targets", "type"):
            if key not in p:
                problems.append("%s: no %r" % (where, key))
        if p.get("id") in ids:
            problems.append("%s: duplicate id %s" % (where, p.get("id")))
        ids.add(p.get("id"))
        titles.append(p.get("title", "").lower())
        if not p.get("targets"):
            problems.append("%s: no targets" % where)
        for t in p.get("targets", []):
            expr = t.get("expr", "")
            if not expr or "refId" not in t:
                problems.append("%s: target without refId or expr" % where)
            names = metric_names(expr)
            if not names:
                problems.append("%s: %r names no metric" % (where, expr))
            for n in names:
                if n not in known:
                    problems.append("%s: %r is not exported by the server nor a recording rule" % (where, n))
            if args.prometheus and expr:
                url = args.prometheus.rstrip("/") + "/api/v1/query?" + urllib.parse.urlencode({"query": expr})
                try:
                    reply = json.load(urllib.request.urlopen(url, timeout=10))
                except (OSError, ValueError) as e:
                    problems.append("%s: %r: query failed: %s" % (where, expr, e))
                    continue
                if reply.get("status") != "success" or not reply["data"]["result"]:
                    problems.append("%s: %r returns no data on %s" % (where, expr, args.prometheus))
    for word, topic in TOPICS.items():
        if not any(word in t for t in titles):
            problems.append("no panel for %s (a title containing %r)" % (topic, word))
    for p in problems:
        print("check_dashboard: " + p)
    if not problems:
        print("check_dashboard: %d panels, every query names an exported metric or a recording rule"
              % len(dash["panels"]))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
