//! CPU twin (f64) of `wgsl/ray_march/splat_segments.wgsl` and `wgsl/ray_march/resolve_splats.wgsl` (EWA-style
//! splatting, Gilet & Dischler 2009, section 5.1), unshaded: per pixel, every interior splat (a
//! sphere) the ray crosses adds the bounds march's samples inside it to the ray's depth slabs,
//! weighted by a Gaussian of the ray's distance to its centre; each slab's weighted mean optical
//! depth per covered sample times its covered samples, and its optical-depth-weighted colour, are
//! composited front to back. It tests every splat against every ray (the kernel only those of
//! its footprint) and sums in f64 (the kernel in fixed point, per splat and slab).

use glam::DVec3;

use super::march::{MAX_ALPHA, MIN_TRANSMITTANCE};
use super::peel_segments::{pixel_ray, PixelRay};
use crate::cpu::hypertexture::Model;
use crate::types::{FrameParams, SegmentParams, Splat};

/// Standard deviation of the Gaussian in units of the sphere's radius (mirrors `SIGMA`).
pub(crate) const SIGMA: f64 = 0.5;

#[derive(Clone, Copy, Default)]
struct Slab {
    tau: f64,
    colour: DVec3,
    share: f64,
    first: u64,
    /// Last covered sample plus one (0: none).
    end: u64,
}

/// Premultiplied rgb and coverage of pixel `(x, y)` (the march state `resolve_splats.wgsl`
/// writes; no opaque surfaces in front). `segments.splatting.x`: the slab count.
pub fn splat_segments(
    frame: &FrameParams,
    model: &Model,
    segments: &SegmentParams,
    splats: &[Splat],
    x: u32,
    y: u32,
) -> [f64; 4] {
    let p = model.params;
    let slabs = segments.splatting[0] as u64;
    let PixelRay { origin, dir, span: (_, t1), start: t0 } = pixel_ray(frame, model, x, y);
    if t1 <= t0 {
        return [0.0; 4];
    }
    let n = ((t1 - t0) / p.bounds_min[3] as f64).ceil().max(1.0) as u64;
    let h = (t1 - t0) / n as f64;
    let start = |j: u64| (j * n).div_ceil(slabs);
    let mut acc = vec![Slab::default(); slabs as usize];
    for s in splats {
        let (c, r) =
            (DVec3::new(s.center[0] as f64, s.center[1] as f64, s.center[2] as f64), s.center[3] as f64);
        let oc = origin - c;
        let (a, b) = (dir.dot(dir), dir.dot(oc));
        let disc = b * b - a * (oc.dot(oc) - r * r);
        if disc <= 0.0 {
            continue;
        }
        let q2 = (1.0 - disc / (a * r * r)).max(0.0);
        let weight = (-0.5 * q2 / (SIGMA * SIGMA)).exp();
        let root = disc.sqrt();
        let lo = (((-b - root) / a - t0) / h - 0.5).ceil().clamp(0.0, n as f64) as u64;
        let hi = ((((-b + root) / a - t0) / h - 0.5).floor() + 1.0).clamp(0.0, n as f64) as u64;
        // Per slab this splat touches: its samples' optical depth and colour.
        let mut k = lo;
        while k < hi {
            let j = k * slabs / n;
            let end = start(j + 1).min(hi);
            let (mut tau, mut colour) = (0.0, DVec3::ZERO);
            for i in k..end {
                let rgba = model.hyper_color(model.hyper_density(origin + dir * (t0 + (i as f64 + 0.5) * h)));
                if rgba[3] > 1e-6 {
                    let depth = -(1.0 - rgba[3].min(MAX_ALPHA)).ln() * h / p.bounds_max[3] as f64;
                    tau += depth;
                    colour += DVec3::new(rgba[0], rgba[1], rgba[2]) * depth;
                }
            }
            let slab = &mut acc[j as usize];
            if slab.end == 0 {
                slab.first = k;
            }
            slab.tau += weight * tau;
            slab.colour += weight * colour;
            slab.share += weight * (end - k) as f64 / (start(j + 1) - start(j)) as f64;
            slab.first = slab.first.min(k);
            slab.end = slab.end.max(end);
            k = end;
        }
    }
    let (mut rgb, mut transmittance) = (DVec3::ZERO, 1.0);
    for (j, slab) in acc.iter().enumerate() {
        if transmittance < MIN_TRANSMITTANCE {
            break;
        }
        if slab.end == 0 || slab.share <= 0.0 || slab.tau <= 0.0 {
            continue;
        }
        let samples = (start(j as u64 + 1) - start(j as u64)) as f64;
        let alpha = 1.0 - (-slab.tau / (slab.share * samples) * (slab.end - slab.first) as f64).exp();
        rgb += slab.colour / slab.tau * alpha * transmittance;
        transmittance *= 1.0 - alpha;
    }
    [rgb.x, rgb.y, rgb.z, 1.0 - transmittance]
}
