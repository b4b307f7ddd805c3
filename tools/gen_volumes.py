#!/usr/bin/env python3
"""Writes the OpenVDB files of scenes/volumes/ and the bad inputs of tests/vdb/ with the OpenVDB
library itself (version 12, as bundled by Blender's `bpy` wheel), so that voltex reads files as
Houdini, Blender and EmberGen write them. Nothing is downloaded but the wheel.

    python3 -m venv /tmp/bpy && /tmp/bpy/bin/pip install bpy numpy
    /tmp/bpy/bin/python tools/gen_volumes.py [examples|bad|paper2002 ...]   # default: all

Conventions (OpenVDB's): voxel (i, j, k) sits at index point (i, j, k), mapped to world space by
the grid's transform; a fog volume's values are densities (0 = empty, the background); a level
set stores signed distances in world units (negative inside), active in a narrow band.
`copyFromArray` reads the array's raw buffer: arrays are made C-contiguous with index [i, j, k].
"""

import glob
import os
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
# bpy bundles the openvdb module in its own Python tree.
for p in glob.glob(os.path.join(sys.prefix, "lib/python3*/site-packages/bpy/*/python/lib/python3*/site-packages")):
    sys.path.insert(0, p)
import openvdb as vdb  # noqa: E402

SCENES = os.path.join(root, "scenes", "volumes")
BAD = os.path.join(root, "tests", "vdb")


def transform(voxel, origin=(0.0, 0.0, 0.0)):
    """Uniform voxel size `voxel`; index (0, 0, 0) at world `origin`."""
    t = vdb.createLinearTransform(voxelSize=voxel)
    t.postTranslate(origin)
    return t


def fog(name, array, t, tolerance=0.0, half=False):
    """A fog volume from a C-contiguous float array indexed [i, j, k] (voxel (0, 0, 0) first)."""
    g = vdb.FloatGrid()
    g.copyFromArray(np.ascontiguousarray(array, dtype=np.float32), tolerance=tolerance)
    g.name = name
    g.transform = t
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.saveFloatAsHalf = half
    return g


def color(name, rgb, t, half=True):
    """A vec3 grid (Houdini's `Cd`) from an array [i, j, k, 3]."""
    g = vdb.Vec3SGrid()
    g.copyFromArray(np.ascontiguousarray(rgb, dtype=np.float32))
    g.name = name
    g.transform = t
    g.saveFloatAsHalf = half
    return g


def grid_coords(n):
    """Index coordinates of an n^3 block, each in [-1, 1] at the block's faces."""
    i = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    return np.meshgrid(i, i, i, indexing="ij")


def blob(n, seed):
    """A soft noisy blob: density in [0, 1], 0 beyond the unit ball."""
    x, y, z = grid_coords(n)
    r = np.sqrt(x * x + y * y + z * z)
    rng = np.random.default_rng(seed)
    wobble = sum(
        a * np.sin(f[0] * x + f[1] * y + f[2] * z + p)
        for a, f, p in [(0.12, rng.normal(0, 4, 3), rng.uniform(0, 6.3)) for _ in range(4)]
    )
    d = np.clip(1.0 - (r + wobble) / 0.8, 0.0, 1.0)
    return np.where(r < 0.95, d, 0.0) ** 0.7


def write(path, grids):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    vdb.write(path, grids=grids)
    print(f"{os.path.relpath(path, root)}: {os.path.getsize(path)} bytes, grids "
          + ", ".join(f"{g.name} ({g.valueTypeName}, {g.activeVoxelCount()} active)" for g in grids))


def examples():
    # The analytic case: a 16^3 box of constant density 1 (tiles after pruning), voxel 1/16,
    # centred on the origin: index (0, 0, 0) at -15/32, so voxel centres lie at the cells of
    # [-1/2, 1/2]^3 (cell-centred data on a unit cube needs the half-voxel translation).
    n = 16
    box_t = transform(1.0 / n, (-0.5 + 0.5 / n,) * 3)
    box = fog("density", np.ones((n, n, n)), box_t, tolerance=1e-6)  # eight 8^3 tiles, no leaves
    # A second, non-constant analytic density on the same box: 0.25 + 1.5 x' (x' in [0, 1]
    # along i at the voxel centres), linear, so its trilinear interpolant is exact.
    ramp = 0.25 + 1.5 * (np.arange(n) + 0.5)[:, None, None] / n * np.ones((1, n, n))
    write(os.path.join(SCENES, "box.vdb"), [box, fog("ramp", ramp, box_t)])

    # A fog blob with Houdini's `Cd`: 32^3 voxels of 1/16 (half-precision colour).
    n = 32
    t = transform(1.0 / 16, (-1.0 + 0.5 / 16,) * 3)
    d = blob(n, 3)
    x, y, z = grid_coords(n)
    rgb = np.stack([0.6 + 0.4 * x, 0.55 + 0.35 * z, 0.9 - 0.5 * (x + 1) / 2], axis=-1)
    write(os.path.join(SCENES, "smoke.vdb"), [fog("density", d, t, tolerance=1e-4), color("Cd", rgb * (d > 0)[..., None], t)])

    # A narrow-band level set: a sphere of radius 0.8, voxel 0.08, half width 3 voxels.
    ls = vdb.createLevelSetSphere(radius=0.8, center=(0.0, 0.0, 0.0), voxelSize=0.08, halfWidth=3.0)
    ls.name = "surface"
    ls.saveFloatAsHalf = True
    write(os.path.join(SCENES, "sphere_level_set.vdb"), [ls])

    # Several grids in one file: density, temperature and Cd (chosen by name in the scene).
    n = 24
    t = transform(1.0 / 12, (-1.0 + 0.5 / 12,) * 3)
    d = blob(n, 7)
    x, y, z = grid_coords(n)
    temperature = np.clip(d * (1.0 - z) * 0.8, 0, None)
    rgb = np.stack([np.ones_like(x), 0.3 + 0.35 * (z + 1), 0.2 + 0.2 * (y + 1)], axis=-1)
    write(os.path.join(SCENES, "several_grids.vdb"), [
        fog("density", d, t, tolerance=1e-4),
        fog("temperature", temperature, t, tolerance=1e-4),
        color("Cd", rgb * (d > 0)[..., None], t),
    ])

    # The sparse case: two 16^3 blobs 1000 voxels apart along the diagonal (a dense grid over
    # their bounds would be 1016^3 voxels). Both blobs into one grid through an accessor.
    g = fog("density", blob(16, 11), transform(0.01))
    other = fog("density", blob(16, 12), transform(0.01))
    acc = g.getAccessor()
    for (i, j, k), v in _active(other):
        acc.setValueOn((i + 1000, j + 1000, k + 1000), v)
    write(os.path.join(SCENES, "far_apart.vdb"), [g])

    # A half-precision fog (`saveFloatAsHalf`), rotated and scaled: an AffineMap transform.
    n = 24
    t = vdb.createLinearTransform(voxelSize=1.0 / 12)
    t.postRotate(0.5, vdb.Axis.Z)
    t.postTranslate((0.2, -0.1, 0.0))
    write(os.path.join(SCENES, "half_rotated.vdb"), [fog("density", blob(n, 5), t, tolerance=1e-4, half=True)])


def _active(grid):
    for it in grid.citerOnValues():
        if it.count == 1:
            yield it.min, it.value
        else:  # a tile: every voxel of it
            lo, hi = it.min, it.max
            for i in range(lo[0], hi[0] + 1):
                for j in range(lo[1], hi[1] + 1):
                    for k in range(lo[2], hi[2] + 1):
                        yield (i, j, k), it.value


def bad():
    t = transform(0.1)
    small = np.zeros((8, 8, 8), dtype=np.float32)
    small[2:6, 2:6, 2:6] = 1.0
    ints = vdb.Int32Grid()
    ints.copyFromArray(np.ascontiguousarray(small.astype(np.int32)))
    ints.name = "density"
    write(os.path.join(BAD, "int.vdb"), [ints])
    bools = vdb.BoolGrid()
    bools.copyFromArray(np.ascontiguousarray(small > 0))
    bools.name = "density"
    write(os.path.join(BAD, "bool.vdb"), [bools])
    points = vdb.PointDataGrid()
    points.name = "points"
    write(os.path.join(BAD, "points.vdb"), [points])
    nan = fog("density", small, t)
    nan.getAccessor().setValueOn((3, 3, 3), float("nan"))
    write(os.path.join(BAD, "nan.vdb"), [nan])
    empty = vdb.FloatGrid()
    empty.name = "density"
    write(os.path.join(BAD, "empty.vdb"), [empty])
    # Absurd index extents: two voxels 2^30 apart on every axis.
    far = vdb.FloatGrid()
    far.name = "density"
    acc = far.getAccessor()
    acc.setValueOn((-(1 << 29), -(1 << 29), -(1 << 29)), 1.0)
    acc.setValueOn(((1 << 29), (1 << 29), (1 << 29)), 1.0)
    write(os.path.join(BAD, "absurd_extents.vdb"), [far])
    # A frustum transform (nonlinear: voltex reads linear transforms only).
    frustum = fog("density", small, vdb.createFrustumTransform(xyzMin=(0, 0, 0), xyzMax=(8, 8, 8), taper=0.5, depth=1.0))
    write(os.path.join(BAD, "frustum.vdb"), [frustum])


# The 2002 slicing paper's external data sets (Figures 9, 11 and 12) are 128^3 volumes we do not
# have; these look-alikes are built from simple shapes with the same make-up (opaque parts,
# semi-transparent parts, empty space) and written to scenes/view_slices/. World space is the unit
# cube (voxel 1/128, z up), which the scenes map onto a texel with `bounds: ((0,0,0), (1,1,1))`.
N2002 = 128


def unit_coords(n=N2002):
    c = (np.arange(n) + 0.5) / n
    return np.meshgrid(c, c, c, indexing="ij")


def solid(distance, n=N2002):
    """An opaque solid from a signed distance (negative inside): density 1 inside, a one-voxel
    ramp across the surface (antialiased slices), 0 outside."""
    return np.clip(0.5 - distance * n, 0.0, 1.0)


def torus_distance(p, centre, axis, major, minor):
    """Signed distance to a torus around `axis` (a unit vector) through `centre`."""
    q = [p[i] - centre[i] for i in range(3)]
    along = sum(q[i] * axis[i] for i in range(3))
    radial = np.sqrt(np.maximum(sum(q[i] * q[i] for i in range(3)) - along * along, 0.0))
    return np.sqrt((radial - major) ** 2 + along ** 2) - minor


def box_distance(p, lo, hi):
    """Signed distance to an axis-aligned box (exact outside, max-norm inside)."""
    c = [(lo[i] + hi[i]) / 2 for i in range(3)]
    h = [(hi[i] - lo[i]) / 2 for i in range(3)]
    q = [np.abs(p[i] - c[i]) - h[i] for i in range(3)]
    outside = np.sqrt(sum(np.maximum(q[i], 0.0) ** 2 for i in range(3)))
    inside = np.minimum(np.maximum(np.maximum(q[0], q[1]), q[2]), 0.0)
    return outside + inside


def painted(parts, n=N2002):
    """Density and Cd from (density, rgb) parts; where parts overlap the densest one paints."""
    density = np.zeros((n, n, n))
    rgb = np.zeros((n, n, n, 3))
    for d, c in parts:
        mask = d > density
        density = np.where(mask, d, density)
        rgb[mask] = np.broadcast_to(np.asarray(c, dtype=float), rgb.shape)[mask]
    return density, rgb


def paper2002():
    t = transform(1.0 / N2002, (0.5 / N2002,) * 3)
    x, y, z = unit_coords()
    p = (x, y, z)
    out = os.path.join(root, "scenes", "view_slices")

    # Figure 9: two interlocked chain links, opaque: one ring standing in the xz plane, one lying
    # in the xy plane through it.
    links = [
        (solid(torus_distance(p, (0.38, 0.5, 0.5), (0, 1, 0), 0.2, 0.065)), (0.75, 0.76, 0.8)),
        (solid(torus_distance(p, (0.62, 0.5, 0.5), (0, 0, 1), 0.2, 0.065)), (0.85, 0.62, 0.3)),
    ]
    d, rgb = painted(links)
    write(os.path.join(out, "fig9_chain.vdb"), [fog("density", d, t, tolerance=1e-3, half=True), color("Cd", rgb, t)])

    # Figure 11: an opaque volcano with a crater on an opaque floor, two semi-transparent smoke
    # rings above it, empty space around.
    rho = np.sqrt((x - 0.5) ** 2 + (y - 0.5) ** 2)
    cone = np.minimum(0.58 - 1.2 * rho, 0.42 + 1.5 * np.maximum(rho - 0.1, 0.0) * (rho > 0.1))
    height = np.maximum(np.where(rho < 0.1, 0.42 - 0.5 * (0.1 - rho), cone), 0.06)
    ground = solid(z - height)
    rock = (0.32, 0.26, 0.22) * np.ones_like(x)[..., None]
    lava = np.clip((z - 0.3) / 0.15, 0, 1) * (rho < 0.16)
    rock_rgb = rock * (1 - lava[..., None]) + np.array([0.9, 0.35, 0.1]) * lava[..., None]
    grass = (z < 0.075)[..., None] * np.array([0.25, 0.45, 0.2])
    ground_rgb = np.where((z < 0.075)[..., None], grass, rock_rgb)
    rings = sum(
        a * np.exp(-(torus_distance(p, (0.5, 0.5, h), (0, 0, 1), r, 0.0) / w) ** 2)
        for h, r, w, a in [(0.66, 0.1, 0.035, 0.008), (0.8, 0.15, 0.04, 0.006), (0.92, 0.2, 0.04, 0.004)]
    )
    density = np.where(ground > 0, ground, np.where(rings > 2e-4, rings, 0.0))
    rgb = np.where((ground > 0)[..., None], ground_rgb, np.array([0.85, 0.85, 0.88]))
    rgb = rgb * (density > 0)[..., None]
    write(os.path.join(out, "fig11_volcano.vdb"), [fog("density", density, t, tolerance=1e-4, half=True), color("Cd", rgb, t)])

    # Figure 12: a car park: a ground plane with painted bays, two rows of cars (a body and a
    # cabin each) and trees (a trunk and a round crown), all opaque.
    bays = ((np.abs((x * 8) % 1.0 - 0.5) > 0.47) & (np.abs(y - 0.5) > 0.08)).astype(float)
    ground_rgb = np.array([0.25, 0.25, 0.27]) * (1 - bays[..., None]) + np.array([0.9, 0.9, 0.85]) * bays[..., None]
    parts = [(solid(z - 0.04), ground_rgb)]
    colours = [(0.8, 0.1, 0.1), (0.1, 0.3, 0.8), (0.9, 0.85, 0.8), (0.15, 0.55, 0.2), (0.9, 0.7, 0.1), (0.2, 0.2, 0.22)]
    k = 0
    for row, cy in [(0, 0.28), (1, 0.72)]:
        for bay in range(1, 7):
            if (row, bay) in [(0, 3), (1, 5)]:
                continue  # empty bays
            cx = (bay + 0.5) / 8
            c = colours[k % len(colours)]
            k += 1
            parts.append((solid(box_distance(p, (cx - 0.045, cy - 0.1, 0.045), (cx + 0.045, cy + 0.1, 0.1))), c))
            parts.append((solid(box_distance(p, (cx - 0.04, cy - 0.05, 0.1), (cx + 0.04, cy + 0.04, 0.14))), (0.15, 0.2, 0.25)))
    for tx, ty in [(0.06, 0.08), (0.94, 0.08), (0.06, 0.92), (0.94, 0.92), (0.5, 0.5)]:
        trunk = np.sqrt((x - tx) ** 2 + (y - ty) ** 2) - 0.012
        parts.append((solid(np.maximum(trunk, z - 0.25)), (0.35, 0.22, 0.1)))
        crown = np.sqrt((x - tx) ** 2 + (y - ty) ** 2 + ((z - 0.3) / 1.3) ** 2) - 0.07
        parts.append((solid(crown), (0.12, 0.42, 0.15)))
    d, rgb = painted(parts)
    write(os.path.join(out, "fig12_car_park.vdb"), [fog("density", d, t, tolerance=1e-3, half=True), color("Cd", rgb, t)])


def varied_density(x, y, z):
    """The density of varied.vdb at world points (x, y, z) of the unit cube, in f64: six decades
    in one grid. tests/gpu/volume_exact.rs computes the same formula in Rust (its f32 values
    must equal the file's), so keep the two alike."""
    # A dense ring (40 per unit, a soft edge of 3 voxels) around the z axis through the centre.
    rad = np.sqrt((x - 0.5) ** 2 + (y - 0.5) ** 2)
    ring = 40.0 * np.clip(0.5 - (np.sqrt((rad - 0.3) ** 2 + (z - 0.5) ** 2) - 0.09) * 128.0 / 3.0, 0.0, 1.0)
    # A thin egg inside it, its density varying smoothly over three decades (1e-2 to 10).
    e = np.sqrt(((x - 0.5) / 0.17) ** 2 + ((y - 0.5) / 0.17) ** 2 + ((z - 0.5) / 0.28) ** 2) - 1.0
    egg = np.clip(-4.0 * e, 0.0, 1.0) * 10.0 ** (-2.0 + 3.0 * (0.5 + 0.5 * np.sin(9.0 * x + 2.0) * np.sin(7.0 * y) * np.cos(5.0 * z)))
    # A hot core in the egg, up to 2000.
    h = ((x - 0.5) ** 2 + (y - 0.5) ** 2 + (z - 0.7) ** 2) / 0.03 ** 2
    core = 2000.0 * np.clip(1.0 - h, 0.0, 1.0)
    # A faint haze (0.02 to 0.22) in a slab under the ring, edges mid-leaf.
    slab = (z < 0.25) & (x > 0.1) & (x < 0.9) & (y > 0.1) & (y < 0.9)
    haze = np.where(slab, 0.02 + 0.2 * (0.5 + 0.5 * np.sin(23.0 * x) * np.cos(19.0 * y)), 0.0)
    return np.maximum(np.maximum(ring, egg), core) + haze


def varied():
    # The exactness check's volume (issue: optical depth on varied data, not a constant box):
    # 128^3 voxels cell-centred on the unit cube (voxel 1/128), densities from 1e-5 to 2000, thin
    # and dense parts, empty leaves, uniform leaves (tiles) inside the ring, full-precision floats.
    n = 128
    c = (np.arange(n) + 0.5) / n
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    d = varied_density(x, y, z).astype(np.float32)
    g = fog("density", d, transform(1.0 / n, (0.5 / n,) * 3))
    path = os.path.join(SCENES, "varied.vdb")
    write(path, [g])
    # OpenVDB reads back exactly the array it was given.
    back = np.zeros_like(d)
    vdb.read(path, "density").copyToArray(back, ijk=(0, 0, 0))
    assert np.array_equal(back, d), "varied.vdb does not read back as written"
    print(f"{path}: densities {d[d > 0].min():.3g} to {d.max():.4g}, {np.count_nonzero(d)} non-zero voxels")


if __name__ == "__main__":
    # Arguments name the sets to write (default all): examples, varied, bad, paper2002.
    sets = {"examples": examples, "varied": varied, "bad": bad, "paper2002": paper2002}
    for name in sys.argv[1:] or list(sets):
        sets[name]()
