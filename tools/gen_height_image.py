#!/usr/bin/env python3
"""Writes scenes/meyer_neyret/cobbles.png: a periodic grey-level height image of cobblestones
(64 x 64, 8 bit), the grey-level input of Meyer & Neyret's height-field texels (section 3.2).

Stones are the cells of a jittered periodic grid: the height is the gap between the nearest and
the second-nearest cell centre, rounded into domes, so grooves run between the stones.
Standard library only (the PNG is written with zlib). Run from the project root.
"""
import random
import struct
import zlib

SIZE, CELLS, SEED = 64, 5, 7


def centres():
    rng = random.Random(SEED)
    return [((i + 0.2 + 0.6 * rng.random()) / CELLS, (j + 0.2 + 0.6 * rng.random()) / CELLS)
            for i in range(CELLS) for j in range(CELLS)]


def height(x, y, pts):
    dists = []
    for cx, cy in pts:
        # Periodic distance: the image tiles.
        dx = min(abs(x - cx), 1 - abs(x - cx))
        dy = min(abs(y - cy), 1 - abs(y - cy))
        dists.append((dx * dx + dy * dy) ** 0.5)
    d1, d2 = sorted(dists)[:2]
    gap = min((d2 - d1) * CELLS * 2.5, 1.0)
    return gap ** 0.5


def png(path, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    header = struct.pack(">IIBBBBB", SIZE, SIZE, 8, 0, 0, 0, 0)  # 8-bit grey
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9))
                + chunk(b"IEND", b""))


def main():
    pts = centres()
    rows = [[round(255 * height((i + 0.5) / SIZE, (j + 0.5) / SIZE, pts)) for i in range(SIZE)]
            for j in range(SIZE)]
    png("scenes/meyer_neyret/cobbles.png", rows)


if __name__ == "__main__":
    main()
