#!/usr/bin/env python3
"""Renders a volume voltex exported (`voltex export SCENE --out DIR --view`) in Mitsuba 3 with
`volpath`, at several sample counts, timing each, and writes one CSV row per render with its
error against a truth image (tools/peers/README.md has the whole run).

    /tmp/peers-venv/bin/python tools/peers/mitsuba_peer.py --view DIR/view.json --vol STEM \
        --truth truth.exr --spp 1,4,16,64 --out OUT [--albedo 0.0] [--max-depth -1] [--threads N]

STEM is what vdb_to_vol.py wrote (STEM.density.vol, STEM.json). The medium is heterogeneous,
sigma_t the grid's density (the extinction per world unit: voltex's export applied the scene's
density_scale), albedo a constant (0: purely absorbing, every pixel the transmittance times the
background), attached to the sensor with no boundary shape (a null-BSDF box around it would
shift every entering ray by Mitsuba's spawn offset and bias the transmittance). Lights: the
view's directional lights and a constant environment of the background colour. The camera is
the view's pinhole (vertical fov), the film a box filter (each pixel the mean over its area).
Writes OUT/mitsuba_<spp>.exr and OUT/mitsuba.csv. Variant scalar_rgb (runs as installed)."""

import argparse
import json
import os
import time

import numpy as np

import common


def scene_dict(mi, view, info, stem, spp, albedo, max_depth):
    cam = view["camera"]
    bg = view["background"]
    medium = {
        "type": "heterogeneous",
        "albedo": albedo,
        "sigma_t": {
            "type": "gridvolume",
            "filename": stem + ".density.vol",
            "to_world": mi.ScalarTransform4f(np.array(info["to_world"])),
            "filter_type": "trilinear",
        },
        "scale": 1.0,
        # A grey extinction: with the default (spectral) the free-flight estimate of a ray that
        # leaves the grid's box is weighted by the majorant's transmittance to infinity, 0.
        "has_spectral_extinction": False,
    }
    d = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["fov_y"],
            "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["target"], up=cam["up"]),
            "film": {
                "type": "hdrfilm",
                "width": view["width"],
                "height": view["height"],
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp},
            "medium": medium,
        },
        "env": {"type": "constant", "radiance": {"type": "rgb", "value": bg}},
    }
    for i, light in enumerate(view["lights"]):
        c = [x * light["intensity"] for x in light["color"]]
        d[f"sun{i}"] = {"type": "directional", "direction": light["direction"], "irradiance": {"type": "rgb", "value": c}}
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--view", required=True)
    ap.add_argument("--vol", required=True, help="the stem vdb_to_vol.py wrote")
    ap.add_argument("--truth", help="the truth image (without it: renders only, no CSV)")
    ap.add_argument("--spp", default="1,4,16,64")
    ap.add_argument("--albedo", type=float, default=0.0)
    ap.add_argument("--max-depth", type=int, default=-1)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--label", default="Mitsuba volpath")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import mitsuba as mi

    import drjit as dr

    mi.set_variant("scalar_rgb")
    dr.set_thread_count(args.threads)
    mi.set_log_level(mi.LogLevel.Warn)
    os.makedirs(args.out, exist_ok=True)
    view = common.load_view(args.view)
    with open(args.vol + ".json") as f:
        info = json.load(f)
    version = f"Mitsuba {mi.__version__} scalar_rgb"
    rows = []
    print(f"{version}, {args.threads} threads, load {common.load_average():.2f}")
    for spp in [int(s) for s in args.spp.split(",")]:
        scene = mi.load_dict(scene_dict(mi, view, info, args.vol, spp, args.albedo, args.max_depth))
        start = time.perf_counter()
        image = mi.render(scene, spp=spp)
        seconds = time.perf_counter() - start
        exr = os.path.join(args.out, f"mitsuba_{spp}.exr")
        mi.Bitmap(image).write(exr)
        if not args.truth:
            print(f"{spp:5d} spp  {seconds:8.3f} s  -> {exr}")
            continue
        m = common.metrics(exr, args.truth)
        setting = f"albedo={args.albedo} max_depth={args.max_depth}"
        rows.append(common.row(args.label, setting, spp, seconds, args.threads, version, m))
        print(f"{spp:5d} spp  {seconds:8.3f} s  FLIP {m['flip']:.5f}  RMSE {m['rmse']:.3e}  load {common.load_average():.2f}")
    if rows:
        common.write_csv(os.path.join(args.out, "mitsuba.csv"), rows)


if __name__ == "__main__":
    main()
