#!/usr/bin/env python3
"""Checks that a refactor changes no image: renders every example scene with two voltex
binaries (`regress DIR --no-truth`, each into its own folder) and compares the pixels of each
scene's `actual.exr` exactly (every channel, bit for bit).

    tools/same_images.py OLD_BINARY NEW_BINARY [SCENE_DIR] [--out FOLDER]

Build the old binary from a worktree of the commit before the change, e.g.
    git worktree add /tmp/old HEAD~1 && (cd /tmp/old && cargo build --release)
Exit status 0 when every scene is bit-identical (and both runs rendered the same scenes).
Needs numpy and the OpenEXR module (pip)."""

import argparse
import os
import subprocess
import sys

import numpy as np
import OpenEXR


def render(binary, scenes, out):
    # regress exits non-zero when a scene fails its reference; the images are written anyway.
    subprocess.run([binary, "regress", scenes, "--no-truth", "--jobs", "2", "--out", out],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)


def images(out):
    found = {}
    for folder, _, files in os.walk(out):
        if "actual.exr" in files:
            found[os.path.relpath(folder, out)] = os.path.join(folder, "actual.exr")
    return found


def pixels(path):
    with OpenEXR.File(path) as f:
        return {name: np.array(ch.pixels) for name, ch in f.channels().items()}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("scenes", nargs="?", default="scenes")
    p.add_argument("--out", default="out/same_images")
    a = p.parse_args()
    runs = {}
    for tag, binary in (("old", a.old), ("new", a.new)):
        out = os.path.join(a.out, tag)
        render(os.path.abspath(binary), a.scenes, out)
        runs[tag] = images(out)
    old, new = runs["old"], runs["new"]
    missing = sorted(set(old) ^ set(new))
    differ = []
    for scene in sorted(set(old) & set(new)):
        a_px, b_px = pixels(old[scene]), pixels(new[scene])
        same = a_px.keys() == b_px.keys() and all(
            a_px[c].shape == b_px[c].shape and a_px[c].tobytes() == b_px[c].tobytes() for c in a_px)
        if not same:
            diff = max((float(np.nanmax(np.abs(a_px[c] - b_px[c]))) for c in a_px if c in b_px
                        and a_px[c].shape == b_px[c].shape), default=float("inf"))
            differ.append(f"{scene}: largest difference {diff:.3g}")
    print(f"{len(set(old) & set(new)) - len(differ)} scenes bit-identical, {len(differ)} differ, "
          f"{len(missing)} rendered by one binary only")
    for line in differ + [f"{s}: rendered by one binary only" for s in missing]:
        print("  " + line)
    sys.exit(1 if differ or missing else 0)


if __name__ == "__main__":
    main()
