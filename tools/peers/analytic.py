#!/usr/bin/env python3
"""The exact transmittance image of an absorbing volume, in f64, independent of voltex's GPU code:
the check that the truth `run.sh` uses (voltex's Reference) is what it claims to be.

    /tmp/bpy-venv/bin/python tools/peers/analytic.py --view DIR/view.json --vdb DIR/box.vdb \
        --out analytic.exr [--supersample N]

For every pixel (N x N rays through sub-pixel centres, averaged; 1: the pixel centre, as voltex's
renders without --supersample) the ray is cut where an index coordinate crosses a voxel centre.
Between cuts the trilinear interpolant of the `density` grid (OpenVDB's: voxel (i, j, k) at index
point (i, j, k), 0 beyond one voxel past the active ones) is a cubic in the ray parameter, so
Simpson's rule on each piece is exact: the optical depth is exact up to f64 rounding. The pixel
is the background times exp(-depth). Any grid and transform (no separability assumed); the
camera is view.json's pinhole, as voltex casts it. Writes an RGBA float EXR (OpenImageIO from
Blender's bundle)."""

import argparse
import json

import numpy as np

import common


def density(a, lo, p):
    """Trilinear interpolant at index points p [..., 3]."""
    q = p - lo
    c = np.floor(q)
    f = q - c
    c = c.astype(np.int64)
    out = np.zeros(p.shape[:-1])
    n = np.array(a.shape)
    for corner in range(8):
        d = np.array([corner & 1, corner >> 1 & 1, corner >> 2 & 1])
        idx = np.clip(c + d, 0, n - 1)
        w = np.prod(np.where(d == 1, f, 1.0 - f), axis=-1)
        out += w * a[idx[..., 0], idx[..., 1], idx[..., 2]]
    return out


def depth(a, lo, o, d):
    """Exact optical depth along rays o + t d (index space, t in world units, t >= 0)."""
    box_lo, box_hi = lo + 1.0, lo + np.array(a.shape) - 2.0  # the grown active box
    with np.errstate(divide="ignore", invalid="ignore"):
        t_a = (box_lo - o) / d
        t_b = (box_hi - o) / d
    t0 = np.nanmax(np.minimum(t_a, t_b), axis=1).clip(min=0.0)
    t1 = np.nanmin(np.maximum(t_a, t_b), axis=1)
    hit = t1 > t0
    cuts = [t0[:, None], t1[:, None]]
    for k in range(3):
        planes = np.arange(box_lo[k], box_hi[k] + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (planes[None, :] - o[:, k : k + 1]) / d[:, k : k + 1]
        inside = np.isfinite(t) & (t > t0[:, None]) & (t < t1[:, None])
        cuts.append(np.where(inside, t, t1[:, None]))
    t = np.sort(np.concatenate(cuts, axis=1), axis=1)
    a_, b_ = t[:, :-1], t[:, 1:]
    m_ = 0.5 * (a_ + b_)
    at = lambda s: density(a, lo, o[:, None, :] + s[..., None] * d[:, None, :])  # noqa: E731
    tau = ((b_ - a_) / 6.0 * (at(a_) + 4.0 * at(m_) + at(b_))).sum(axis=1)
    return np.where(hit, tau, 0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--view", required=True)
    ap.add_argument("--vdb", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--supersample", type=int, default=1)
    args = ap.parse_args()
    # Two voxels of background: lookups clamped to the array read zeros.
    a, lo, m, _ = common.dense_density(args.vdb, 2)
    a = a.astype(np.float64)
    import OpenImageIO as oiio  # bundled with bpy, on the path dense_density set

    view = json.load(open(args.view))
    inv = np.linalg.inv(m)
    cam = view["camera"]
    w, h, n = view["width"], view["height"], args.supersample
    eye, target, up = (np.array(cam[k], dtype=np.float64) for k in ("eye", "target", "up"))
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    up_dir = np.cross(right, fwd)
    half = np.tan(np.radians(cam["fov_y"]) / 2)
    right, up_dir = right * half * w / h, up_dir * half
    image = np.zeros((h, w))
    for sy in range(n):
        for sx in range(n):
            px, py = np.meshgrid(np.arange(w) + (sx + 0.5) / n, np.arange(h) + (sy + 0.5) / n)
            x = (2.0 * px / w - 1.0).ravel()
            y = (1.0 - 2.0 * py / h).ravel()
            dirs = fwd[None, :] + x[:, None] * right[None, :] + y[:, None] * up_dir[None, :]
            dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
            o = np.broadcast_to(inv[:3, :3] @ eye + inv[:3, 3], dirs.shape)
            d = dirs @ inv[:3, :3].T
            tau = np.concatenate([depth(a, lo, o[i : i + 8192], d[i : i + 8192]) for i in range(0, len(d), 8192)])
            image += np.exp(-tau).reshape(h, w) / (n * n)
    bg = np.array(view["background"])
    rgba = np.concatenate([image[..., None] * bg[None, None, :], np.ones((h, w, 1))], axis=2).astype(np.float32)
    out = oiio.ImageOutput.create(args.out)
    out.open(args.out, oiio.ImageSpec(w, h, 4, oiio.FLOAT))
    out.write_image(rgba)
    out.close()
    print(f"{args.out}: {w}x{h}, {n * n} rays a pixel, transmittance {image.min():.4f} to {image.max():.4f}")


if __name__ == "__main__":
    main()
