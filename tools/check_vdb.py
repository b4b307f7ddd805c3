#!/usr/bin/env python3
"""Checks `voltex export` with the OpenVDB library itself, and renders an export in Blender Cycles.

Not part of the CI suite: it needs Blender as a Python module (`pip install bpy numpy`, Blender
5.0, ~400 MB), which bundles OpenVDB 12's `openvdb` module and OpenImageIO.

    python3 tools/check_vdb.py [--voltex target/release/voltex] [--out out/check_vdb] [SCENE ...]

For every scene (default: a texel scene, a curved-shell scene and a hypertexture scene) it runs
`voltex export` twice (zip and uncompressed) and, for every file:
  1. loads it with `openvdb.readAll` and checks the grids (`density` a FloatGrid of class fog
     volume, `Cd` a Vec3SGrid active at least where density is (texels and hypertextures: at the
     same voxels; volume nodes: also one voxel beyond each leaf), finite, density >= 0);
  2. compares every voxel of the zip and the uncompressed file (two code paths of the writer,
     read by OpenVDB) and, where `voltex bake --unlit --depth 32` can write the same texel as float slices,
     every voxel against those slices converted here (density = -ln(1 - alpha) / opacity length,
     Cd = colour / alpha);
  3. for the analytic `flat_box` (a constant fog box, opacity 0.5 over 0.5 world units, 0.5 high)
     checks the density (ln 2 / 0.5 everywhere), then renders its VDB in Cycles looking straight
     down through it with a black absorbing volume over a white background: the transmittance
     must be exp(-ln 2) = 0.5, which checks the extinction convention in a renderer that is not
     ours. Writes flat_box_cycles.exr / .png;
  4. renders the first scene's first export lit by a sun, Cd as the colour: OUT/cycles.png.
Prints one line per check and exits 1 if any failed.
"""

import argparse
import glob
import json
import math
import os
import subprocess
import sys

import numpy as np


def bundled_modules():
    """Blender's bundled site-packages (openvdb, OpenImageIO) onto sys.path."""
    import importlib.util

    base = os.path.dirname(importlib.util.find_spec("bpy").origin)
    for sp in glob.glob(os.path.join(base, "*", "python", "lib", "python3.*", "site-packages")):
        sys.path.insert(0, sp)


FAILED = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        FAILED.append(what)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    return r.stdout


def dense(grid, bbox):
    """The grid's values over bbox (inclusive index box) as an array [x, y, z, ...]."""
    (lo, hi) = bbox
    shape = tuple(h - l + 1 for l, h in zip(lo, hi))
    if grid.__class__.__name__ == "Vec3SGrid":
        shape = shape + (3,)
    a = np.zeros(shape, dtype=np.float32)
    grid.copyToArray(a, ijk=lo)
    return a


def active(grid, bbox):
    (lo, hi) = bbox
    m = np.zeros(tuple(h - l + 1 for l, h in zip(lo, hi)), dtype=bool)
    for item in grid.citerOnValues():
        if item.count != 1:
            continue  # voltex writes no tiles
        x, y, z = (c - l for c, l in zip(item.min, lo))
        if all(0 <= v < s for v, s in zip((x, y, z), m.shape)):
            m[x, y, z] = True
    return m


def read(vdb, path):
    grids, _meta = vdb.readAll(path)
    return {g.name: g for g in grids}


def check_file(vdb, path, plain):
    name = os.path.basename(path)
    g = read(vdb, path)
    check(sorted(g) == ["Cd", "density"], f"{name}: grids {sorted(g)}")
    d, c = g["density"], g["Cd"]
    check(type(d).__name__ == "FloatGrid" and d.gridClass == vdb.GridClass.FOG_VOLUME, f"{name}: density is a fog-volume FloatGrid")
    check(type(c).__name__ == "Vec3SGrid", f"{name}: Cd is a Vec3SGrid")
    bbox = d.evalActiveVoxelBoundingBox()
    n = d.activeVoxelCount()
    dv, cv, mask = dense(d, bbox), dense(c, bbox), active(d, bbox)
    covered = (active(c, bbox) | ~mask).all()
    check(covered and n <= c.activeVoxelCount(), f"{name}: Cd active at the {n} active voxels of density ({c.activeVoxelCount()} in all)")
    check(mask.sum() == n and np.isfinite(dv).all() and (dv[mask] > 0).all(), f"{name}: densities finite and positive where active")
    p = read(vdb, plain)
    same = all(np.array_equal(dense(p[k], bbox), v) for k, v in (("density", dv), ("Cd", cv)))
    same = same and p["density"].activeVoxelCount() == n
    check(same, f"{name}: zip and uncompressed files hold the same voxels")
    m = d.transform.indexToWorld((0, 0, 0)), d.transform.indexToWorld((1, 1, 1))
    return {"density": dv, "Cd": cv, "mask": mask, "bbox": bbox, "transform": d.transform, "corner": m}


def compare_with_slices(oiio, data, slices_dir, manifest, name):
    """Every active voxel against `voltex bake --unlit --depth 32` float slices (OpenImageIO reads them)."""
    res = manifest["resolution"]
    L = manifest["opacity_length"]
    vol = np.zeros((res[0], res[1], res[2], 4), dtype=np.float64)
    for z in range(res[2]):
        f = os.path.join(slices_dir, manifest["slices"][z])
        img = oiio.ImageBuf(f).get_pixels(oiio.FLOAT)  # [rows (t = 1 first), s, channels]
        vol[:, :, z, :] = np.transpose(img[::-1, :, :4], (1, 0, 2))
    a = vol[..., 3]
    if manifest["premultiplied"]:
        rgb = vol[..., :3] / np.where(a > 0, a, 1)[..., None]
    else:
        rgb = vol[..., :3]
    (lo, hi) = data["bbox"]
    sub = tuple(slice(l, h + 1) for l, h in zip(lo, hi))
    a, rgb = a[sub], rgb[sub]
    mask = data["mask"]
    check(np.array_equal(mask, a > 0), f"{name}: active voxels are those with alpha > 0 in the slices")
    expect = -np.log1p(-np.minimum(a, 1 - 2**-20)) / L
    ok = (a < 1 - 2**-20) & mask
    err = np.abs(data["density"][ok] - expect[ok]) / np.maximum(expect[ok], 1e-6)
    check(err.size == 0 or err.max() < 1e-4, f"{name}: density = -ln(1 - alpha) / L (largest relative error {err.max() if err.size else 0:.2e})")
    cerr = np.abs(data["Cd"][mask] - rgb[mask]).max() if mask.any() else 0.0
    check(cerr < 1e-4, f"{name}: Cd = colour / alpha (largest error {cerr:.2e})")


def cycles_scene(bpy, vdb_path, resolution, samples):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.render.resolution_x = scene.render.resolution_y = resolution
    scene.view_settings.view_transform = "Standard"
    d = os.path.dirname(os.path.abspath(vdb_path))
    bpy.ops.object.volume_import(filepath=vdb_path, directory=d, files=[{"name": os.path.basename(vdb_path)}])
    return scene, bpy.context.selected_objects[0]


def render(bpy, scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def flat_box_transmittance(bpy, oiio, vdb_path, out):
    """Ortho camera looking down through the fog box; black absorbing volume; white world."""
    scene, obj = cycles_scene(bpy, vdb_path, 32, 16)
    mat = bpy.data.materials.new("absorb")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    absorb = nt.nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0, 0, 0, 1)
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "density"
    nt.links.new(attr.outputs["Fac"], absorb.inputs["Density"])
    outn = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(absorb.outputs["Volume"], outn.inputs["Volume"])
    obj.data.materials.append(mat)
    obj.data.render.space = "WORLD"
    obj.data.render.step_size = 0.001
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.world = world
    cam = bpy.data.cameras.new("cam")
    cam.type = "ORTHO"
    cam.ortho_scale = 1.0  # the middle of the 2 x 2 box
    cam_obj = bpy.data.objects.new("cam", cam)
    cam_obj.location = (0, 0, 3)
    scene.collection.objects.link(cam_obj)
    scene.camera = cam_obj
    scene.render.image_settings.file_format = "OPEN_EXR"
    exr = os.path.join(out, "flat_box_cycles.exr")
    render(bpy, scene, exr)
    scene.render.image_settings.file_format = "PNG"
    render(bpy, scene, os.path.join(out, "flat_box_cycles.png"))
    px = oiio.ImageBuf(exr).get_pixels(oiio.FLOAT)[..., :3]
    mean = float(px.mean())
    check(abs(mean - 0.5) < 0.01, f"flat_box in Cycles: transmittance {mean:.4f} (expected exp(-ln 2) = 0.5)")
    return mean


def pretty(bpy, vdb_path, out):
    """The export lit by a sun, Cd as the colour, from a camera framing the grid's box."""
    scene, obj = cycles_scene(bpy, vdb_path, 256, 32)
    mat = bpy.data.materials.new("vol")
    mat.use_nodes = True
    nt = mat.node_tree
    pv = nt.nodes["Principled Volume"] if "Principled Volume" in nt.nodes else nt.nodes.new("ShaderNodeVolumePrincipled")
    for n in list(nt.nodes):
        if n.type not in ("OUTPUT_MATERIAL",) and n != pv:
            nt.nodes.remove(n)
    pv.inputs["Color Attribute"].default_value = "Cd"
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Density"].default_value = 1.0
    outn = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(pv.outputs["Volume"], outn.inputs["Volume"])
    obj.data.materials.append(mat)
    obj.data.render.space = "WORLD"
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("grey")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.15, 0.17, 0.2, 1)
    scene.world = world
    bpy.context.view_layer.update()
    corners = [obj.matrix_world @ __import__("mathutils").Vector(c) for c in obj.bound_box]
    centre = sum(corners, __import__("mathutils").Vector()) / 8
    size = max((c - centre).length for c in corners)
    cam_obj = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam_obj.location = centre + __import__("mathutils").Vector((0.0, -2.6, 1.6)) * size
    cam_obj.rotation_euler = (centre - cam_obj.location).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(cam_obj)
    scene.camera = cam_obj
    scene.render.image_settings.file_format = "PNG"
    png = os.path.join(out, "cycles.png")
    render(bpy, scene, png)
    check(os.path.getsize(png) > 1000, f"Cycles rendered {vdb_path} to {png}")


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--voltex", default=os.path.join(root, "target", "release", "voltex"))
    ap.add_argument("--out", default=os.path.join(root, "out", "check_vdb"))
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args()
    scenes = args.scenes or [
        os.path.join(root, "scenes/view_slices/torus_egg.ron"),
        os.path.join(root, "scenes/view_slices/flat_box.ron"),
        os.path.join(root, "scenes/hypertextures/fig6_clouds.ron"),
    ]
    bundled_modules()
    import bpy
    import openvdb as vdb
    import OpenImageIO as oiio

    print(f"Blender {bpy.app.version_string}, OpenVDB {'.'.join(map(str, vdb.LIBRARY_VERSION))}, OpenImageIO {oiio.VERSION_STRING}")
    os.makedirs(args.out, exist_ok=True)
    first = None
    for s in scenes:
        stem = os.path.splitext(os.path.basename(s))[0]
        zip_dir, plain_dir = os.path.join(args.out, stem, "zip"), os.path.join(args.out, stem, "none")
        print(run([args.voltex, "export", s, "--out", zip_dir, "--resolution", "64"]).rstrip())
        run([args.voltex, "export", s, "--out", plain_dir, "--resolution", "64", "--compression", "none"])
        for f in sorted(glob.glob(os.path.join(zip_dir, "*.vdb"))):
            data = check_file(vdb, f, os.path.join(plain_dir, os.path.basename(f)))
            first = first or f
            texel = os.path.splitext(os.path.basename(f))[0]
            slices = os.path.join(args.out, stem, "slices")
            bake = subprocess.run(
                [args.voltex, "bake", s, "--texel", texel, "--out", slices, "--unlit", "--depth", "32"], capture_output=True, text=True
            )
            if bake.returncode == 0:
                with open(os.path.join(slices, texel, "manifest.json")) as m:
                    compare_with_slices(oiio, data, os.path.join(slices, texel), json.load(m), os.path.basename(f))
            if stem == "flat_box":
                want = math.log(2) / 0.5
                dv = data["density"][data["mask"]]
                check(np.abs(dv - want).max() < 1e-5 * want, f"flat_box: density ln 2 / 0.5 = {want:.6f} everywhere")
                flat_box_transmittance(bpy, oiio, f, args.out)
    if first:
        pretty(bpy, first, args.out)
    print(f"{len(FAILED)} failed" if FAILED else "all checks passed")
    sys.exit(1 if FAILED else 0)


if __name__ == "__main__":
    main()
