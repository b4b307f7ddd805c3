//! CPU twin of `wgsl/bake/bake_mesh_texel.wgsl`: a mesh grid sample at a voxel centre (vector to the
//! closest surface point, signed distance positive inside) as the voxel's premultiplied RGBA and
//! outward normal in texel space.

use super::bake::{gradient_normal, shade_lambert};
use crate::types::{BakeParams, MeshTexelParams};

/// One voxel: (premultiplied rgba, texel-space normal); `color`: a coloured mesh's colour at the
/// closest surface point (tints the texel's).
pub(crate) fn bake_mesh_texel_voxel(
    params: &BakeParams,
    texel: &MeshTexelParams,
    cell: [f32; 4],
    color: Option<[f32; 3]>,
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let voxel = texel.extent[3];
    let fill = texel.mode[1] != 0;
    let v = [cell[0], cell[1], cell[2]];
    let (coverage, away) = if fill {
        let away = if cell[3] > 0.0 { v } else { v.map(|x| -x) };
        ((0.5 + cell[3] / voxel).clamp(0.0, 1.0), away)
    } else {
        ((1.0 - cell[3].abs() / voxel).clamp(0.0, 1.0), v.map(|x| -x))
    };
    let normal = gradient_normal([0, 1, 2].map(|a| away[a] * texel.extent[a]));
    let alpha = (texel.color[3] * coverage).clamp(0.0, 1.0);
    let tint = color.unwrap_or([1.0; 3]);
    let albedo = [0, 1, 2].map(|c| texel.color[c] * tint[c]);
    let rgb = if per_pixel { albedo } else { shade_lambert(albedo, normal, params.light) };
    let rgb = rgb.map(|c| c.clamp(0.0, 1.0) * alpha);
    ([rgb[0], rgb[1], rgb[2], alpha], normal)
}

/// Every voxel of a texel (x fastest) from the grid's samples (and colours) in the same order.
pub fn bake_mesh_texel(
    params: &BakeParams,
    texel: &MeshTexelParams,
    cells: &[[f32; 4]],
    colors: Option<&[[f32; 4]]>,
    per_pixel: bool,
) -> Vec<([f32; 4], [f32; 3])> {
    let color = |v: usize| colors.map(|c| [c[v][0], c[v][1], c[v][2]]);
    cells
        .iter()
        .enumerate()
        .map(|(v, &c)| bake_mesh_texel_voxel(params, texel, c, color(v), per_pixel))
        .collect()
}
