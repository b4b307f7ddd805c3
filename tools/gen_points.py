#!/usr/bin/env python3
"""Writes the point set of the `points_cumulus` example scene (hypertexture Points objects,
Gilet & Dischler 2009, section 5.1) to scenes/hypertextures/points/cumulus.ply: a cumulus cloud
as the union of six puffs (spheres) cut flat at its base, sampled by a jittered lattice of
spacing 0.09 (an even density, so the kernel sum is even inside), as binary little-endian PLY
with x, y, z and a per-point `radius` factor from 0.8 to 1.2.

Provenance and licence: our own shape, defined by the numbers in this file (written for voltex,
under the project's licence).

Usage: python3 tools/gen_points.py   (from the project root; deterministic output)
"""

import os
import struct

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "hypertextures", "points", "cumulus.ply")
# (centre, radius) of each puff; the base is cut at z = BASE.
PUFFS = [
    ((0.0, 0.0, 0.0), 0.75),
    ((-0.75, 0.1, -0.12), 0.55),
    ((0.75, -0.05, -0.08), 0.6),
    ((0.25, 0.1, 0.5), 0.5),
    ((-0.35, -0.1, 0.42), 0.45),
    ((1.25, 0.05, -0.25), 0.35),
]
BASE = -0.42
SPACING = 0.09


def hash01(n):
    """A PCG-style hash of an integer into [0, 1) (deterministic jitter)."""
    n = (n * 747796405 + 2891336453) & 0xFFFFFFFF
    n = (((n >> ((n >> 28) + 4)) ^ n) * 277803737) & 0xFFFFFFFF
    return ((n >> 22) ^ n) / 4294967296.0


def inside(p):
    if p[2] < BASE:
        return False
    return any(sum((a - b) ** 2 for a, b in zip(p, c)) <= r * r for c, r in PUFFS)


def main():
    points = []
    n = 24
    for k in range(-n, n + 1):
        for j in range(-n, n + 1):
            for i in range(-n, n + 1):
                seed = ((k + n) * 64 + (j + n)) * 64 + (i + n)
                jitter = [0.35 * (hash01(3 * seed + a) - 0.5) for a in range(3)]
                p = tuple(SPACING * (c + d) for c, d in zip((i, j, k), jitter))
                if inside(p):
                    points.append(p + (0.8 + 0.4 * hash01(7 * seed + 11),))
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment voltex tools/gen_points.py: a cumulus of six puffs\n"
        f"element vertex {len(points)}\nproperty float x\nproperty float y\nproperty float z\n"
        "property float radius\nend_header\n"
    )
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "wb") as f:
        f.write(header.encode("ascii"))
        for p in points:
            f.write(struct.pack("<4f", *p))
    print(f"{OUT}: {len(points)} points")


if __name__ == "__main__":
    main()
