#!/usr/bin/env python3
"""Writes scenes/view_slices/meshes/dome.glb and dome.obj: the same base surface (a wavy dome over
the unit disc's square, with uvs and vertex colours) as glTF 2.0 binary and as OBJ, for
gltf_dome.ron and the test that both load to the same mesh and render the same image.

The glb is written the way DCC exporters write meshes: vertices split per triangle corner (uv
and colour seams), the mesh under a parent node whose transform (translation (0.5, 0, 0), scale
2) the positions undo, and v flipped (glTF's origin is top left). Every coordinate is a multiple
of 1/4096, exact in f32 and in decimal, so the two files describe bit-identical f64 meshes; OBJ
vertices are listed in the order of their first corner, the order voltex welds glTF vertices in.

Provenance and licence: our own shape, defined by the numbers in this file (written for voltex,
under the project's licence).

Usage: python3 tools/gen_dome.py   (from anywhere; deterministic output, standard library only)
"""

import json
import math
import os
import struct

DIR = os.path.join(os.path.dirname(__file__), "..", "scenes", "view_slices", "meshes")
N = 12  # cells per side


def q(x):
    return round(x * 4096) / 4096


def corner(i, j):
    x, y = 2.0 * i / N - 1.0, 2.0 * j / N - 1.0
    z = 0.35 * math.cos(0.5 * math.pi * min(1.0, math.hypot(x, y))) + 0.05 * math.sin(3 * x) * math.sin(3 * y)
    color = (q(0.5 + 0.5 * x), q(0.6), q(0.5 + 0.5 * y))
    return (q(x), q(y), q(z)), (q(i / N), q(j / N)), color


def main():
    # Triangles as corners (position, uv, colour), counter-clockwise from above.
    tris = []
    for j in range(N):
        for i in range(N):
            a, b, c, d = corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)
            tris += [(a, b, c), (a, c, d)]
    os.makedirs(DIR, exist_ok=True)

    # OBJ: welded vertices in first-corner order, uvs per corner.
    index, lines, faces = {}, [], []
    for t in tris:
        ids = []
        for p, uv, col in t:
            if p not in index:
                index[p] = len(index) + 1
                lines.append("v %r %r %r %r %r %r" % (p + col))
            ids.append(index[p])
        faces.append(ids)
    out = ["# dome: tools/gen_dome.py (the same surface as dome.glb)"] + lines
    uvs = []
    for t, ids in zip(tris, faces):
        base = len(uvs) + 1
        uvs += [uv for _, uv, _ in t]
        faces_line = " ".join("%d/%d" % (v, base + k) for k, v in enumerate(ids))
        out.append("f " + faces_line)
    out[1 + len(lines):1 + len(lines)] = ["vt %r %r" % uv for uv in uvs]
    with open(os.path.join(DIR, "dome.obj"), "w") as f:
        f.write("\n".join(out) + "\n")

    # glb: one vertex per corner, positions in the child's frame (undoing the parent's transform).
    pos, tex, cols = [], [], []
    for t in tris:
        for p, uv, col in t:
            pos += [(p[0] - 0.5) / 2, p[1] / 2, p[2] / 2]
            tex += [uv[0], 1.0 - uv[1]]
            cols += list(col)
    n = len(pos) // 3
    binary = struct.pack("<%df" % len(pos), *pos) + struct.pack("<%df" % len(tex), *tex)
    binary += struct.pack("<%df" % len(cols), *cols)
    lo = [min(pos[k::3]) for k in range(3)]
    hi = [max(pos[k::3]) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "voltex tools/gen_dome.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "dome", "translation": [0.5, 0, 0], "scale": [2, 2, 2], "children": [1]},
            {"name": "dome mesh", "mesh": 0},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}}]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * n},
            {"buffer": 0, "byteOffset": 12 * n, "byteLength": 8 * n},
            {"buffer": 0, "byteOffset": 20 * n, "byteLength": 12 * n},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC3"},
        ],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    glb = struct.pack("<4sII", b"glTF", 2, total)
    glb += struct.pack("<I4s", len(text), b"JSON") + text
    glb += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    with open(os.path.join(DIR, "dome.glb"), "wb") as f:
        f.write(glb)


if __name__ == "__main__":
    main()
