#!/usr/bin/python3
"""Writes large deterministic maps for the transition-scaling benchmarks.

    /usr/bin/python3 scripts/maps/gen_warehouse.py warehouse OUT_DIR [WIDTH_M HEIGHT_M]
    /usr/bin/python3 scripts/maps/gen_warehouse.py lawn OUT_DIR [SIDE_M]

warehouse: a walled hall (default 280 m x 180 m at 0.1 m per pixel) of
shelf rows 1.2 m deep with 2.4 m aisles between them, cut into blocks by
4 m cross aisles every 14 m, with seeded pillars, pallets in the cross
aisles and checkout-style islands near the front. At a 0.3 m tool the
matching partition needs about 5,700 ranks (docs/benchmarks.md section 13).
lawn: an open walled square (default 50 m at 0.05 m per pixel) with a few
seeded trees; at a 0.05 m tool the grid has about 10^6 cells and ~1,000 ranks.

Writes OUT_DIR/<name>.pgm and OUT_DIR/<name>.yaml (ROS map_server format).
Deterministic (fixed seeds), stdlib only.
"""
import random
import sys


class Image:
    def __init__(self, width, height):
        self.width, self.height = width, height
        self.px = bytearray([254]) * (width * height)

    def box(self, x0, y0, x1, y1):
        x0, x1 = max(0, int(x0)), min(self.width, int(x1))
        y0, y1 = max(0, int(y0)), min(self.height, int(y1))
        if x1 <= x0:
            return
        for y in range(y0, y1):
            self.px[y * self.width + x0: y * self.width + x1] = bytes(x1 - x0)

    def walls(self, thickness):
        w, h = self.width, self.height
        self.box(0, 0, w, thickness)
        self.box(0, h - thickness, w, h)
        self.box(0, 0, thickness, h)
        self.box(w - thickness, 0, w, h)

    def write(self, out, name, resolution):
        with open(f"{out}/{name}.pgm", "wb") as f:
            f.write(b"P5\n%d %d\n255\n" % (self.width, self.height))
            f.write(self.px)
        with open(f"{out}/{name}.yaml", "w") as f:
            f.write(f"image: {name}.pgm\nresolution: {resolution}\norigin: [0, 0, 0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")


def warehouse(out, width_m, height_m):
    res = 0.1
    m = lambda metres: int(round(metres / res))  # noqa: E731
    img = Image(m(width_m), m(height_m))
    rng = random.Random(12)
    img.walls(m(0.3))
    front = m(12.0)          # open front zone (loading bays, checkouts)
    shelf, aisle = m(1.2), m(2.4)
    block, cross = m(14.0), m(4.0)
    margin = m(3.0)
    # Shelf rows run along x, blocks separated by cross aisles.
    y = front
    while y + shelf < img.height - margin:
        x = margin
        while x + m(4.0) < img.width - margin:
            x1 = min(x + block, img.width - margin)
            img.box(x, y, x1, y + shelf)
            x = x1 + cross
        y += shelf + aisle
    # Pillars on a 10 m grid (0.4 m square), some standing in aisles.
    for py in range(m(6.0), img.height - margin, m(10.0)):
        for px in range(m(5.0), img.width - margin, m(10.0)):
            img.box(px, py, px + m(0.4), py + m(0.4))
    # Pallets parked in the cross aisles.
    for _ in range(int(width_m * height_m / 60)):
        x = rng.randrange(margin, img.width - margin)
        y = rng.randrange(front, img.height - margin)
        img.box(x, y, x + m(rng.uniform(0.6, 1.2)), y + m(rng.uniform(0.6, 1.2)))
    # Checkout islands and displays in the front zone.
    for cx in range(m(6.0), img.width - m(6.0), m(6.0)):
        img.box(cx, m(3.0), cx + m(1.0), m(3.0) + m(rng.uniform(1.5, 3.0)))
        img.box(cx + m(2.5), m(7.5), cx + m(3.3), m(7.5) + m(0.8))
    img.write(out, "warehouse", res)


def lawn(out, side_m):
    res = 0.05
    n = int(round(side_m / res))
    img = Image(n, n)
    rng = random.Random(7)
    img.walls(2)
    for _ in range(6):  # trees, 0.6-1.2 m trunks
        x, y = rng.randrange(n // 10, 9 * n // 10), rng.randrange(n // 10, 9 * n // 10)
        d = int(rng.uniform(0.6, 1.2) / res)
        img.box(x, y, x + d, y + d)
    img.write(out, "lawn", res)


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in ("warehouse", "lawn"):
        sys.exit(__doc__)
    kind, out = sys.argv[1], sys.argv[2]
    if kind == "warehouse":
        w = float(sys.argv[3]) if len(sys.argv) > 3 else 280.0
        h = float(sys.argv[4]) if len(sys.argv) > 4 else 180.0
        warehouse(out, w, h)
    else:
        lawn(out, float(sys.argv[3]) if len(sys.argv) > 3 else 50.0)


if __name__ == "__main__":
    main()
