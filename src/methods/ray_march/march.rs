//! CPU twin (f64) of `wgsl/ray_march/ray_march.wgsl`: per pixel, the ray's span inside the hypertexture's
//! enlarged bounds is cut into whole steps sampled at their middles, composited front to back with
//! the shared step-corrected opacity until the transmittance falls below 1e-4; Phong shading from
//! the density gradient by central differences and shadow rays towards the light; with an
//! adaptive stride (`HyperParams::budget` w) the same strided samples as the kernel. It marches
//! each ray in one go, so it also checks the kernel's resumption across dispatches.

use glam::{DMat4, DVec3, DVec4};

use super::light_volume;
use crate::cpu::hypertexture::Model;
use crate::types::LightVolumeParams;

pub(crate) const MIN_TRANSMITTANCE: f64 = 1e-4;
pub(crate) const MAX_ALPHA: f64 = 0.999999;

/// The camera and light of a frame (from `FrameParams`); right, up, near and the object come
/// from the model's `HyperParams`.
pub struct MarchView {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) forward: DVec3,
    /// Unit direction towards the light, ambient term and light colour.
    pub(crate) light_dir: DVec3,
    pub(crate) ambient: f64,
    pub(crate) light_color: [f64; 3],
}

impl MarchView {
    /// The view of a frame of `width` x `height` pixels, as the kernel reads it from `frame`.
    pub fn of_frame(frame: &crate::types::FrameParams, (width, height): (u32, u32)) -> Self {
        let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
        MarchView {
            width,
            height,
            forward: v3(frame.forward),
            light_dir: v3(frame.light_dir),
            ambient: frame.light_dir[3] as f64,
            light_color: [0, 1, 2].map(|c| frame.light_color[c] as f64),
        }
    }
}

/// Shading switches (the kernel's overrides).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shade {
    /// Phong shading with the density gradient (`Phong`, `PhongShadows`).
    pub phong: bool,
    pub(crate) shadows: bool,
    /// Volumetric lighting by the Henyey-Greenstein phase function of this anisotropy g
    /// (instead of Phong).
    pub(crate) phase: Option<f64>,
    /// Shadows read from a light volume (override `volume_shadows`) instead of shadow rays.
    pub(crate) volume: bool,
}

impl Shade {
    pub(crate) fn of(shading: crate::scene::Shading) -> Self {
        use crate::scene::Shading as S;
        match shading {
            S::None => Shade::default(),
            S::Phong => Shade { phong: true, ..Default::default() },
            S::PhongShadows => Shade { phong: true, shadows: true, ..Default::default() },
            S::HenyeyGreenstein { g, shadows } => Shade { shadows, phase: Some(g), ..Default::default() },
        }
    }

    /// Density evaluations of shading one sample besides its own: 6 for Phong's gradient, one
    /// per shadow sample (a light volume replaces all but the first).
    pub(crate) fn evaluations(&self, shadow_samples: u32) -> u32 {
        let shadow = if self.volume { 1 } else { shadow_samples };
        6 * self.phong as u32 + shadow * self.shadows as u32
    }
}

/// The Henyey-Greenstein phase function at the cosine of the scattering angle (between the
/// light's and the scattered direction): `(1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2))`, a
/// density over the sphere of directions (it integrates to 1).
pub fn henyey_greenstein(g: f64, cos: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

struct Ray<'a> {
    model: Model<'a>,
    to_local: DMat4,
    view: &'a MarchView,
    shade: Shade,
    light: Option<LightVolume<'a>>,
}

/// A light volume as [`light_volume::bake_light_volume`] makes it, and its grid.
pub(crate) type LightVolume<'a> = (&'a LightVolumeParams, &'a [[f64; 2]]);

impl Ray<'_> {
    fn bounds_span(&self, o: DVec3, d: DVec3) -> (f64, f64) {
        let p = self.model.params;
        let tiny = 1e-30;
        let safe = DVec3::from_array(d.to_array().map(|c| if c.abs() < tiny { tiny.copysign(c) } else { c }));
        let a = (v3(p.bounds_min) - o) / safe;
        let b = (v3(p.bounds_max) - o) / safe;
        (a.min(b).max_element(), a.max(b).min_element())
    }

    fn step_alpha(&self, a: f64, step: f64) -> f64 {
        1.0 - (1.0 - a.min(MAX_ALPHA)).powf(step / self.model.params.bounds_max[3] as f64)
    }

    fn surface_normal(&self, x: DVec3, ray: DVec3) -> DVec3 {
        let e = self.model.params.march[1] as f64;
        let d = |axis: DVec4| {
            let o = (self.to_local * axis).truncate() * e;
            self.model.hyper_density(x + o) - self.model.hyper_density(x - o)
        };
        let g = DVec3::new(d(DVec4::X), d(DVec4::Y), d(DVec4::Z));
        let len = g.length();
        if len > 1e-12 {
            -g / len
        } else {
            -ray
        }
    }

    fn shadow(&self, x: DVec3) -> f64 {
        let p = self.model.params;
        let l = (self.to_local * self.view.light_dir.extend(0.0)).truncate();
        let exit = self.bounds_span(x, l).1.max(0.0);
        let mut n = (exit / p.march[0] as f64).ceil().clamp(1.0, p.budget[1] as f64) as u32;
        let h = exit / n as f64;
        if self.light.is_some() {
            n = n.min(1);
        }
        let mut transmittance = 1.0;
        for j in 0..n {
            if transmittance < MIN_TRANSMITTANCE {
                break;
            }
            let a = self.model.hyper_color(self.model.hyper_density(x + l * ((j as f64 + 0.5) * h)))[3];
            transmittance *= 1.0 - self.step_alpha(a, h);
        }
        match self.light {
            Some((grid, volume)) if transmittance >= MIN_TRANSMITTANCE => {
                transmittance * light_volume::light_transmittance(volume, grid, x + l * h)
            }
            _ => transmittance,
        }
    }

    fn phong_shade(&self, albedo: DVec3, n: DVec3, ray: DVec3, lit: f64) -> DVec3 {
        let l = self.view.light_dir;
        let h = (l - ray).normalize();
        let diffuse = n.dot(l).max(0.0);
        let specular = if diffuse > 0.0 { 0.25 * n.dot(h).max(0.0).powi(32) } else { 0.0 };
        albedo * (self.view.ambient + (1.0 - self.view.ambient) * diffuse * lit)
            + DVec3::splat(specular * lit)
    }

    /// Single scattering with the Henyey-Greenstein phase function: the light travels along
    /// `-light_dir` and leaves towards the eye along `-ray`, so the scattering angle's cosine is
    /// `light_dir . ray`; scaled by 4 pi so that isotropic scattering keeps the albedo.
    fn phase_shade(&self, albedo: DVec3, g: f64, ray: DVec3, lit: f64) -> DVec3 {
        let p = 4.0 * std::f64::consts::PI * henyey_greenstein(g, self.view.light_dir.dot(ray));
        albedo * (self.view.ambient + (1.0 - self.view.ambient) * p * lit)
    }

    /// Premultiplied rgb and coverage of the ray `d` (unit, camera-relative world).
    fn march(&self, d: DVec3) -> [f64; 4] {
        let p = self.model.params;
        let near = p.right[3] as f64;
        let cos_d = d.dot(self.view.forward);
        let origin = self.to_local.w_axis.truncate();
        let dir = (self.to_local * d.extend(0.0)).truncate();
        let (entry, t1) = self.bounds_span(origin, dir);
        let t0 = entry.max(near / cos_d);
        let mut rgb = DVec3::ZERO;
        let mut transmittance = 1.0;
        if t1 > t0 {
            let n = ((t1 - t0) / p.bounds_min[3] as f64).ceil().max(1.0) as u64;
            let h = (t1 - t0) / n as f64;
            // Adaptive stride as in the kernel: sample k was reached from k - stride.
            let max_stride = p.budget[3].max(1) as u64;
            let (mut k, mut stride) = (0u64, 1u64);
            while k < n && transmittance >= MIN_TRANSMITTANCE {
                let x = origin + dir * (t0 + (k as f64 + 0.5) * h);
                let density = self.model.hyper_density(x);
                if density > 0.0 && stride > 1 {
                    k = k + 1 - stride;
                    stride = 1;
                    continue;
                }
                stride = if density > 0.0 { 1 } else { (2 * stride).min(max_stride) };
                if k + stride >= n && k + 1 < n {
                    stride = n - 1 - k;
                }
                k += stride;
                let rgba = self.model.hyper_color(density);
                if rgba[3] <= 1e-6 {
                    continue;
                }
                let alpha = self.step_alpha(rgba[3], h);
                let mut colour = DVec3::new(rgba[0], rgba[1], rgba[2]);
                if self.shade.phong {
                    let normal = self.surface_normal(x, d);
                    let lit = if self.shade.shadows { self.shadow(x) } else { 1.0 };
                    colour = self.phong_shade(colour, normal, d, lit);
                } else if let Some(g) = self.shade.phase {
                    let lit = if self.shade.shadows { self.shadow(x) } else { 1.0 };
                    colour = self.phase_shade(colour, g, d, lit);
                }
                rgb += colour * alpha * transmittance;
                transmittance *= 1.0 - alpha;
            }
        }
        let c = self.view.light_color;
        [rgb.x * c[0], rgb.y * c[1], rgb.z * c[2], 1.0 - transmittance]
    }
}

/// The premultiplied layer (rgb times the light colour, coverage) of the whole image, rows top to
/// bottom, as `composite_ray_march.wgsl` blends it.
pub fn ray_march(view: &MarchView, model: Model, shade: Shade) -> Vec<[f64; 4]> {
    ray_march_lit(view, model, shade, None)
}

/// [`ray_march`] with shadows read from a light volume (`shade.volume`) instead of shadow rays.
pub fn ray_march_lit(
    view: &MarchView,
    model: Model,
    shade: Shade,
    light: Option<LightVolume>,
) -> Vec<[f64; 4]> {
    assert_eq!(shade.volume, light.is_some(), "a light volume exactly when the shading reads one");
    let p = model.params;
    let to_local = DMat4::from_cols_array_2d(&p.to_local.map(|c| c.map(|x| x as f64)));
    let ray = Ray { model, to_local, view, shade, light };
    let (right, up) = (v3(p.right), v3(p.up));
    let mut out = Vec::with_capacity((view.width * view.height) as usize);
    for y in 0..view.height {
        for x in 0..view.width {
            let sx = 2.0 * (x as f64 + 0.5) / view.width as f64 - 1.0;
            let sy = 1.0 - 2.0 * (y as f64 + 0.5) / view.height as f64;
            out.push(ray.march((view.forward + right * sx + up * sy).normalize()));
        }
    }
    out
}
