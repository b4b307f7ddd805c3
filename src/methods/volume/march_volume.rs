//! CPU twin (f64) of `wgsl/volume/march_volume.wgsl`: the same march through a volume object,
//! sampled through the CPU twin of the brick table (`vdb::SparseVolume`). No opaque surfaces.

use glam::{DMat4, DVec3};

use super::VolumePlan;
use crate::methods::view::RayCamera;
use crate::vdb::SparseVolume;

/// What the twin needs of the frame: the camera, the light (towards it, unit) and ambient term.
pub struct TwinView {
    /// The camera.
    pub camera: RayCamera,
    /// The camera's unit forward direction.
    pub forward: DVec3,
    /// Unit direction towards the light.
    pub light: DVec3,
    /// Light kept without direct light, in [0, 1].
    pub ambient: f64,
    /// Image size in pixels (width, height).
    pub size: (u32, u32),
}

const MIN_TRANSMITTANCE: f64 = 1e-4;

struct Ray<'a> {
    grid: &'a SparseVolume,
    plan: &'a VolumePlan,
    to_index: DMat4,
    scale: f64,
}

impl Ray<'_> {
    fn extinction(&self, x: DVec3) -> f64 {
        self.scale * self.grid.density_at(x)
    }

    fn shadow(&self, x: DVec3, l: DVec3) -> f64 {
        let (lo, hi) = self.grid.index_bounds();
        let exit = span(x, l, lo, hi).1.max(0.0);
        let n = (exit / self.plan.shadow_step).ceil().clamp(1.0, self.plan.params.budget[1] as f64);
        let h = exit / n;
        let tau: f64 = (0..n as u32).map(|j| self.extinction(x + l * ((j as f64 + 0.5) * h)) * h).sum();
        (-tau).exp()
    }

    fn shade(&self, x: DVec3, d: DVec3, view: &TwinView) -> DVec3 {
        let m = self.plan.params.medium;
        let albedo = DVec3::new(m[0] as f64, m[1] as f64, m[2] as f64) * DVec3::from(self.grid.color_at(x));
        if !self.plan.phong {
            return albedo;
        }
        let e = 0.5;
        let g = |a: DVec3| self.grid.density_at(x + a * e) - self.grid.density_at(x - a * e);
        let gi = DVec3::new(g(DVec3::X), g(DVec3::Y), g(DVec3::Z));
        let a = glam::DMat3::from_mat4(self.to_index);
        let grad = a.transpose() * gi;
        let len = grad.length();
        let normal = if len > 1e-12 { -grad / len } else { -d };
        let light = view.light;
        let lit = if self.plan.shadows { self.shadow(x, a * light) } else { 1.0 };
        let diffuse = normal.dot(light).max(0.0);
        let half_way = (light - d).normalize();
        let specular = if diffuse > 0.0 { 0.25 * normal.dot(half_way).max(0.0).powf(32.0) } else { 0.0 };
        albedo * (view.ambient + (1.0 - view.ambient) * diffuse * lit) + DVec3::splat(specular * lit)
    }
}

/// Parameters (entry, exit) of the ray o + t d in the box lo..hi (entry > exit: a miss).
pub fn span(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> (f64, f64) {
    let safe = DVec3::select(d.abs().cmplt(DVec3::splat(1e-30)), DVec3::splat(1e-30).copysign(d), d);
    let a = (lo - o) / safe;
    let b = (hi - o) / safe;
    (a.min(b).max_element(), a.max(b).min_element())
}

/// The premultiplied colour and coverage of every pixel (rows top to bottom), as the kernel
/// leaves them in `volume_state` (before the light colour and the background).
pub fn march_volume(plan: &VolumePlan, to_world: &DMat4, view: &TwinView) -> Vec<[f64; 4]> {
    let grid = &*plan.grid;
    let to_index = (*to_world * grid.index_to_world).inverse() * DMat4::from_translation(view.camera.eye);
    let ray = Ray { grid, plan, to_index, scale: plan.params.medium[3] as f64 };
    let (w, h) = view.size;
    let mut out = Vec::with_capacity((w * h) as usize);
    for py in 0..h {
        for px in 0..w {
            let sx = 2.0 * (px as f64 + 0.5) / w as f64 - 1.0;
            let sy = 1.0 - 2.0 * (py as f64 + 0.5) / h as f64;
            let d = (view.forward + view.camera.right * sx + view.camera.up * sy).normalize();
            out.push(pixel(&ray, d, view));
        }
    }
    out
}

fn pixel(r: &Ray, d: DVec3, view: &TwinView) -> [f64; 4] {
    let origin = r.to_index.transform_point3(DVec3::ZERO);
    let dir = r.to_index.transform_vector3(d);
    let (lo, hi) = r.grid.index_bounds();
    let (entry, t1) = span(origin, dir, lo, hi);
    let t0 = entry.max(view.camera.near / d.dot(view.forward));
    let step = r.plan.step;
    let mut rgb = DVec3::ZERO;
    let mut transmittance = 1.0;
    let mut add = |alpha: f64, x: DVec3, transmittance: &mut f64| {
        rgb += r.shade(x, d, view) * alpha * *transmittance;
        *transmittance *= 1.0 - alpha;
    };
    if t1 <= t0 {
        return [0.0; 4];
    }
    if !r.plan.exact {
        let n = ((t1 - t0) / step).ceil().max(1.0);
        let h = (t1 - t0) / n;
        for k in 0..n as u64 {
            if transmittance < MIN_TRANSMITTANCE {
                break;
            }
            let x = origin + dir * (t0 + (k as f64 + 0.5) * h);
            let sigma = r.extinction(x);
            if sigma > 0.0 {
                add(1.0 - (-sigma * h).exp(), x, &mut transmittance);
            }
        }
    } else {
        // Pieces within one voxel cell: the interpolant is a cubic along each, so Simpson's rule
        // integrates its optical depth exactly.
        let nudge = 1e-4 / dir.length().max(1e-30);
        let mut t = t0;
        while t < t1 && transmittance >= MIN_TRANSMITTANCE {
            let ahead = (t + nudge).min(0.5 * (t + t1));
            let c = (origin + dir * ahead).floor();
            let end = span(origin, dir, c, c + 1.0).1.max(ahead).min(t1);
            let m = ((end - t) / step).ceil().max(1.0);
            let h = (end - t) / m;
            for j in 0..m as u64 {
                if transmittance < MIN_TRANSMITTANCE {
                    break;
                }
                let a = t + j as f64 * h;
                let f = |s: f64| r.grid.density_at(origin + dir * s);
                let tau = r.scale * h * (f(a) + 4.0 * f(a + 0.5 * h) + f(a + h)) / 6.0;
                if tau > 0.0 {
                    add(1.0 - (-tau).exp(), origin + dir * (a + 0.5 * h), &mut transmittance);
                }
            }
            t = end;
        }
    }
    [rgb.x, rgb.y, rgb.z, 1.0 - transmittance]
}
