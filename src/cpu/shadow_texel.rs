//! CPU twin of `wgsl/bake/shadow_texel.wgsl`, in f64: self-shadowing baked into a texel's
//! colour for a fixed light (Meyer & Neyret 1998, 3.1). The same exact voxel traversal as the
//! kernel, so the two differ only by f32 rounding.

use crate::types::ShadowParams;

/// The voltex default of [`ShadowParams::shading`]'s `y`: past this optical depth the march
/// stops (the transmittance left, below 1.2e-7, is under an 8-bit step by far).
pub const OPTICAL_CUTOFF: f32 = 16.0;

/// Alpha of the matter a march starting in it first leaves, counting nothing (a voxel inside a
/// solid takes the shadow of the point where the light enters the solid, as the paper fills a
/// solid's inside with its surface colour, 3.2).
pub const SOLID: f64 = 0.99;

/// Most voxels one march crosses for a texel of `res`: four times across the box along each
/// axis, enough for a light 70 degrees off the vertical through a cubic texel; a longer
/// march counts the rest of its way as empty.
pub fn max_steps(res: [u32; 3]) -> u32 {
    4 * (res[0] + res[1] + res[2])
}

/// The uniform of the kernel: `toward_light` (texel space, any length), `extinction` (optical
/// depth of one texel unit of alpha-1 matter), `ambient` in `[0, 1]`, `bias` (voxels, along
/// the axis the light's direction crosses fastest, that the march skips).
pub fn shadow_params(
    res: [u32; 3],
    toward_light: [f32; 3],
    extinction: f32,
    ambient: f32,
    bias: f32,
) -> ShadowParams {
    let l = glam::Vec3::from_array(toward_light).normalize();
    ShadowParams {
        resolution: [res[0], res[1], res[2], max_steps(res)],
        light: [l.x, l.y, l.z, extinction],
        shading: [ambient, OPTICAL_CUTOFF, bias, 0.0],
    }
}

/// Transmittance from `bias` voxels off the centre of `voxel` towards the light through the opacity `alpha(x, y,
/// z)` (nearest voxel; x and y wrap, the march ends where z leaves the box).
pub fn transmittance(p: &ShadowParams, alpha: impl Fn([usize; 3]) -> f64, voxel: [u32; 3]) -> f64 {
    let res = [p.resolution[0] as i64, p.resolution[1] as i64, p.resolution[2] as i64];
    let dq: [f64; 3] = std::array::from_fn(|a| p.light[a] as f64 * res[a] as f64);
    let delta = dq.map(|d| if d != 0.0 { 1.0 / d.abs() } else { 1e30 });
    let advance = dq.map(|d| d.signum() as i64 * (d != 0.0) as i64);
    let mut t = p.shading[2] as f64 * delta.iter().copied().fold(f64::INFINITY, f64::min);
    let start: [f64; 3] = std::array::from_fn(|a| voxel[a] as f64 + 0.5 + t * dq[a]);
    let mut cell = start.map(|s| s.floor() as i64);
    let mut next: [f64; 3] = std::array::from_fn(|a| match dq[a] {
        d if d > 0.0 => t + ((cell[a] + 1) as f64 - start[a]) / d,
        d if d < 0.0 => t + (cell[a] as f64 - start[a]) / d,
        _ => 1e30,
    });
    let (mut optical, mut inside) = (0.0, true);
    for _ in 0..p.resolution[3] {
        if cell[2] < 0 || cell[2] >= res[2] {
            break;
        }
        let axis = if next[0] <= next[1] && next[0] <= next[2] {
            0
        } else if next[1] <= next[2] {
            1
        } else {
            2
        };
        let at = [cell[0].rem_euclid(res[0]) as usize, cell[1].rem_euclid(res[1]) as usize, cell[2] as usize];
        let a = alpha(at).clamp(0.0, 1.0);
        // A sliver (the start on a voxel's face, where f32 and f64 round apart) leaves nothing.
        let sliver = next[axis] - t < 1e-3 * delta.iter().copied().fold(f64::INFINITY, f64::min);
        inside = inside && (a as f32 >= SOLID as f32 || sliver);
        if !inside {
            optical += p.light[3] as f64 * a * (next[axis] - t);
        }
        t = next[axis];
        cell[axis] += advance[axis];
        next[axis] += delta[axis];
        if optical > p.shading[1] as f64 {
            break;
        }
    }
    (-optical).exp()
}

/// The shadowed volume: every voxel's colour (premultiplied RGB) times `ambient + (1 - ambient)
/// T`, alpha kept. `volume` holds RGBA voxels, s fastest, then t, then w.
pub fn shadow_texel(p: &ShadowParams, volume: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let [nx, ny, nz] = [p.resolution[0], p.resolution[1], p.resolution[2]];
    assert_eq!(volume.len(), (nx * ny * nz) as usize, "a volume of the params' resolution");
    let alpha = |[x, y, z]: [usize; 3]| volume[x + nx as usize * (y + ny as usize * z)][3] as f64;
    let ambient = p.shading[0] as f64;
    let mut out = Vec::with_capacity(volume.len());
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let v = volume[out.len()];
                let light = ambient + (1.0 - ambient) * transmittance(p, alpha, [x, y, z]);
                let lit = |c: f32| (c as f64 * light) as f32;
                out.push([lit(v[0]), lit(v[1]), lit(v[2]), v[3]]);
            }
        }
    }
    out
}

#[cfg(test)]
#[path = "shadow_texel_tests.rs"]
mod tests;
