#!/usr/bin/env python3
"""Converts the `density` (and `Cd`) grid of an OpenVDB file to Mitsuba 3's gridvolume `.vol`
format, with the transform that places it where OpenVDB puts it. Mitsuba has no VDB reader.

Run with Blender's Python (`pip install bpy`), whose bundled `openvdb` module reads the file:

    /tmp/bpy-venv/bin/python tools/peers/vdb_to_vol.py IN.vdb OUT_STEM

writes OUT_STEM.density.vol, OUT_STEM.Cd.vol (if the file has Cd) and OUT_STEM.json (the
4x4 to_world matrix, row-major, taking Mitsuba's unit cube onto the grid's world box).

Conventions: OpenVDB puts voxel (i, j, k) at index point (i, j, k), and interpolates to 0 (the
background) over one voxel beyond the active ones. Mitsuba's grid (a Dr.Jit texture) puts voxel
i of n at (i + 0.5) / n of the unit cube and clamps beyond the edge voxels. So the dense array is
the active bounding box grown by one voxel of background on every side: Mitsuba's trilinear
interpolant then equals OpenVDB's everywhere in the box (within half a voxel of the box's faces
it clamps to the background 0, as OpenVDB's is there), and to_world = index_to_world *
translate(lo - 1.5) * scale(n)."""

import json
import os
import struct
import sys

import numpy as np

import common


def write_vol(path, a):
    """a: [x, y, z] or [x, y, z, c] float32; Mitsuba's .vol stores x fastest."""
    if a.ndim == 3:
        a = a[..., None]
    nx, ny, nz, c = a.shape
    data = np.ascontiguousarray(np.transpose(a, (2, 1, 0, 3)), dtype="<f4")  # z, y, x, c
    with open(path + ".tmp", "wb") as f:
        f.write(b"VOL" + bytes([3]))
        f.write(struct.pack("<iiiii", 1, nx, ny, nz, c))
        f.write(struct.pack("<6f", 0, 0, 0, 1, 1, 1))  # the box: the unit cube, to_world does the rest
        f.write(data.tobytes())
    os.replace(path + ".tmp", path)


def main():
    src, stem = sys.argv[1], sys.argv[2]
    dense, lo, m, grids = common.dense_density(src, 1)
    n = dense.shape
    lo = tuple(int(v) for v in lo)
    write_vol(stem + ".density.vol", dense)
    if "Cd" in grids:
        cd = np.zeros(n + (3,), dtype=np.float32)
        grids["Cd"].copyToArray(cd, ijk=lo)
        write_vol(stem + ".Cd.vol", cd)
    place = np.eye(4)
    place[:3, :3] = np.diag(n)
    place[:3, 3] = np.array(lo) - 0.5
    to_world = m @ place
    info = {"to_world": to_world.tolist(), "resolution": n, "index_lo": lo, "has_cd": "Cd" in grids,
            "max_density": float(dense.max())}
    with open(stem + ".json", "w") as f:
        json.dump(info, f, indent=1)
    print(f"{src}: {n[0]}x{n[1]}x{n[2]} voxels (with a rim of background) -> {stem}.density.vol")


if __name__ == "__main__":
    main()
