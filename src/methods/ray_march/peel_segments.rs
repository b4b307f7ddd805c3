//! CPU twin (f64) of `wgsl/ray_march/begin_segments.wgsl` and `wgsl/ray_march/peel_segments.wgsl`: per pixel, the
//! ray's start and then, peel after peel, the nearest front-facing surface splat beyond the last
//! boundary (an entry) and the nearest back-facing one beyond that, where the disk lies on or
//! outside the splat surface (an exit). It tests every
//! splat against every ray, so it also checks that the kernel's footprints miss no hit.

use glam::{DMat4, DVec3};

use crate::cpu::hypertexture::Model;
use crate::types::{FrameParams, SegmentParams, Splat};

/// Mirrors the kernel's: exits count only where the disk is on or outside the splat surface
/// (in cells).
pub(crate) const EXIT_SLACK: f64 = 1e-3;

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// The unit world direction through the middle of pixel `(x, y)` (mirrors `pixel_direction`).
pub(crate) fn pixel_direction(frame: &FrameParams, model: &Model, x: u32, y: u32) -> DVec3 {
    let v = frame.viewport;
    let sx = 2.0 * (x as f64 + 0.5) * v[2] as f64 - 1.0;
    let sy = 1.0 - 2.0 * (y as f64 + 0.5) * v[3] as f64;
    (v3(frame.forward) + v3(model.params.right) * sx + v3(model.params.up) * sy).normalize()
}

/// The parameters (entry, exit) of the ray o + t d inside the enlarged bounds (mirrors
/// `bounds_span`).
pub(crate) fn bounds_span(model: &Model, o: DVec3, d: DVec3) -> (f64, f64) {
    let p = model.params;
    let tiny = 1e-30;
    let safe = DVec3::from_array(d.to_array().map(|c| if c.abs() < tiny { tiny.copysign(c) } else { c }));
    let a = (v3(p.bounds_min) - o) / safe;
    let b = (v3(p.bounds_max) - o) / safe;
    (a.min(b).max_element(), a.max(b).min_element())
}

/// Pixel `(x, y)`'s ray as the segment kernels set it up: the object-space ray `origin + dir t`
/// (world point `d t`, `d` its `pixel_direction`), its span (entry, exit) in the enlarged bounds, and
/// where it starts (the entry or the near plane, whichever is farther).
pub(crate) struct PixelRay {
    pub(crate) origin: DVec3,
    pub(crate) dir: DVec3,
    pub(crate) span: (f64, f64),
    pub(crate) start: f64,
}

pub(crate) fn pixel_ray(frame: &FrameParams, model: &Model, x: u32, y: u32) -> PixelRay {
    let to_local = DMat4::from_cols_array_2d(&model.params.to_local.map(|c| c.map(|v| v as f64)));
    let d = pixel_direction(frame, model, x, y);
    let origin = to_local.w_axis.truncate();
    let dir = to_local.transform_vector3(d);
    let span = bounds_span(model, origin, dir);
    let start = span.0.max(model.params.right[3] as f64 / d.dot(v3(frame.forward)));
    PixelRay { origin, dir, span, start }
}

/// Boundary slots of pixel `(x, y)` after every peel: the start, then entry and exit of each
/// segment (infinity where none was found).
pub fn peel_segments(
    frame: &FrameParams,
    model: &Model,
    segments: &SegmentParams,
    splats: &[Splat],
    x: u32,
    y: u32,
) -> Vec<f64> {
    let passes = segments.counts[2] as usize;
    let PixelRay { origin, dir, span, start } = pixel_ray(frame, model, x, y);
    let mut slots = vec![f64::INFINITY; 2 * passes + 1];
    slots[0] = start;
    if span.0 < span.1 && model.support_distance(origin + dir * start) < segments.surface[0] as f64 {
        slots[1] = start;
    }
    for phase in 0..2 * passes {
        // The first entry may lie before the start (the marcher clips it).
        let previous = if phase == 0 { 0.0 } else { slots[phase] };
        if previous.is_infinite() {
            continue;
        }
        let entering = phase % 2 == 0;
        for s in splats {
            let (c, n, r) = (v3(s.center), v3(s.normal), s.center[3] as f64);
            let facing = dir.dot(n);
            if (facing < 0.0) != entering || facing == 0.0 {
                continue;
            }
            let t = (c - origin).dot(n) / facing;
            if (origin + dir * t - c).length_squared() > r * r || t <= previous || t >= slots[phase + 1] {
                continue;
            }
            let level = model.support_distance(origin + dir * t) - segments.surface[0] as f64;
            if !entering && level < -EXIT_SLACK * segments.lattice_min[3] as f64 {
                continue;
            }
            slots[phase + 1] = t;
        }
    }
    slots
}
