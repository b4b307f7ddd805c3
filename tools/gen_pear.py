#!/usr/bin/env python3
"""Writes scenes/meyer_neyret/pear.obj: the pattern mesh of pear_mesh.ron (Meyer & Neyret 1998,
section 3.2: texels built by slicing a mesh). A closed surface of revolution (the body, lathed from
a bottom pole to a top pole along the outline of pear.ron's implicit pear: two ellipsoids and a
sphere) and a closed, capped stem buried in its top: two closed parts, drawn as their union.

Provenance and licence: our own shape, defined by the numbers in this file (written for voltex,
under the project's licence). Object space: z up, the body from z = 0.02 to 0.86 inside the box
(-0.5, -0.5, 0) to (0.5, 0.5, 1).

Usage: python3 tools/gen_pear.py   (from anywhere; deterministic output, standard library only)
"""

import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "meyer_neyret", "pear.obj")
AROUND = 32
RINGS = 40
# (centre z, horizontal radius, vertical radius) of the body's pieces, as in pear.ron.
PIECES = [(0.30, 0.30, 0.28), (0.56, 0.19, 0.19), (0.72, 0.13, 0.14)]
BOTTOM, TOP = 0.02, 0.86
# Vertex colours (OBJ `v x y z r g b`): the skin from yellow to green with a blush; the stem.
YELLOW, GREEN, BLUSH, STEM = (0.85, 0.75, 0.2), (0.55, 0.65, 0.18), (0.8, 0.3, 0.12), (0.35, 0.22, 0.1)


def radius(z):
    r = 0.0
    for c, a, b in PIECES:
        u = (z - c) / b
        if abs(u) < 1.0:
            r = max(r, a * math.sqrt(1.0 - u * u))
    return r


def main():
    lines = ["# Lathed pear with a stem (tools/gen_pear.py): two closed parts"]
    count = 0

    def vertex(x, y, z, color):
        nonlocal count
        xyz = tuple(0.0 if abs(c) < 5e-5 else c for c in (x, y, z))
        lines.append("v %.4f %.4f %.4f %.3f %.3f %.3f" % (xyz + color))
        count += 1
        return count

    def skin(x, y, z):
        # Yellow below, greener towards the neck, a red blush on the sunny (-x, +y) side.
        t = (z - BOTTOM) / (TOP - BOTTOM)
        blush = max(0.0, (-x + y) / 0.42) * max(0.0, 1.0 - abs(z - 0.3) / 0.3)
        r, g, b = YELLOW[0] + (GREEN[0] - YELLOW[0]) * t, YELLOW[1] + (GREEN[1] - YELLOW[1]) * t, 0.2
        return (r + (BLUSH[0] - r) * 0.6 * blush, g + (BLUSH[1] - g) * 0.6 * blush, b)

    # Body: rings spaced by a cosine so that the poles get finer steps.
    bottom = vertex(0.0, 0.0, BOTTOM, skin(0.0, 0.0, BOTTOM))
    rings = []
    for i in range(1, RINGS):
        t = 0.5 - 0.5 * math.cos(math.pi * i / RINGS)
        z = BOTTOM + (TOP - BOTTOM) * t
        r = radius(z)
        ring = []
        for a in range(AROUND):
            phi = 2.0 * math.pi * a / AROUND
            x, y = r * math.cos(phi), r * math.sin(phi)
            ring.append(vertex(x, y, z, skin(x, y, z)))
        rings.append(ring)
    top = vertex(0.0, 0.0, TOP, skin(0.0, 0.0, TOP))
    for a in range(AROUND):
        b = (a + 1) % AROUND
        lines.append("f %d %d %d" % (bottom, rings[0][b], rings[0][a]))
        for k in range(len(rings) - 1):
            lo, hi = rings[k], rings[k + 1]
            lines.append("f %d %d %d %d" % (lo[a], lo[b], hi[b], hi[a]))
        lines.append("f %d %d %d" % (top, rings[-1][a], rings[-1][b]))

    # Stem: a capped tube from inside the top of the body, leaning a little.
    sides = 8
    (x0, z0), (x1, z1), r = (0.0, 0.78), (0.04, 0.98), 0.025
    lo = [vertex(x0 + r * math.cos(2 * math.pi * a / sides), r * math.sin(2 * math.pi * a / sides), z0, STEM) for a in range(sides)]
    hi = [vertex(x1 + r * math.cos(2 * math.pi * a / sides), r * math.sin(2 * math.pi * a / sides), z1, STEM) for a in range(sides)]
    for a in range(sides):
        b = (a + 1) % sides
        lines.append("f %d %d %d %d" % (lo[a], lo[b], hi[b], hi[a]))
    lines.append("f " + " ".join(str(v) for v in reversed(lo)))
    lines.append("f " + " ".join(str(v) for v in hi))
    with open(OUT, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
