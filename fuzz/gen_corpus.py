#!/usr/bin/python3
"""Writes the seed corpus for map_reader_fuzzer into fuzz/corpus/ (stdlib only).

Each file starts with the selector byte the fuzzer reads (see
map_reader_fuzzer.cc): 0 image, 1 YAML, 2 YAML + NUL + image, 3 image negated.
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


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
    os.makedirs(out, exist_ok=True)
    for name, data in SEEDS.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
