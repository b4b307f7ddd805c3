#!/usr/bin/env python3
"""Writes scenes/meyer_neyret/bush.obj: the sparse pattern mesh of bushes.ron (Meyer & Neyret
1998, section 6 and Figure 11 right: "an AMAP generated bush of 3,500 triangles ... sparse
triangles, no filling is done"). AMAP is not available, so this grows a bush of its own: a trunk
splitting recursively into tapered four-sided branches (open tubes), with rhombic leaves (two
triangles each) scattered along the outer branches, about 3,500 triangles in all, coloured per
vertex (bark, leaves of varied greens). Nothing is closed: the texel draws it as a one-voxel
shell (`fill: false`).

Provenance and licence: our own shape, defined by the numbers and the seeded generator in this
file (written for voltex, under the project's licence). Object space: z up, the bush inside the
box (-0.5, -0.5, 0) to (0.5, 0.5, 0.6), its root at the origin.

Usage: python3 tools/gen_bush.py   (from anywhere; deterministic output, standard library only)
"""

import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "meyer_neyret", "bush.obj")
LO, HI = (-0.5, -0.5, 0.0), (0.5, 0.5, 0.6)
# Branching: children per branch, length and radius ratios, levels below the trunk.
CHILDREN, LENGTH_RATIO, RADIUS_RATIO, LEVELS = 3, 0.8, 0.6, 4
TRUNK_LENGTH, TRUNK_RADIUS = 0.17, 0.014
# Leaves per branch of the last two levels, and a leaf's length and width.
LEAVES = {LEVELS - 1: 7, LEVELS: 13}
LEAF_LENGTH, LEAF_WIDTH = 0.05, 0.022
# Vertex colours (OBJ `v x y z r g b`): bark, and leaves between a dark and a light green.
BARK = (0.42, 0.3, 0.18)
LEAF_DARK, LEAF_LIGHT = (0.2, 0.42, 0.12), (0.45, 0.65, 0.2)


class Lcg:
    """A fixed 64-bit linear congruential generator (the output must not depend on Python's
    random module across versions)."""

    def __init__(self, seed):
        self.state = seed

    def uniform(self, lo=0.0, hi=1.0):
        self.state = (self.state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        return lo + (hi - lo) * ((self.state >> 11) / float(1 << 53))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return scale(a, 1.0 / n)


def frame(d):
    """Two unit vectors perpendicular to the unit vector d and to each other."""
    side = (1.0, 0.0, 0.0) if abs(d[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = normalize(cross(d, side))
    return u, cross(d, u)


def inside(p, margin):
    return all(LO[i] + margin <= p[i] <= HI[i] - margin for i in range(3))


class Obj:
    def __init__(self):
        self.lines = ["# Bush (tools/gen_bush.py): open branch tubes and leaves, drawn as a shell"]
        self.count = 0
        self.triangles = 0

    def vertex(self, p, color):
        self.count += 1
        xyz = tuple(0.0 if abs(c) < 5e-5 else c for c in p)
        self.lines.append("v %.4f %.4f %.4f %.3f %.3f %.3f" % (xyz + tuple(color)))
        return self.count

    def face(self, *v):
        self.lines.append("f " + " ".join(str(i) for i in v))
        self.triangles += 1


def tube(obj, a, b, ra, rb):
    """A tapered open four-sided tube from a (radius ra) to b (radius rb): eight triangles."""
    u, v = frame(normalize(add(b, scale(a, -1.0))))
    ring = []
    for end, r in ((a, ra), (b, rb)):
        ring.append([obj.vertex(add(end, add(scale(u, r * math.cos(k * math.pi / 2)),
                                               scale(v, r * math.sin(k * math.pi / 2)))), BARK)
                     for k in range(4)])
    for k in range(4):
        i, j = k, (k + 1) % 4
        obj.face(ring[0][i], ring[0][j], ring[1][j])
        obj.face(ring[0][i], ring[1][j], ring[1][i])


def leaf(obj, rng, at, along):
    """A rhombic leaf (two triangles) from `at`, leaning out along the branch and upwards."""
    d = normalize(add(add(scale(along, 0.6), (0.0, 0.0, 0.5)),
                      (rng.uniform(-0.7, 0.7), rng.uniform(-0.7, 0.7), rng.uniform(-0.3, 0.5))))
    u, v = frame(d)
    turn = rng.uniform(0.0, 2.0 * math.pi)
    across = add(scale(u, math.cos(turn)), scale(v, math.sin(turn)))
    length = LEAF_LENGTH * rng.uniform(0.7, 1.2)
    tip = add(at, scale(d, length))
    if not inside(tip, 0.002):
        return
    mid = add(at, scale(d, 0.45 * length))
    half = scale(across, 0.5 * LEAF_WIDTH * length / LEAF_LENGTH)
    # Leaves vary in hue; the stalk end is darker than the tip.
    green = rng.uniform(0.0, 1.0)
    base = tuple(a + (b - a) * green for a, b in zip(LEAF_DARK, LEAF_LIGHT))
    tip_color = tuple(min(1.0, c * 1.25) for c in base)
    a, b, c, e = (obj.vertex(at, base), obj.vertex(add(mid, half), base), obj.vertex(tip, tip_color),
                  obj.vertex(add(mid, scale(half, -1.0)), base))
    obj.face(a, b, c)
    obj.face(a, c, e)


def grow(obj, rng, start, direction, length, radius, level):
    end = add(start, scale(direction, length))
    # Branches that would leave the box are shortened to stay inside it.
    while not inside(end, 0.01) and length > 0.01:
        length *= 0.8
        end = add(start, scale(direction, length))
    tube(obj, start, end, radius, radius * RADIUS_RATIO)
    for _ in range(LEAVES.get(level, 0)):
        f = rng.uniform(0.15, 1.0)
        leaf(obj, rng, add(start, scale(direction, f * length)), direction)
    if level == LEVELS:
        return
    for k in range(CHILDREN):
        # Spread around the parent, leaning outwards and up; children start along the top half.
        around = 2.0 * math.pi * (k + rng.uniform(-0.3, 0.3)) / CHILDREN
        u, v = frame(direction)
        spread = rng.uniform(0.6, 1.0)
        d = normalize(add(scale(direction, math.cos(spread)),
                          scale(add(scale(u, math.cos(around)), scale(v, math.sin(around))),
                                math.sin(spread))))
        d = normalize(add(d, (0.0, 0.0, 0.15)))
        at = add(start, scale(direction, length * rng.uniform(0.55, 1.0)))
        grow(obj, rng, at, d, length * LENGTH_RATIO * rng.uniform(0.85, 1.15),
             radius * RADIUS_RATIO, level + 1)


def main():
    obj = Obj()
    rng = Lcg(20261122)
    grow(obj, rng, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), TRUNK_LENGTH, TRUNK_RADIUS, 0)
    obj.lines.insert(1, "# %d vertices, %d triangles" % (obj.count, obj.triangles))
    with open(OUT, "w") as f:
        f.write("\n".join(obj.lines) + "\n")
    print("wrote %s: %d triangles" % (os.path.normpath(OUT), obj.triangles))


if __name__ == "__main__":
    main()
