#!/usr/bin/python3
"""Writes N distinct occupancy maps for server benchmarks and robustness runs.

    /usr/bin/python3 scripts/maps/gen_bench_maps.py OUT_DIR N [WIDTH HEIGHT]

Each map k is a walled floor (default 600 x 400 px at 0.05 m: 30 m x 20 m)
with 60 pieces of seeded random furniture: mK.pgm + mK.yaml (ROS map_server
format). Deterministic, stdlib only.
"""
import random
import sys


def main():
    out, n = sys.argv[1], int(sys.argv[2])
    width = int(sys.argv[3]) if len(sys.argv) > 3 else 600
    height = int(sys.argv[4]) if len(sys.argv) > 4 else 400
    for k in range(n):
        rng = random.Random(k)
        px = bytearray([254]) * (width * height)

        def box(x0, y0, x1, y1):
            x0, x1 = max(0, x0), min(width, x1)
            for y in range(max(0, y0), min(height, y1)):
                px[y * width + x0: y * width + x1] = bytes(x1 - x0)

        box(0, 0, width, 6)
        box(0, height - 6, width, height)
        box(0, 0, 6, height)
        box(width - 6, 0, width, height)
        for _ in range(60):
            x, y = rng.randrange(20, width - 60), rng.randrange(20, height - 60)
            box(x, y, x + rng.randrange(8, 40), y + rng.randrange(8, 40))
        with open(f"{out}/m{k}.pgm", "wb") as f:
            f.write(b"P5\n%d %d\n255\n" % (width, height))
            f.write(px)
        with open(f"{out}/m{k}.yaml", "w") as f:
            f.write(f"image: m{k}.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")


if __name__ == "__main__":
    main()
