#!/usr/bin/python3
"""Compares the GTSP searches of `covplan gtsp` per instance and seed.

Runs `covplan gtsp FILE --time-limit L --threads T --seed S --search X` for
every instance of the given directories, every search, limit, thread count
and seed, and prints one markdown row per instance and seed: the gap, in %,
of each run to the instance's reference. The reference is the best known
value of the directory's best_known.csv when it lists the instance, else the
cheapest tour of any run recorded for the instance in the --raw file (any
search, limit, thread count or binary: the column says which). Runs are kept
in that TSV, keyed by the binary's path too, and not repeated, so a table
can be extended later; a rebuilt binary at the same path needs a new --raw.

  /usr/bin/python3 scripts/bench/gtsp_compare.py --bin build/bin/covplan \\
      --data ../shared/data/gtsp --data /tmp/gtsp-gen --only '[0-9]{3,}\\.gtsp$' \\
      --searches "lns memetic hybrid" --limits "1 5" --threads "1 2" --seeds 3
"""
import argparse
import collections
import csv
import glob
import json
import os
import re
import subprocess
import sys


def instances(dirs, only):
    out = []
    for d in dirs:
        known = {}
        path = os.path.join(d, "best_known.csv")
        if os.path.exists(path):
            known = {r["instance"].lower(): int(r["best_known"]) for r in csv.DictReader(open(path))}
        for f in sorted(glob.glob(os.path.join(d, "*.gtsp"))):
            if not re.search(only, os.path.basename(f)):
                continue
            name = os.path.basename(f)[:-5]
            size = int(re.search(r"([0-9]*)$", name).group(1) or 0)
            out.append((size, name, f, known.get(name.lower())))
    out.sort()
    return out


def load_raw(path):
    runs = {}
    if os.path.exists(path):
        for line in open(path):
            name, search, limit, threads, seed, cost, _, binary = line.rstrip("\n").split("\t")
            runs[(name, search, float(limit), int(threads), int(seed), binary)] = int(cost)
    return runs


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="the covplan binary")
    ap.add_argument("--data", action="append", required=True)
    ap.add_argument("--only", default=".")
    ap.add_argument("--searches", default="lns memetic hybrid")
    ap.add_argument("--limits", default="1 5")
    ap.add_argument("--threads", default="1 2")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--raw", default="/tmp/gtsp_compare.tsv")
    a = ap.parse_args()
    searches = a.searches.split()
    limits = [float(x) for x in a.limits.split()]
    threads = [int(x) for x in a.threads.split()]
    todo = instances(a.data, a.only)
    binary = os.path.realpath(a.bin)
    recorded = load_raw(a.raw)
    runs = {k[:5]: c for k, c in recorded.items() if k[5] == binary}
    with open(a.raw, "a") as raw:
        for _, name, path, _ in todo:
            for limit in limits:
                for t in threads:
                    for seed in range(1, a.seeds + 1):
                        for search in searches:
                            key = (name, search, limit, t, seed)
                            if key in runs:
                                continue
                            cmd = [a.bin, "gtsp", path, "--time-limit", str(limit), "--threads",
                                   str(t), "--seed", str(seed), "--search", search]
                            d = json.loads(subprocess.run(cmd, check=True, capture_output=True,
                                                          text=True).stdout)
                            runs[key] = int(d["cost"])
                            raw.write("\t".join(map(str, [*key, d["cost"], d["time_s"], binary]))
                                      + "\n")
                            raw.flush()
                            print(f"  {name} {search} {limit:g}s x{t} seed {seed}: {d['cost']}",
                                  file=sys.stderr)
    cols = [(limit, t, s) for limit in limits for t in threads for s in searches]
    print("| instance | seed | reference | " +
          " | ".join(f"{s} {t}t@{limit:g}s" for limit, t, s in cols) + " |")
    print("|---|---:|---:|" + "---:|" * len(cols))
    gaps = collections.defaultdict(list)
    worse = collections.Counter()
    for _, name, _, known in todo:
        seen = [c for k, c in list(recorded.items()) + list(runs.items()) if k[0] == name]
        ref = min([known] + seen) if known else min(seen)
        label = f"{ref}" + (" (best known)" if known and ref == known else " (best run)")
        for seed in range(1, a.seeds + 1):
            row = []
            for limit, t, s in cols:
                c = runs.get((name, s, limit, t, seed))
                if c is None:
                    row.append("-")
                    continue
                g = 100.0 * (c - ref) / ref
                gaps[(limit, t, s)].append(g)
                row.append(f"{g:.3f}")
            print(f"| {name} | {seed} | {label} | " + " | ".join(row) + " |")
        for limit in limits:
            for t in threads:
                for s in searches:
                    mean = lambda x: sum(x) / len(x)
                    mine = [runs.get((name, s, limit, t, sd)) for sd in range(1, a.seeds + 1)]
                    if None in mine:
                        continue
                    for other in searches:
                        theirs = [runs.get((name, other, limit, t, sd)) for sd in range(1, a.seeds + 1)]
                        if other != s and None not in theirs and mean(mine) > mean(theirs):
                            worse[(limit, t, s, other)] += 1
    print()
    for (limit, t, s), g in gaps.items():
        print(f"- {s}, {t} thread(s) @{limit:g}s: mean gap {sum(g) / len(g):.3f} % over {len(g)} runs, "
              f"worst {max(g):.3f} %")
    for (limit, t, s, other), n in sorted(worse.items()):
        print(f"- {t} thread(s) @{limit:g}s: {s}'s mean over the seeds above {other}'s on {n} instance(s)")


if __name__ == "__main__":
    sys.exit(main())
