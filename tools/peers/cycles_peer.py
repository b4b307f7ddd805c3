#!/usr/bin/env python3
"""Renders a volume voltex exported (`voltex export SCENE --out DIR --view`) in Blender Cycles
on the CPU, at several sample counts, timing each, and writes one CSV row per render with its
error against a truth image (tools/peers/README.md has the whole run).

    /tmp/bpy-venv/bin/python tools/peers/cycles_peer.py --view DIR/view.json --vdb DIR/box.vdb \
        --truth truth.exr --spp 1,4,16,64 --out OUT [--albedo 0.0] [--threads N]

The VDB is imported as a volume object (`density` is the extinction per world unit: voltex's
export applied the scene's density_scale), its material a Principled Volume with the density
attribute and `albedo` as its colour, or, for albedo 0, a black Volume Absorption (a purely
absorbing medium: every pixel the transmittance times the background). The world is the
background colour; the view's directional lights become suns. The camera is the view's pinhole
(vertical sensor fit), the pixel filter a box of one pixel (each pixel the mean over its area),
denoising and adaptive sampling off. Writes OUT/cycles_<spp>.exr and OUT/cycles.csv."""

import argparse
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402


def setup(bpy, view, vdb, albedo, threads):
    import mathutils

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.cycles.max_bounces = 1024
    scene.cycles.volume_bounces = 1024
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x = view["width"]
    scene.render.resolution_y = view["height"]
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    d = os.path.dirname(os.path.abspath(vdb))
    bpy.ops.object.volume_import(filepath=vdb, directory=d, files=[{"name": os.path.basename(vdb)}])
    obj = bpy.context.selected_objects[0]
    mat = bpy.data.materials.new("voltex")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "density"
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    if albedo == 0.0:
        shader = nt.nodes.new("ShaderNodeVolumeAbsorption")
        shader.inputs["Color"].default_value = (0, 0, 0, 1)
        nt.links.new(attr.outputs["Fac"], shader.inputs["Density"])
    else:
        # Principled Volume: density scales its extinction, colour its scattering albedo.
        shader = nt.nodes.new("ShaderNodeVolumePrincipled")
        shader.inputs["Color"].default_value = (albedo, albedo, albedo, 1)
        shader.inputs["Density"].default_value = 1.0
        shader.inputs["Density Attribute"].default_value = "density"
    nt.links.new(shader.outputs["Volume"], out.inputs["Volume"])
    obj.data.materials.append(mat)
    obj.data.render.space = "WORLD"
    world = bpy.data.worlds.new("background")
    world.use_nodes = True
    bg = view["background"]
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (bg[0], bg[1], bg[2], 1)
    scene.world = world
    for i, light in enumerate(view["lights"]):
        sun = bpy.data.objects.new(f"sun{i}", bpy.data.lights.new(f"sun{i}", "SUN"))
        sun.data.energy = light["intensity"]
        sun.data.color = light["color"]
        sun.data.angle = 0.0
        sun.rotation_euler = mathutils.Vector(light["direction"]).to_track_quat("-Z", "Y").to_euler()
        scene.collection.objects.link(sun)
    cam = view["camera"]
    camera = bpy.data.cameras.new("cam")
    camera.sensor_fit = "VERTICAL"
    camera.angle_y = math.radians(cam["fov_y"])
    cam_obj = bpy.data.objects.new("cam", camera)
    cam_obj.location = cam["eye"]
    forward = mathutils.Vector(cam["target"]) - mathutils.Vector(cam["eye"])
    cam_obj.rotation_euler = forward.to_track_quat("-Z", "Y").to_euler()
    # to_track_quat's "Y" up is the world's Z only for a Z-up view: set the roll from `up`.
    scene.collection.objects.link(cam_obj)
    scene.camera = cam_obj
    return scene


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--view", required=True)
    ap.add_argument("--vdb", required=True)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--spp", default="1,4,16,64")
    ap.add_argument("--albedo", type=float, default=0.0)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--label", default="Cycles")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy

    os.makedirs(args.out, exist_ok=True)
    view = common.load_view(args.view)
    if view["camera"]["up"] != [0.0, 0.0, 1.0]:
        sys.exit("cycles_peer.py places cameras with up = +z only")
    version = f"Blender {bpy.app.version_string} Cycles CPU"
    rows = []
    print(f"{version}, {args.threads} threads, load {common.load_average():.2f}")
    for spp in [int(s) for s in args.spp.split(",")]:
        scene = setup(bpy, view, args.vdb, args.albedo, args.threads)
        scene.cycles.samples = spp
        exr = os.path.abspath(os.path.join(args.out, f"cycles_{spp}.exr"))
        scene.render.filepath = exr
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - start
        m = common.metrics(exr, args.truth)
        setting = f"albedo={args.albedo} step_rate={scene.cycles.volume_step_rate}"
        rows.append(common.row(args.label, setting, spp, seconds, args.threads, version, m))
        print(f"{spp:5d} spp  {seconds:8.3f} s  FLIP {m['flip']:.5f}  RMSE {m['rmse']:.3e}  load {common.load_average():.2f}")
    common.write_csv(os.path.join(args.out, "cycles.csv"), rows)


if __name__ == "__main__":
    main()
