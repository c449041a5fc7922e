#!/usr/bin/python3
"""Draws the sample maps shipped in maps/ (deterministic, stdlib only).

    /usr/bin/python3 scripts/maps/gen_sample_maps.py [--out maps] [--preview DIR]

Writes, in ROS map_server format (free 254, occupied 0, unknown 205):
  sample_office.pgm/.yaml            30 m x 20 m office floor, 0.05 m/px (600 x 400)
  sample_office_furnished.pgm/.yaml  the same floor with extra furniture
                                     (pixel aligned: it only adds obstacles)
  small_rooms.png/.yaml              10 m x 7.5 m flat, RGBA PNG (200 x 150)
With --preview, also writes 8-bit PNG copies of the PGMs for viewing.
"""

import argparse
import math
import os
import random
import struct
import zlib

FREE, OCCUPIED, UNKNOWN = 254, 0, 205
RES = 0.05  # metres per pixel


class Canvas:
    """Grey image, row 0 = top. Coordinates are pixels (x right, y down)."""

    def __init__(self, width, height, fill):
        self.width = width
        self.height = height
        self.px = [bytearray([fill]) * width for _ in range(height)]

    def rect(self, x0, y0, x1, y1, value):
        """Fills the half-open box [x0, x1) x [y0, y1), clipped to the image."""
        x0, x1 = max(0, x0), min(self.width, x1)
        for y in range(max(0, y0), min(self.height, y1)):
            self.px[y][x0:x1] = bytes([value]) * max(0, x1 - x0)

    def disc(self, cx, cy, r, value):
        for y in range(cy - r, cy + r + 1):
            for x in range(cx - r, cx + r + 1):
                if (x - cx) ** 2 + (y - cy) ** 2 <= r * r and 0 <= x < self.width \
                        and 0 <= y < self.height:
                    self.px[y][x] = value

    def copy(self):
        c = Canvas(self.width, self.height, 0)
        c.px = [bytearray(row) for row in self.px]
        return c


def m(metres):
    """Metres to pixels."""
    return int(round(metres / RES))


# ---------------------------------------------------------------- office

WALL = m(0.15)    # interior wall, 3 px
OUTER = m(0.25)   # exterior wall, 5 px


def hwall(c, x0, x1, y, t=WALL):
    c.rect(x0, y, x1, y + t, OCCUPIED)


def vwall(c, x, y0, y1, t=WALL):
    c.rect(x, y0, x + t, y1, OCCUPIED)


def door_h(c, x, y, width=m(0.9), t=OUTER):
    """Opening in a horizontal wall starting at x."""
    c.rect(x, y, x + width, y + t, FREE)


def door_v(c, x, y, width=m(0.9), t=OUTER):
    c.rect(x, y, x + t, y + width, FREE)


def desk(c, x, y, w=m(1.6), h=m(0.8)):
    c.rect(x, y, x + w, y + h, OCCUPIED)


def office_floor():
    """600 x 400 px: building 28.5 m x 18 m, corridor along y, rooms either side."""
    W, H = 600, 400
    c = Canvas(W, H, UNKNOWN)
    # Building footprint: an L-ish shape (the top-right corner is a courtyard
    # outside the building, so it stays unknown).
    bx0, by0, bx1, by1 = m(0.75), m(1.0), m(29.25), m(19.0)
    court_x, court_y = m(23.0), m(6.0)  # courtyard: x > court_x, y < court_y
    c.rect(bx0, by0, bx1, by1, FREE)
    c.rect(court_x, by0, bx1, court_y, UNKNOWN)
    # Exterior walls.
    hwall(c, bx0, court_x + OUTER, by0, OUTER)
    hwall(c, court_x, bx1, court_y, OUTER)
    hwall(c, bx0, bx1, by1 - OUTER, OUTER)
    vwall(c, bx0, by0, by1, OUTER)
    vwall(c, court_x, by0, court_y + OUTER, OUTER)
    vwall(c, bx1 - OUTER, court_y, by1, OUTER)

    # Horizontal corridor 2 m wide at y = 9..11 m across the building.
    cy0, cy1 = m(9.0), m(11.0)
    hwall(c, bx0, bx1, cy0 - WALL)
    hwall(c, bx0, bx1, cy1)

    # North side (top of the image, small y): offices split by vertical walls.
    north = [bx0, m(6.5), m(11.0), m(16.5), court_x]
    for x in north[1:-1]:
        vwall(c, x, by0, cy0)
    # East of the courtyard line north of the corridor: meeting room.
    vwall(c, m(26.0), court_y, cy0)
    # South side: open-plan office, kitchen, two small rooms, storage.
    south = [bx0, m(12.0), m(18.0), m(22.5), m(26.0), bx1]
    for x in south[1:-1]:
        vwall(c, x, cy1, by1)
    hwall(c, m(22.5), m(26.0), m(15.0))  # splits the two small rooms

    # Doors from the corridor into every room (0.9 m), plus a double door.
    for x in (m(3.0), m(8.0), m(13.0), m(19.0), m(24.0), m(27.0)):
        door_h(c, x, cy0 - WALL, t=WALL)
    for x in (m(5.0), m(14.0), m(19.5), m(23.2), m(27.5)):
        door_h(c, x, cy1, t=WALL)
    door_h(c, m(9.0), cy1, width=m(1.8), t=WALL)   # double door, open plan
    door_v(c, m(22.5), m(16.5), t=WALL)            # lower small room via side door
    door_v(c, m(26.0), m(6.8), t=WALL)             # meeting room <-> east office
    # Building entrances at both ends of the corridor.
    door_v(c, bx0, m(9.4), width=m(1.2))
    door_v(c, bx1 - OUTER, m(9.4), width=m(1.2))

    # Pillars along the corridor and in the open plan.
    for x in (m(6.0), m(12.0), m(18.0), m(24.0)):
        c.rect(x - m(0.2), cy1 + WALL, x + m(0.2), cy1 + WALL + m(0.4), OCCUPIED)
    for x in (m(4.5), m(8.5)):
        c.rect(x, m(15.0), x + m(0.4), m(15.4), OCCUPIED)

    # North offices: desks along walls, a cabinet each.
    for i, (x0, x1) in enumerate(zip(north[:-1], north[1:])):
        desk(c, x0 + m(0.6), by0 + m(0.8))
        desk(c, x1 - m(2.4), by0 + m(0.8))
        if i % 2 == 0:
            desk(c, x0 + m(1.5), m(5.0), w=m(1.2), h=m(1.2))  # round-ish table
        c.rect(x1 - m(0.8), m(7.0), x1 - m(0.2), m(8.5), OCCUPIED)  # cabinet
    # Meeting room: big table.
    c.rect(m(23.8), m(7.0), m(25.4), m(8.2), OCCUPIED)
    # East office (x 26..29, y 6..9): one desk.
    desk(c, m(26.8), m(6.8), w=m(1.4), h=m(0.7))
    # Open plan (x 0.75..12, y 11..19): two rows of desk islands.
    for x in (m(2.0), m(5.5), m(9.0)):
        for y in (m(12.5), m(16.3)):
            desk(c, x, y, w=m(2.0), h=m(1.4))
    # Kitchen (x 12..18): counter along the bottom wall and an island.
    c.rect(m(12.2), by1 - OUTER - m(0.7), m(17.8), by1 - OUTER, OCCUPIED)
    c.rect(m(14.0), m(14.0), m(16.0), m(15.0), OCCUPIED)
    c.disc(m(16.8), m(12.3), m(0.35), OCCUPIED)  # bin
    # Small rooms (x 18..22.5 and 22.5..26): a desk each, a sofa.
    desk(c, m(18.6), m(17.5), w=m(1.8), h=m(0.8))
    desk(c, m(23.0), m(11.7))
    c.rect(m(23.0), m(17.9), m(25.6), m(18.6), OCCUPIED)
    # Storage (x 26..29.25): shelving rows.
    for y in (m(12.2), m(14.2), m(16.2)):
        c.rect(m(26.5), y, m(28.6), y + m(0.5), OCCUPIED)
    return c


def furnish(c):
    """Extra furniture on top of office_floor() for replanning demos."""
    f = c.copy()
    f.rect(m(10.0), m(9.6), m(10.6), m(10.3), OCCUPIED)    # trolley in the corridor
    f.rect(m(20.5), m(9.4), m(21.0), m(9.9), OCCUPIED)     # box by a wall
    f.rect(m(3.0), m(6.8), m(4.2), m(7.6), OCCUPIED)       # new table, office 1
    f.rect(m(14.2), m(3.5), m(15.7), m(4.3), OCCUPIED)     # sofa, office 3
    f.rect(m(6.0), m(14.3), m(7.2), m(15.0), OCCUPIED)     # printer, open plan
    f.disc(m(10.8), m(18.0), m(0.3), OCCUPIED)             # plant
    f.rect(m(19.5), m(12.0), m(20.5), m(13.0), OCCUPIED)   # crate, small room
    return f


# ---------------------------------------------------------------- small flat

def small_rooms():
    """200 x 150 px = 10 m x 7.5 m: three rooms and a hall, fully enclosed."""
    c = Canvas(200, 150, FREE)
    t = 4
    c.rect(0, 0, 200, t, OCCUPIED)
    c.rect(0, 150 - t, 200, 150, OCCUPIED)
    c.rect(0, 0, t, 150, OCCUPIED)
    c.rect(200 - t, 0, 200, 150, OCCUPIED)
    c.rect(0, 70, 130, 73, OCCUPIED)       # hall / rooms divider
    c.rect(80, 0, 83, 70, OCCUPIED)        # room 1 | room 2
    c.rect(130, 0, 133, 150, OCCUPIED)     # west | east room
    c.rect(30, 70, 50, 73, FREE)           # doors
    c.rect(100, 70, 118, 73, FREE)
    c.rect(130, 100, 133, 118, FREE)
    c.rect(20, 20, 50, 36, OCCUPIED)       # bed
    c.rect(150, 30, 180, 50, OCCUPIED)     # table
    c.disc(60, 115, 7, OCCUPIED)           # round table
    c.rect(90, 130, 126, 146, OCCUPIED)    # sofa
    return c


# ---------------------------------------------------------------- writers

def scanner_noise(c, seed):
    """Sparse speckle on walls only, as a laser map would show."""
    rng = random.Random(seed)
    for y in range(1, c.height - 1):
        row = c.px[y]
        for x in range(1, c.width - 1):
            if row[x] == OCCUPIED and rng.random() < 0.03:
                row[x] = 30 + rng.randrange(40)  # still clearly occupied


def write_pgm(path, c):
    with open(path, "wb") as f:
        # The header names the path this script had when the shipped maps were written; it stays
        # so that regenerating reproduces maps/ byte for byte (their content ids included).
        f.write(b"P5\n# covplan sample map (scripts/gen_sample_maps.py)\n")
        f.write(b"%d %d\n255\n" % (c.width, c.height))
        for row in c.px:
            f.write(bytes(row))


def png_chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))


def write_png(path, c, rgba=False):
    raw = bytearray()
    for row in c.px:
        raw.append(0)  # filter: none
        if rgba:
            for v in row:
                raw += bytes((v, v, v, 255))
        else:
            raw += row
    ihdr = struct.pack(">IIBBBBB", c.width, c.height, 8, 6 if rgba else 0, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(png_chunk(b"IHDR", ihdr))
        f.write(png_chunk(b"IDAT", zlib.compress(bytes(raw), 9)))
        f.write(png_chunk(b"IEND", b""))


# ---------------------------------------------------------------- yard (polygons)

def yard_polygons():
    """A garden for a mowing robot, as polygons in metres: a back lawn with a
    house, a round flower bed and a pond cut out, joined by a 1.4 m path to
    a front lawn with a tree ring. Returns (free-space polygons, no-go zones)."""
    def circle(cx, cy, r, n=24):
        pts = [(round(cx + r * math.cos(2 * math.pi * k / n), 3),
                round(cy + r * math.sin(2 * math.pi * k / n), 3)) for k in range(n)]
        return pts + [pts[0]]
    back = [(0.0, 0.0), (24.0, 0.0), (24.0, 14.0), (13.0, 14.0), (13.0, 15.5),
            (11.6, 15.5), (11.6, 14.0), (0.0, 14.0), (0.0, 0.0)]
    house = [(2.0, 9.0), (9.5, 9.0), (9.5, 12.8), (2.0, 12.8), (2.0, 9.0)]
    bed = circle(16.0, 9.0, 1.6)
    pond = [(4.0, 2.0), (7.5, 1.6), (8.6, 3.4), (6.9, 5.1), (4.6, 4.6), (4.0, 2.0)]
    front = [(6.0, 15.5), (20.0, 15.5), (20.0, 23.0), (6.0, 23.0), (6.0, 15.5)]
    tree = circle(15.5, 19.5, 0.9, n=16)
    veg_patch = [(19.0, 2.0), (22.6, 2.0), (22.6, 5.0), (19.0, 5.0), (19.0, 2.0)]
    free = [[back, house, bed, pond], [front, tree]]
    return free, [[veg_patch]]


def write_geojson(path, polygons):
    import json
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {},
         "geometry": {"type": "MultiPolygon",
                      "coordinates": [[[list(p) for p in ring] for ring in poly]
                                      for poly in polygons]}}]}
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def to_lon_lat(polygons, lon0=11.5874, lat0=48.1557):
    """The polygons placed on the globe (a park in Munich), longitude/latitude in
    degrees as a web map draws them (RFC 7946 GeoJSON): a local equirectangular
    approximation on the WGS84 ellipsoid's radii, good to millimetres over 25 m."""
    a, e2 = 6378137.0, 6.69437999014e-3
    s = math.sin(math.radians(lat0))
    n = a / math.sqrt(1 - e2 * s * s)                   # prime vertical radius
    m = a * (1 - e2) / (1 - e2 * s * s) ** 1.5          # meridian radius
    def ll(p):
        return (round(lon0 + math.degrees(p[0] / (n * math.cos(math.radians(lat0)))), 9),
                round(lat0 + math.degrees(p[1] / m), 9))
    return [[[ll(p) for p in ring] for ring in poly] for poly in polygons]


def write_yaml(path, image, origin):
    with open(path, "w") as f:
        f.write("image: %s\nresolution: %g\norigin: [%g, %g, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
                % (image, RES, origin[0], origin[1]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    parser.add_argument("--out", default=os.path.join(here, "..", "..", "maps"))
    parser.add_argument("--preview", help="also write PNG previews into this directory")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    office = office_floor()
    scanner_noise(office, seed=1)
    furnished = furnish(office)
    flat = small_rooms()
    outputs = [("sample_office", office), ("sample_office_furnished", furnished)]
    for name, canvas in outputs:
        write_pgm(os.path.join(args.out, name + ".pgm"), canvas)
        write_yaml(os.path.join(args.out, name + ".yaml"), name + ".pgm", (-1.0, -0.5))
    write_png(os.path.join(args.out, "small_rooms.png"), flat, rgba=True)
    write_yaml(os.path.join(args.out, "small_rooms.yaml"), "small_rooms.png", (0.0, 0.0))
    yard, zones = yard_polygons()
    write_geojson(os.path.join(args.out, "sample_yard.geojson"), yard)
    write_geojson(os.path.join(args.out, "sample_yard_no_go.geojson"), zones)
    write_geojson(os.path.join(args.out, "sample_lawn_lonlat.geojson"), to_lon_lat(yard))
    write_geojson(os.path.join(args.out, "sample_lawn_lonlat_no_go.geojson"), to_lon_lat(zones))
    if args.preview:
        os.makedirs(args.preview, exist_ok=True)
        for name, canvas in outputs:
            write_png(os.path.join(args.preview, name + ".png"), canvas)


if __name__ == "__main__":
    main()
