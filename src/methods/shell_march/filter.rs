//! ShellMarch's footprint filter (`filter: Footprint`), host side: which MIP levels of a texel it
//! reads (the bake's layers, whose levels halve s and t only), where they sit in `shell_mips`,
//! each prism's voxel density in s and t (its level's scale), and how far a filtered sample
//! reads beyond a level-0 one (skipping and bands use occupancy dilated by as much). The
//! kernel's side is `footprint_level`, `filter_pyramid` and `sample_filtered` in
//! march_shell.wgsl's includes.

use glam::DVec3;

use crate::types::{ReferencePrism, ShellFilter, ShellVertex};

/// Voxels per row of a level in `shell_mips`: rows are padded to 256 bytes (a texture copy's
/// row alignment), 32 voxels of 8 bytes.
const ROW_VOXELS: u32 = 32;

/// MIP levels the filter reads of a texel of `res`, level 0 included: while s and t both halve
/// exactly, so a voxel of level l is the mean of exactly 2^l x 2^l voxels of level 0 and repeats
/// with the texel (the layers' odd sizes fold their last voxel in; the filter stops before).
pub(crate) fn levels(res: [u32; 3]) -> u32 {
    let exact = res[0].trailing_zeros().min(res[1].trailing_zeros()) + 1;
    exact.min(crate::bake::texel_layers::mip_levels(res))
}

/// Size (s, t) of level l of a texel of `res`.
pub(crate) fn level_size(res: [u32; 3], l: u32) -> [u32; 2] {
    [(res[0] >> l).max(1), (res[1] >> l).max(1)]
}

/// Voxels of level l in `shell_mips` (rows padded).
fn level_words(res: [u32; 3], l: u32) -> u64 {
    let [w, h] = level_size(res, l);
    w.next_multiple_of(ROW_VOXELS) as u64 * h as u64 * res[2] as u64
}

/// Where each level from 1 on starts, relative to the object's first, and the words of all.
pub(crate) fn layout(res: [u32; 3], levels: u32) -> (Vec<u64>, u64) {
    let mut starts = Vec::new();
    let mut words = 0;
    for l in 1..levels {
        starts.push(words);
        words += level_words(res, l);
    }
    (starts, words)
}

/// Per object (its texel's resolution, and its bias where it filters) its filter, `mips` counted
/// from the start of `shell_mips`; and the words of `shell_mips`.
pub(crate) fn table(objects: impl Iterator<Item = ([u32; 3], Option<f64>)>) -> (Vec<ShellFilter>, u64) {
    let mut words = 0u64;
    let table = objects
        .map(|(res, bias)| match bias {
            Some(bias) => {
                let levels = levels(res);
                let occupancy = crate::bake::occupancy::words(res) as u32;
                let filter = ShellFilter { mips: words as u32, levels, bias: bias as f32, occupancy };
                words += layout(res, levels).1;
                filter
            }
            None => ShellFilter::default(),
        })
        .collect();
    (table, words)
}

fn point(p: [f32; 4]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// Voxels of the texel per world unit in s and t over the prism's middle section: the square
/// root of its area in voxels over its area in the world (large where the section is flat).
pub(crate) fn density(prism: &ReferencePrism, vertices: &[ShellVertex], res: [u32; 3]) -> f32 {
    let mid = |i: usize| {
        let v = &vertices[prism.vertices[i] as usize];
        (point(v.bottom) + point(v.top)) * 0.5
    };
    let (a, b, c) = (mid(0), mid(1), mid(2));
    let world = (b - a).cross(c - a).length();
    let uv = |i: usize| match i {
        0 => [prism.uv01[0] as f64, prism.uv01[1] as f64],
        1 => [prism.uv01[2] as f64, prism.uv01[3] as f64],
        _ => [prism.uv2[0] as f64, prism.uv2[1] as f64],
    };
    let (p, q, r) = (uv(0), uv(1), uv(2));
    let texture = ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs()
        * res[0] as f64
        * res[1] as f64;
    if world > 0.0 {
        (texture / world).sqrt().min(1e30) as f32
    } else {
        1e30
    }
}

/// A pixel's width per unit distance at the image's centre, from the tracer's `right` and `up`
/// (half extents at unit distance) and the image size, as the kernel's `pixel_cone`.
pub(crate) fn pixel_cone(right: [f32; 4], up: [f32; 4], size: (u32, u32)) -> f64 {
    (2.0 * point(right).length() / size.0 as f64).max(2.0 * point(up).length() / size.1 as f64)
}

/// The MIP level a sample at distance t reads, for a pixel of cone `cone` in a prism of
/// `density` (voxels per world unit): as the kernel's `footprint_level`.
pub(crate) fn level(cone: f64, t: f64, density: f64, filter: &ShellFilter) -> f64 {
    if filter.levels <= 1 {
        return 0.0;
    }
    ((cone * t * density).log2() + filter.bias as f64).clamp(0.0, (filter.levels - 1) as f64)
}

/// The occupancy pyramid a sample at `level` skips by: 0 (the texel's own) at level 0, else the
/// coarser of the two levels it mixes, c, whose pyramid is made of the opacity dilated by
/// [`radius`]`(c)` in s and t. As the kernel's `filter_pyramid`.
pub(crate) fn pyramid(level: f64, levels: u32) -> u32 {
    if level <= 0.0 {
        return 0;
    }
    (level.floor() as u32 + 1).min(levels - 1)
}

/// How far (voxels of s and t) a sample mixing level c reads beyond the voxels a level-0 sample
/// reads: the two voxels of level c around it span 1.5 of its voxels (2^c voxels of level 0)
/// either side, less the half voxel level 0 reads.
pub(crate) fn radius(c: u32) -> u32 {
    if c == 0 {
        0
    } else {
        3 << (c - 1)
    }
}

/// The pyramid a prism's samples may need in this view: at the level of its farthest corner
/// (every sample is nearer: the prism lies in its corners' hull), a hundredth of a level on for
/// the kernel's f32 rounding.
pub(crate) fn prism_pyramid(prism: &ReferencePrism, vertices: &[ShellVertex], cone: f64, filter: &ShellFilter) -> u32 {
    if filter.levels <= 1 {
        return 0;
    }
    let far = (0..3)
        .flat_map(|i| {
            let v = &vertices[prism.vertices[i] as usize];
            [v.bottom, v.top]
        })
        .map(|p| point(p).length())
        .fold(0.0, f64::max);
    let level = level(cone, far, prism.uv2[3] as f64, filter);
    pyramid(if level > 0.0 { level + 0.01 } else { 0.0 }, filter.levels)
}

/// Records copies of levels 1.. of each filtering object's texel layers (`layers`, per object)
/// into `mips`.
pub(crate) fn copy_levels(
    encoder: &mut wgpu::CommandEncoder,
    mips: &wgpu::Buffer,
    objects: &[(ShellFilter, [u32; 3], &wgpu::Texture)],
) {
    for (filter, res, layers) in objects {
        let (starts, _) = layout(*res, filter.levels);
        for (l, start) in (1..filter.levels).zip(starts) {
            let [w, h] = level_size(*res, l);
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: layers,
                    mip_level: l,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: mips,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: (filter.mips as u64 + start) * 8,
                        bytes_per_row: Some(w.next_multiple_of(ROW_VOXELS) * 8),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: res[2] },
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Levels stop where s or t no longer halves exactly; rows are padded to 32 voxels.
    #[test]
    fn levels_halve_exactly_and_rows_are_padded() {
        assert_eq!(levels([128, 128, 64]), 8);
        assert_eq!(levels([96, 128, 8]), 6);
        assert_eq!(levels([7, 8, 8]), 1);
        let (starts, words) = layout([64, 64, 2], 3);
        // Level 1: 32 x 32 x 2; level 2: 16 (padded to 32) x 16 x 2.
        assert_eq!(starts, [0, 2048]);
        assert_eq!(words, 2048 + 1024);
    }

    /// A flat unit square's section, its uvs one repeat of a 64-voxel texel, holds 64 voxels per
    /// world unit; the level is log2 of the footprint in voxels, clamped, and the reach grows with
    /// the coarser level mixed.
    #[test]
    fn the_footprint_picks_its_level() {
        let v = |x: f32, y: f32| ShellVertex { bottom: [x, y, 5.0, 1.0], top: [x, y, 5.5, 1.0] };
        let vertices = [v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
        let prism = ReferencePrism { vertices: [0, 1, 2, 0], uv01: [0.0, 0.0, 1.0, 0.0], uv2: [0.0, 1.0, 0.0, 0.0] };
        let d = density(&prism, &vertices, [64, 64, 16]) as f64;
        assert!((d - 64.0).abs() < 1e-4, "{d}");
        let filter = ShellFilter { mips: 0, levels: 7, bias: 0.0, occupancy: 0 };
        // A pixel of 1/64 unit per unit distance, at distance 4: 1/16 unit, 4 voxels, level 2.
        assert!((level(1.0 / 64.0, 4.0, d, &filter) - 2.0).abs() < 1e-6);
        assert_eq!(level(1.0 / 64.0, 0.5, d, &filter), 0.0);
        assert_eq!(level(1.0, 100.0, d, &filter), 6.0);
        assert_eq!(level(1.0, 100.0, d, &ShellFilter::default()), 0.0);
        assert_eq!([0.0, 0.5, 2.0, 5.5, 6.0].map(|l| pyramid(l, 7)), [0, 1, 3, 6, 6]);
        assert_eq!([0, 1, 3, 6].map(radius), [0, 3, 12, 96]);
    }
}
