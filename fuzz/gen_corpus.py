#!/usr/bin/python3
"""Writes the seed corpora of map_reader_fuzzer into fuzz/corpus/ and of
plan_request_fuzzer into fuzz/corpus/plan_request/ (stdlib only).

Each map reader seed starts with the selector byte the fuzzer reads (see
map_reader_fuzzer.cc): 0 image, 1 YAML, 2 YAML + NUL + image, 3 image negated.
The plan request seeds are covplan.v1.PlanRequest messages in the protobuf
wire format, encoded here by hand so that no protobuf module is needed.
"""

import os
import struct
import zlib


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))


def png(width, height, bit_depth, color_type, rows, plte=None, trns=None):
    """rows: list of already packed row bytes (without the filter byte)."""
    raw = b"".join(b"\0" + r for r in rows)
    out = b"\x89PNG\r\n\x1a\n"
    out += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0))
    if plte:
        out += chunk(b"PLTE", plte)
    if trns:
        out += chunk(b"tRNS", trns)
    out += chunk(b"IDAT", zlib.compress(raw, 9))
    return out + chunk(b"IEND", b"")


YAML = (b"image: map.pgm\nresolution: 0.05\norigin: [-1.5, 2.0, 0.0]\nnegate: 0\n"
        b"occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n")
P5 = b"P5\n# seed\n4 3\n255\n" + bytes([0, 254, 205, 254, 254, 0, 90, 206, 254, 254, 254, 0])
P2 = b"P2\n# ascii\n3 2 # dims\n255\n0 254 205\n# mid\n254 0 254\n"
P5_16 = b"P5 2 2 65535\n" + struct.pack(">4H", 0, 65535, 52685, 1000)

SEEDS = {
    "pgm_p5": b"\0" + P5,
    "pgm_p2": b"\0" + P2,
    "pgm_p5_16bit": b"\0" + P5_16,
    "png_grey8": b"\0" + png(4, 2, 8, 0, [bytes([0, 254, 205, 90]), bytes([254] * 4)]),
    "png_grey1": b"\0" + png(9, 2, 1, 0, [b"\xa5\x80", b"\xff\x00"]),
    "png_rgba8": b"\0" + png(2, 2, 8, 6, [bytes([0, 0, 0, 255, 254, 254, 254, 0])] * 2),
    "png_rgb16": b"\0" + png(2, 1, 16, 2, [struct.pack(">6H", 0, 0, 0, 65535, 65535, 52685)]),
    "png_palette2": b"\0" + png(4, 2, 2, 3, [b"\x1b", b"\xe4"],
                                plte=bytes([0, 0, 0, 254, 254, 254, 205, 205, 205, 255, 0, 0]),
                                trns=b"\x00\xff"),
    "png_grey_alpha16": b"\3" + png(1, 2, 16, 4, [struct.pack(">2H", 0, 0),
                                                  struct.pack(">2H", 65535, 65535)]),
    "yaml_block": b"\1" + YAML,
    "yaml_flow": b"\1{image: m.png, resolution: 0.1, origin: [0, 0], negate: true}",
    "yaml_with_image": b"\2" + YAML + b"\0" + P5,
    "pgm_negated": b"\3" + P2,
}


def varint(n):
    out = b""
    while True:
        low = n & 0x7F
        n >>= 7
        if n:
            out += bytes([low | 0x80])
        else:
            return out + bytes([low])


def field_varint(number, n):
    return varint(number << 3) + varint(n)


def field_double(number, x):
    return varint(number << 3 | 1) + struct.pack("<d", x)


def field_bytes(number, data):
    return varint(number << 3 | 2) + varint(len(data)) + data


def pose(x, y, theta):
    return field_double(1, x) + field_double(2, y) + field_double(3, theta)


def polygon(points, holes=()):
    """A Polygon of closed rings (the first point repeated at the end)."""
    def ring(pts):
        pts = list(pts) + [pts[0]]
        return b"".join(field_bytes(1, field_double(1, x) + field_double(2, y)) for x, y in pts)
    return field_bytes(1, ring(points)) + b"".join(field_bytes(2, ring(h)) for h in holes)


SQUARE = [(0.0, 0.0), (10.0, 0.0), (10.0, 8.0), (0.0, 8.0)]
POST = [(4.0, 3.0), (5.0, 3.0), (5.0, 4.0), (4.0, 4.0)]
ROBOT = field_double(1, 0.5) + field_double(2, 0.8) + field_bytes(5, pose(1.0, 1.0, 0.0))
POLYGON_MAP = field_bytes(2, field_bytes(2, field_bytes(1, polygon(SQUARE, [POST])) +
                                         field_double(2, 0.05)))
RASTER_MAP = field_bytes(2, field_bytes(1, field_bytes(1, P5) + field_double(3, 0.5)))
MAP_ID = field_bytes(1, b"0" * 64)

PLAN_REQUEST_SEEDS = {
    # oarp with its nested options, a region and a no-go zone on a polygon map
    "oarp_polygon_zones": POLYGON_MAP + field_bytes(3, ROBOT) + field_double(6, 0.5) +
    field_varint(7, 3) + field_bytes(9, b"oarp") + field_bytes(10, field_varint(1, 2) +
                                                               field_varint(2, 2)) +
    field_bytes(11, polygon([(1.0, 1.0), (9.0, 1.0), (9.0, 7.0), (1.0, 7.0)])) +
    field_bytes(12, polygon([(6.0, 5.0), (7.0, 5.0), (7.0, 6.0), (6.0, 6.0)])),
    # the top-level solver fields of the default planner, a raster map
    "default_raster": RASTER_MAP + field_bytes(3, field_double(1, 0.5)) + field_varint(4, 1) +
    field_varint(5, 1) + field_double(8, 0.6),
    # boustrophedon by stored map id, with a battery
    "boustrophedon_battery": MAP_ID + field_bytes(3, ROBOT) + field_bytes(9, b"boustrophedon") +
    field_bytes(14, field_varint(1, 2) + field_varint(2, 2)) +
    field_bytes(15, field_double(1, 200.0) + field_bytes(2, pose(0.5, 0.5, 0.0)) +
                field_double(3, 10.0) + field_bytes(4, field_double(1, 1.0) +
                                                    field_double(2, 0.5))),
    # stc with every option set, improve_remembered
    "stc_options": MAP_ID + field_bytes(3, ROBOT) + field_bytes(9, b"stc") +
    field_bytes(13, field_varint(1, 2) + field_varint(2, 1) + field_varint(3, 2)) +
    field_varint(16, 1),
}


def write(out, seeds):
    os.makedirs(out, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
    write(out, SEEDS)
    write(os.path.join(out, "plan_request"), PLAN_REQUEST_SEEDS)


if __name__ == "__main__":
    main()
