"""Shared by the peer scripts: the view voltex exported, the metrics against the truth (through
`voltex compare --json`, so peers and voltex are measured by the same code), the CSV rows that
`voltex pareto --peers` reads, and the machine's threads and load."""

import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VOLTEX = os.environ.get("VOLTEX", os.path.join(ROOT, "target", "release", "voltex"))
COLUMNS = ["renderer", "setting", "samples", "seconds", "threads", "version", "rmse", "rel_rmse", "flip"]


def bundled_openvdb():
    """The `openvdb` module bundled with Blender's Python module (`pip install bpy`)."""
    import glob
    import importlib.util

    base = os.path.dirname(importlib.util.find_spec("bpy").origin)
    for sp in glob.glob(os.path.join(base, "*", "python", "lib", "python3.*", "site-packages")):
        sys.path.insert(0, sp)
    import openvdb

    return openvdb


def dense_density(path, rim):
    """The `density` grid of the VDB at `path` over its active box grown by `rim` voxels of
    background: (float32 array [x, y, z], index of its first voxel, index_to_world 4x4, all grids
    by name)."""
    import numpy as np

    vdb = bundled_openvdb()
    grids = {g.name: g for g in vdb.readAll(path)[0]}
    d = grids["density"]
    lo, hi = (np.array(c) for c in d.evalActiveVoxelBoundingBox())
    lo, hi = lo - rim, hi + rim
    a = np.zeros(tuple(int(v) for v in hi - lo + 1), dtype=np.float32)
    d.copyToArray(a, ijk=tuple(int(v) for v in lo))
    # index_to_world (column vectors): the images of the unit axes and of the origin.
    t = d.transform
    o = np.array(t.indexToWorld((0, 0, 0)))
    m = np.eye(4)
    for k in range(3):
        e = [0, 0, 0]
        e[k] = 1
        m[:3, k] = np.array(t.indexToWorld(tuple(e))) - o
    m[:3, 3] = o
    return a, lo, m, grids


def load_view(path):
    with open(path) as f:
        return json.load(f)


def metrics(image, truth):
    """FLIP, relative RMSE and RMSE of `image` against `truth` (both EXR)."""
    r = subprocess.run([VOLTEX, "compare", image, truth, "--json"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"voltex compare {image} {truth} failed:\n{r.stderr}")
    return json.loads(r.stdout)


def load_average():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def write_csv(path, rows):
    """Rows (dicts with COLUMNS) to `path`, written whole (temporary file, then rename)."""
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, lineterminator="\n")
        w.writeheader()
        for row in rows:
            assert not any("," in str(v) for v in row.values()), row
            w.writerow(row)
    os.replace(tmp, path)


def row(renderer, setting, samples, seconds, threads, version, m):
    return {
        "renderer": renderer,
        "setting": setting,
        "samples": samples,
        "seconds": f"{seconds:.6f}",
        "threads": threads,
        "version": version,
        "rmse": f"{m['rmse']:.6e}",
        "rel_rmse": f"{m['rel_rmse']:.6e}",
        "flip": f"{m['flip']:.6e}",
    }
