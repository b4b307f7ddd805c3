//! CPU twin of `wgsl/bake/bake_hypertexture.wgsl`: one voxel of a texel baked from a hypertexture
//! (density and colour transfer at the voxel centre, shading from the density gradient by central
//! differences), from the same packed parameters, in f64 (the hypertexture twin's precision).

use glam::DVec3;

use super::bake::{bake_volume, gradient_normal, shade_lambert, TexelVoxels};
use super::hypertexture::Model;
use crate::types::BakeParams;

/// Below this opacity a voxel is empty (mirrors `MIN_OPACITY`).
pub(crate) const MIN_OPACITY: f64 = 1e-6;

/// Voxel `voxel` of the texel `params` describes, `model.params` holding the texel's box and
/// gradient offset as `HyperTexel` packs them: (premultiplied rgba, texel-space normal).
pub fn bake_hypertexture_voxel(
    params: &BakeParams,
    model: &Model,
    voxel: [u32; 3],
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let h = model.params;
    let v = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let (lo, extent) = (v(h.bounds_min), v(h.bounds_max) - v(h.bounds_min));
    let res =
        DVec3::new(params.resolution[0] as f64, params.resolution[1] as f64, params.resolution[2] as f64);
    let centre = DVec3::new(voxel[0] as f64, voxel[1] as f64, voxel[2] as f64) + 0.5;
    let x = lo + extent * centre / res;
    let rgba = model.hyper_color(model.hyper_density(x));
    if rgba[3] <= MIN_OPACITY {
        return ([0.0; 4], [0.0, 0.0, 1.0]);
    }
    let e = h.march[1] as f64;
    let g = DVec3::from_array(std::array::from_fn(|a| {
        let step = DVec3::AXES[a] * e;
        model.hyper_density(x + step) - model.hyper_density(x - step)
    }));
    let outward = -g * extent;
    let normal = gradient_normal(outward.as_vec3().to_array());
    let alpha = rgba[3].clamp(0.0, 1.0) as f32;
    let albedo = [rgba[0] as f32, rgba[1] as f32, rgba[2] as f32];
    let rgb = if per_pixel { albedo } else { shade_lambert(albedo, normal, params.light) };
    let rgb = rgb.map(|c| c.clamp(0.0, 1.0) * alpha);
    ([rgb[0], rgb[1], rgb[2], alpha], normal)
}

/// Twin of `bake_hypertexture.wgsl`: the whole volume (rgba, normals with w = 0).
pub fn bake_hypertexture(params: &BakeParams, model: &Model, per_pixel: bool) -> (TexelVoxels, TexelVoxels) {
    bake_volume(params, |v| bake_hypertexture_voxel(params, model, v, per_pixel))
}
