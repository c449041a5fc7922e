#!/usr/bin/python3
"""Writes N distinct site maps for load runs (deterministic, stdlib only).

    /usr/bin/python3 scripts/maps/gen_load_maps.py --out /tmp/covplan-load-maps --count 24 [--seed 1]

Each map is a walled rectangle of 12-20 m x 8-14 m at 0.05 m/px (ROS
map_server PGM + YAML) with 3-8 random rectangular obstacles, so every map
has its own map id, grid, rank partition and transition table. The maps are
generated, never copied from anywhere; they are not shipped in maps/.
"""

import argparse
import os
import random

FREE, OCCUPIED = 254, 0
RES = 0.05


def draw(rng):
    w = int(rng.uniform(12, 20) / RES)
    h = int(rng.uniform(8, 14) / RES)
    px = [bytearray([FREE]) * w for _ in range(h)]

    def rect(x0, y0, x1, y1):
        x0, x1 = max(0, x0), min(w, x1)
        for y in range(max(0, y0), min(h, y1)):
            px[y][x0:x1] = bytes([OCCUPIED]) * max(0, x1 - x0)

    wall = 4
    rect(0, 0, w, wall)
    rect(0, h - wall, w, h)
    rect(0, 0, wall, h)
    rect(w - wall, 0, w, h)
    for _ in range(rng.randint(3, 8)):
        bw, bh = rng.randint(10, 60), rng.randint(10, 60)
        x, y = rng.randint(wall, w - wall - bw), rng.randint(wall, h - wall - bh)
        rect(x, y, x + bw, y + bh)
    return w, h, px


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--count", type=int, default=24)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rng = random.Random(args.seed)
    for k in range(args.count):
        w, h, px = draw(rng)
        name = "site_%03d" % k
        with open(os.path.join(args.out, name + ".pgm"), "wb") as f:
            f.write(b"P5\n%d %d\n255\n" % (w, h))
            for row in px:
                f.write(row)
        with open(os.path.join(args.out, name + ".yaml"), "w") as f:
            f.write("image: %s.pgm\nresolution: %.2f\norigin: [0, 0, 0.0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n" % (name, RES))


if __name__ == "__main__":
    main()
