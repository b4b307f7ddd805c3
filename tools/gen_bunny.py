#!/usr/bin/env python3
"""Writes scenes/hypertextures/meshes/bunny.obj: a closed, rabbit-like STAND-IN for the Stanford
bunny of Gilet & Dischler 2009, Figure 11.

Why a stand-in: every Stanford bunny we found in a package (the npm package "bunny", for one)
derives from the Stanford 3D Scanning Repository, whose terms restrict commercial use; the package
says "Public Domain" but ships no licence file and credits Stanford for the data. So this shape is
our own, defined by the numbers in this file (written for voltex, under the project's licence).

How: a smooth union (polynomial smooth minimum) of ellipsoids (body, haunches, chest, head,
snout, cheeks, two ears, tail, paws), sampled on a regular grid and meshed by marching
tetrahedra (six tetrahedra per cell around the cell's main diagonal, so neighbouring cells split
their shared faces alike): every edge of the result is shared by exactly two triangles, and
triangles are oriented outwards. Hypertexture mesh objects need closed meshes.

Usage: python3 tools/gen_bunny.py   (from the project root; deterministic output)
"""

import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "hypertextures", "meshes")
CELL = 0.07  # grid spacing (object units): 9,356 triangles for a bunny 1.8 tall
SMOOTH = 0.12  # smooth-minimum blend radius


def rot_y(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def rot_x(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))


def mul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

# (centre, radii, rotation): the bunny sits on z = 0, faces -x, its ears up and back.
# Ears: rotated about y (leaning back) then about x (splayed sideways).
PARTS = [
    ((0.12, 0.0, 0.42), (0.55, 0.40, 0.40), IDENTITY),  # body
    ((0.30, 0.22, 0.33), (0.36, 0.20, 0.32), IDENTITY),  # left haunch
    ((0.30, -0.22, 0.33), (0.36, 0.20, 0.32), IDENTITY),  # right haunch
    ((-0.30, 0.0, 0.52), (0.28, 0.28, 0.34), IDENTITY),  # chest
    ((-0.50, 0.0, 0.98), (0.30, 0.25, 0.25), rot_y(-15.0)),  # head
    ((-0.76, 0.0, 0.92), (0.15, 0.14, 0.13), IDENTITY),  # snout
    ((-0.58, 0.13, 0.90), (0.16, 0.12, 0.13), IDENTITY),  # left cheek
    ((-0.58, -0.13, 0.90), (0.16, 0.12, 0.13), IDENTITY),  # right cheek
    ((-0.36, 0.12, 1.48), (0.11, 0.075, 0.36), mul(rot_x(-26.0), rot_y(20.0))),  # left ear
    ((-0.36, -0.12, 1.48), (0.11, 0.075, 0.36), mul(rot_x(26.0), rot_y(20.0))),  # right ear
    ((0.72, 0.0, 0.50), (0.13, 0.13, 0.13), IDENTITY),  # tail
    ((-0.52, 0.13, 0.09), (0.17, 0.085, 0.09), IDENTITY),  # left front paw
    ((-0.52, -0.13, 0.09), (0.17, 0.085, 0.09), IDENTITY),  # right front paw
    ((0.22, 0.30, 0.09), (0.34, 0.11, 0.09), IDENTITY),  # left hind foot
    ((0.22, -0.30, 0.09), (0.34, 0.11, 0.09), IDENTITY),  # right hind foot
]


def ellipsoid_distance(p, centre, radii, rot):
    """An approximate signed distance (negative inside): |q / r| - 1 scaled by the smallest radius,
    q in the ellipsoid's own frame (rot's columns are its axes)."""
    d = [p[i] - centre[i] for i in range(3)]
    q = [sum(rot[k][i] * d[k] for k in range(3)) for i in range(3)]
    n = math.sqrt(sum((q[i] / radii[i]) ** 2 for i in range(3)))
    return (n - 1.0) * min(radii)


def smooth_min(a, b, k):
    h = max(k - abs(a - b), 0.0) / k
    return min(a, b) - h * h * k * 0.25


def field(p):
    d = 1e9
    for centre, radii, rot in PARTS:
        d = smooth_min(d, ellipsoid_distance(p, centre, radii, rot), SMOOTH)
    # Cut flat at z = 0 so that the bunny sits on the ground plane.
    return max(d, -p[2])


# Kuhn triangulation of the unit cell: six tetrahedra around the diagonal (0,0,0)-(1,1,1).
CORNERS = [(i & 1, i >> 1 & 1, i >> 2 & 1) for i in range(8)]
TETS = [(0, 1, 3, 7), (0, 1, 5, 7), (0, 2, 3, 7), (0, 2, 6, 7), (0, 4, 5, 7), (0, 4, 6, 7)]


def main():
    lo = (-1.05, -0.62, -0.08)
    hi = (0.95, 0.62, 1.98)
    n = [int(math.ceil((hi[i] - lo[i]) / CELL)) for i in range(3)]
    grid = {}
    for k in range(n[2] + 1):
        for j in range(n[1] + 1):
            for i in range(n[0] + 1):
                v = field((lo[0] + i * CELL, lo[1] + j * CELL, lo[2] + k * CELL))
                grid[(i, j, k)] = v if v != 0.0 else 1e-9  # no sample exactly on the surface

    def pos(c):
        return tuple(lo[a] + c[a] * CELL for a in range(3))

    verts, index = [], {}

    def edge_vertex(a, b):
        key = (a, b) if a < b else (b, a)
        if key not in index:
            va, vb = grid[a], grid[b]
            # Kept off the end points so that vertices on different edges never coincide.
            t = min(max(va / (va - vb), 0.02), 0.98)
            pa, pb = pos(a), pos(b)
            verts.append(tuple(pa[x] + t * (pb[x] - pa[x]) for x in range(3)))
            index[key] = len(verts)
        return index[key]

    tris = []

    def emit(tri, inside_pts, outside_pts):
        p = [verts[v - 1] for v in tri]
        e1 = [p[1][x] - p[0][x] for x in range(3)]
        e2 = [p[2][x] - p[0][x] for x in range(3)]
        nrm = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        ci = [sum(q[x] for q in inside_pts) / len(inside_pts) for x in range(3)]
        co = [sum(q[x] for q in outside_pts) / len(outside_pts) for x in range(3)]
        out = sum(nrm[x] * (co[x] - ci[x]) for x in range(3))
        tris.append(tri if out > 0 else (tri[0], tri[2], tri[1]))

    for k in range(n[2]):
        for j in range(n[1]):
            for i in range(n[0]):
                cell = [(i + c[0], j + c[1], k + c[2]) for c in CORNERS]
                for tet in TETS:
                    vs = [cell[t] for t in tet]
                    ins = [v for v in vs if grid[v] < 0.0]
                    outs = [v for v in vs if grid[v] >= 0.0]
                    ip, op = [pos(v) for v in ins], [pos(v) for v in outs]
                    if len(ins) in (1, 3):
                        lone, rest = (ins[0], outs) if len(ins) == 1 else (outs[0], ins)
                        emit(tuple(edge_vertex(lone, r) for r in rest), ip, op)
                    elif len(ins) == 2:
                        a, b = ins
                        c, d = outs
                        q = (edge_vertex(a, c), edge_vertex(a, d), edge_vertex(b, d), edge_vertex(b, c))
                        emit((q[0], q[1], q[2]), ip, op)
                        emit((q[0], q[2], q[3]), ip, op)

    lines = [
        "# A rabbit-like stand-in for the Stanford bunny (tools/gen_bunny.py): a smooth union of",
        "# ellipsoids meshed by marching tetrahedra; closed. Our own shape, under the project's licence.",
        f"# {len(verts)} vertices, {len(tris)} triangles",
    ]
    lines += ["v %.5f %.5f %.5f" % v for v in verts]
    lines += ["f %d %d %d" % t for t in tris]
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "bunny.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"bunny.obj: {len(verts)} vertices, {len(tris)} triangles")


if __name__ == "__main__":
    main()
