#!/usr/bin/env python3
"""Writes the closed meshes of the Figure 11 example scenes (Gilet & Dischler 2009) to
scenes/hypertextures/meshes/: a cube, and a teapot.

Provenance and licence: both shapes are our own, defined by the numbers in this file (written for
voltex, under the project's licence). The teapot is NOT the Newell (Utah) teapot: it is a lathed
body and lid (one closed surface of revolution from a bottom pole to a knob pole) with a spout and
a handle swept as closed, capped tubes whose ends are buried in the body. Hypertexture mesh objects
take a mesh made of several closed parts as their union, so the parts may overlap.

Usage: python3 tools/gen_fig11_meshes.py   (from the project root; deterministic output)
"""

import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "hypertextures", "meshes")


class Obj:
    def __init__(self, comment):
        self.lines = [f"# {line}" for line in comment.splitlines()]
        self.count = 0

    def vertex(self, p):
        self.lines.append("v %.5f %.5f %.5f" % tuple(0.0 if abs(c) < 5e-6 else c for c in p))
        self.count += 1
        return self.count

    def face(self, *ids):
        self.lines.append("f " + " ".join(str(i) for i in ids))

    def write(self, name):
        os.makedirs(OUT, exist_ok=True)
        with open(os.path.join(OUT, name), "w") as f:
            f.write("\n".join(self.lines) + "\n")


def cube():
    o = Obj("A cube of edge 1.6 centred on the origin (tools/gen_fig11_meshes.py).")
    h = 0.8
    ids = [o.vertex(((-h, h)[k & 1], (-h, h)[k >> 1 & 1], (-h, h)[k >> 2 & 1])) for k in range(8)]
    for f in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
        o.face(*(ids[i] for i in f))
    o.write("cube.obj")


def catmull_rom(points, per_segment):
    """A smooth polyline through `points` (2D or 3D tuples), end points repeated as tangents."""
    pts = [points[0]] + list(points) + [points[-1]]
    out = []
    for i in range(1, len(pts) - 2):
        p0, p1, p2, p3 = pts[i - 1], pts[i], pts[i + 1], pts[i + 2]
        for s in range(per_segment):
            t = s / per_segment
            t2, t3 = t * t, t * t * t
            out.append(tuple(
                0.5 * (2 * b + (c - a) * t + (2 * a - 5 * b + 4 * c - d) * t2 + (3 * b - a - 3 * c + d) * t3)
                for a, b, c, d in zip(p0, p1, p2, p3)
            ))
    out.append(points[-1])
    return out


def lathe(o, profile, around):
    """A closed surface of revolution about z: `profile` runs (r, z) from a pole (r = 0) to a pole."""
    bottom = o.vertex((0.0, 0.0, profile[0][1]))
    rings = []
    for r, z in profile[1:-1]:
        rings.append([o.vertex((r * math.cos(2 * math.pi * a / around), r * math.sin(2 * math.pi * a / around), z))
                      for a in range(around)])
    top = o.vertex((0.0, 0.0, profile[-1][1]))
    for a in range(around):
        b = (a + 1) % around
        o.face(bottom, rings[0][b], rings[0][a])
        for lo, hi in zip(rings, rings[1:]):
            o.face(lo[a], lo[b], hi[b], hi[a])
        o.face(top, rings[-1][a], rings[-1][b])


def tube(o, centre, radii, around):
    """A closed tube along `centre` (points in the xz plane) with a radius per point, capped."""
    def sub(p, q):
        return tuple(a - b for a, b in zip(p, q))

    def unit(v):
        n = math.sqrt(sum(c * c for c in v))
        return tuple(c / n for c in v)

    rings = []
    for i, (p, r) in enumerate(zip(centre, radii)):
        t = unit(sub(centre[min(i + 1, len(centre) - 1)], centre[max(i - 1, 0)]))
        # The curve lies in the xz plane: y is the binormal, n = y x t the normal.
        n = (t[2], 0.0, -t[0])
        rings.append([o.vertex(tuple(p[k] + r * (math.cos(2 * math.pi * a / around) * n[k]
                                                   + math.sin(2 * math.pi * a / around) * (0.0, 1.0, 0.0)[k])
                                     for k in range(3)))
                      for a in range(around)])
    start = o.vertex(centre[0])
    end = o.vertex(centre[-1])
    for a in range(around):
        b = (a + 1) % around
        o.face(start, rings[0][b], rings[0][a])
        for lo, hi in zip(rings, rings[1:]):
            o.face(lo[a], lo[b], hi[b], hi[a])
        o.face(end, rings[-1][a], rings[-1][b])


def teapot():
    o = Obj("A teapot of our own design, not the Newell teapot (tools/gen_fig11_meshes.py):\n"
            "a lathed body and lid, a spout and a handle as closed tubes buried in the body.")
    # (r, z): bottom pole, foot, belly, shoulder, rim, lid dome, knob neck, knob, top pole.
    body = [(0.0, 0.0), (0.75, 0.0), (1.0, 0.08), (1.25, 0.35), (1.32, 0.62), (1.2, 0.95), (0.95, 1.2),
            (0.84, 1.3), (0.86, 1.36), (0.7, 1.48), (0.35, 1.6), (0.12, 1.66), (0.12, 1.72), (0.2, 1.78),
            (0.16, 1.88), (0.0, 1.92)]
    profile = catmull_rom(body, 3)
    lathe(o, profile, 40)
    spout = catmull_rom([(0.7, 0.0, 0.45), (1.3, 0.0, 0.55), (1.7, 0.0, 0.95), (2.0, 0.0, 1.35)], 6)
    radii = [0.3 - 0.18 * i / (len(spout) - 1) for i in range(len(spout))]
    tube(o, spout, radii, 16)
    handle = catmull_rom([(-0.9, 0.0, 1.1), (-1.5, 0.0, 1.15), (-1.85, 0.0, 0.8), (-1.6, 0.0, 0.42),
                          (-1.0, 0.0, 0.3)], 6)
    tube(o, handle, [0.1] * len(handle), 12)
    o.write("teapot.obj")


if __name__ == "__main__":
    cube()
    teapot()
