//! CPU twin (f64) of `wgsl/reference/trace_reference.wgsl`: exact ray casting through the prisms of every
//! `Reference` object. Per pixel: the intervals of the ray inside each prism (entry and exit
//! through its triangles and bilinear sides), split where any interval starts or ends; each piece
//! is integrated front to back with the fine step (rounded so the piece holds whole steps), each
//! sample mapped back to texel space by the inverse prism map. Where objects overlap, their
//! extinctions add and their colours mix by extinction, so the order of overlapping objects needs
//! no sorting. The result is the premultiplied layer the graph composites over the frame.
//!
//! It keeps every interval (no fixed-size list as on the GPU), so it also checks the kernel's
//! windowed collection.

use glam::{DVec2, DVec3};

pub(crate) use crate::cpu::decoded_texel::DecodedTexel;
use crate::cpu::prism_map::{self, PrismCorners};

/// Rays stop once the transmittance falls below this (as the kernel does).
pub(crate) const MIN_TRANSMITTANCE: f64 = 1e-4;
/// Voxel opacity is clamped below 1 so that its extinction stays finite.
pub(crate) const MAX_ALPHA: f64 = 0.999999;

/// Per-pixel (Phong) lighting inputs of an object: its normal volume and, per prism corner,
/// `dP/ds` and `dP/dt` (the same vertex frames the slicing method interpolates).
pub(crate) struct PerPixel {
    pub(crate) normals: DecodedTexel,
    pub(crate) frames: Vec<[(DVec3, DVec3); 3]>,
}

/// One object as the tracer sees it (camera-relative f64 corners).
pub struct TraceObject {
    /// The prisms' corners, camera-relative.
    pub prisms: Vec<PrismCorners>,
    pub(crate) uvs: Vec<[DVec2; 3]>,
    pub(crate) volume: DecodedTexel,
    pub(crate) per_pixel: Option<PerPixel>,
    pub(crate) opacity_length: f64,
    pub(crate) step: f64,
    /// The base surface is drawn opaque: rays stop where they cross a prism's bottom from above.
    pub(crate) opaque_base: bool,
}

/// The camera and light: a pixel's ray is `forward + sx right + sy up` (right and up scaled by the
/// half extents of the image at unit distance), starting at the near plane.
pub struct TraceView {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    pub(crate) forward: DVec3,
    pub(crate) right: DVec3,
    pub(crate) up: DVec3,
    pub(crate) near: f64,
    /// Towards the light (unit), its colour, and the ambient term.
    pub(crate) light_dir: DVec3,
    pub(crate) light_color: [f64; 3],
    pub(crate) ambient: f64,
}

impl TraceView {
    /// Unit ray direction through the centre of pixel (x, y) (y down).
    pub fn ray(&self, x: u32, y: u32) -> DVec3 {
        self.direction(x, y).normalize()
    }

    /// Length of the unnormalised direction through pixel (x, y) (1 at the image's centre).
    pub(crate) fn through(&self, x: u32, y: u32) -> f64 {
        self.direction(x, y).length()
    }

    fn direction(&self, x: u32, y: u32) -> DVec3 {
        let sx = 2.0 * (x as f64 + 0.5) / self.width as f64 - 1.0;
        let sy = 1.0 - 2.0 * (y as f64 + 0.5) / self.height as f64;
        self.forward + self.right * sx + self.up * sy
    }
}

struct Segment {
    object: usize,
    prism: usize,
    t0: f64,
    t1: f64,
}

/// Twin of `trace_reference.wgsl`: the premultiplied layer (rgb, coverage) of the whole image,
/// rows top to bottom.
pub fn trace_reference(view: &TraceView, objects: &[TraceObject]) -> Vec<[f64; 4]> {
    let mut out = Vec::with_capacity((view.width * view.height) as usize);
    for y in 0..view.height {
        for x in 0..view.width {
            out.push(trace_ray(view, objects, view.ray(x, y)));
        }
    }
    out
}

pub(crate) fn trace_ray(view: &TraceView, objects: &[TraceObject], d: DVec3) -> [f64; 4] {
    let t_min = view.near / d.dot(view.forward);
    let mut t_max = f64::INFINITY;
    let mut segments = Vec::new();
    for (o, obj) in objects.iter().enumerate() {
        for (k, p) in obj.prisms.iter().enumerate() {
            if obj.opaque_base {
                let n = (p.bottom[1] - p.bottom[0]).cross(p.bottom[2] - p.bottom[0]);
                if d.dot(n) < 0.0 {
                    if let Some(t) = prism_map::ray_triangle(d, p.bottom[0], p.bottom[1], p.bottom[2]) {
                        if t > t_min {
                            t_max = t_max.min(t);
                        }
                    }
                }
            }
            for (t0, t1) in prism_map::ray_intervals(d, p, t_min, f64::INFINITY) {
                segments.push(Segment { object: o, prism: k, t0, t1 });
            }
        }
    }
    let mut cuts: Vec<f64> = segments.iter().flat_map(|s| [s.t0, s.t1]).map(|t| t.min(t_max)).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut rgb = DVec3::ZERO;
    let mut transmittance = 1.0;
    for k in 1..cuts.len() {
        let (a, b) = (cuts[k - 1], cuts[k]);
        let active: Vec<&Segment> = segments.iter().filter(|s| s.t0 <= a && s.t1 >= b).collect();
        let Some(step) = active.iter().map(|s| objects[s.object].step).reduce(f64::min) else { continue };
        let n = ((b - a) / step).ceil().max(1.0);
        let h = (b - a) / n;
        for i in 0..n as u64 {
            let t = a + (i as f64 + 0.5) * h;
            let (sigma, emitted) = sample(view, objects, &active, d, t);
            if sigma <= 0.0 {
                continue;
            }
            let alpha = 1.0 - (-sigma * h).exp();
            rgb += emitted / sigma * alpha * transmittance;
            transmittance *= 1.0 - alpha;
            if transmittance < MIN_TRANSMITTANCE {
                return finish(view, rgb, transmittance);
            }
        }
    }
    finish(view, rgb, transmittance)
}

fn finish(view: &TraceView, rgb: DVec3, transmittance: f64) -> [f64; 4] {
    let c = view.light_color;
    [rgb.x * c[0], rgb.y * c[1], rgb.z * c[2], 1.0 - transmittance]
}

/// Total extinction at `d t` over the active segments, and the extinction-weighted colour sum.
fn sample(view: &TraceView, objects: &[TraceObject], active: &[&Segment], d: DVec3, t: f64) -> (f64, DVec3) {
    let x = d * t;
    let mut sigma = 0.0;
    let mut emitted = DVec3::ZERO;
    for s in active {
        let obj = &objects[s.object];
        let p = &obj.prisms[s.prism];
        let Some((b, w)) = prism_map::inverse(x, p) else { continue };
        let uv = obj.uvs[s.prism];
        let st = uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2];
        let uvw = DVec3::new(st.x, st.y, w);
        let texel = obj.volume.sample(uvw);
        let a = texel[3].clamp(0.0, MAX_ALPHA);
        if a <= 1e-6 {
            continue;
        }
        let mut colour = DVec3::new(texel[0], texel[1], texel[2]) / a;
        if let Some(pp) = &obj.per_pixel {
            colour = shade(view, pp, s.prism, p, b, pp.normals.sample(uvw), d, colour);
        }
        let s_k = -(1.0 - a).ln() / obj.opacity_length;
        sigma += s_k;
        emitted += colour * s_k;
    }
    (sigma, emitted)
}

/// Phong lighting exactly as `draw_slices.wgsl` does it, with the exact barycentrics; `tn` is the
/// normal volume's sample there (texture space).
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade(
    view: &TraceView,
    pp: &PerPixel,
    prism: usize,
    p: &PrismCorners,
    b: [f64; 3],
    tn: [f64; 4],
    ray: DVec3,
    albedo: DVec3,
) -> DVec3 {
    let f = &pp.frames[prism];
    let ds = f[0].0 * b[0] + f[1].0 * b[1] + f[2].0 * b[2];
    let dt = f[0].1 * b[0] + f[1].1 * b[1] + f[2].1 * b[2];
    let dw = (0..3).map(|i| (p.top[i] - p.bottom[i]) * b[i]).sum::<DVec3>();
    let sign = if ds.dot(dt.cross(dw)) >= 0.0 { 1.0 } else { -1.0 };
    let n = dt.cross(dw) * sign * tn[0] + dw.cross(ds) * sign * tn[1] + ds.cross(dt) * sign * tn[2];
    let n = if n.length_squared() > 1e-20 { n.normalize() } else { -ray };
    let l = view.light_dir;
    let h = (l - ray).normalize();
    let diffuse = n.dot(l).max(0.0);
    let specular = if diffuse > 0.0 { 0.25 * n.dot(h).max(0.0).powi(32) } else { 0.0 };
    albedo * (view.ambient + (1.0 - view.ambient) * diffuse) + DVec3::splat(specular)
}
