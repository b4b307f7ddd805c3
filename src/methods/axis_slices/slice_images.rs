//! Slice images for axis-aligned slicing: from a baked texel volume, per direction (s, t, w) a 2D
//! texture array holding every power-of-two level (finest first), each coarser slice combining
//! `2^level` voxel slices, and one occupancy word per slice for empty-slice culling.

use std::sync::Arc;

use crate::bake::derived::{Derived, Kernels, Made};
use crate::bake::texel_layers;
use crate::error::{Error, Result};
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::types::AxisBake;

/// The kernel baking one level of one direction's slice images.
const KERNEL: &str = "axis_slices/bake_axis_slices.wgsl";

/// The slice images a texel's bake derives for AxisSlices (the bake layer's [`Derived`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SliceImages {
    /// With their MIP levels (`AxisSlices(mipmaps: true)` on any object drawing the texel).
    pub(crate) mipmaps: bool,
}

/// A bake request's derivations with the slice images (tests bake them directly).
pub fn slice_images(mipmaps: bool) -> crate::bake::derived::Derivations {
    crate::bake::derived::Derivations(vec![Arc::new(SliceImages { mipmaps })])
}

impl Derived for SliceImages {
    fn kernels(&self) -> Vec<&'static str> {
        let mut k = vec![KERNEL];
        if self.mipmaps {
            k.push(texel_layers::MIP_KERNEL);
        }
        k
    }

    fn describe(&self) -> String {
        let mut s = "  (and its slice images: bake_axis_slices.wgsl per direction and level)\n".to_string();
        if self.mipmaps {
            s += "  (and their MIP levels: mip_layers.wgsl per direction and MIP level)\n";
        }
        s
    }

    fn memory(&self, texel: &str, resolution: [u32; 3]) -> (String, u64) {
        let mips = if self.mipmaps { " with MIP levels" } else { "" };
        (
            format!("texel {texel} slice images (s, t, w; all levels{mips}) rgba16f"),
            bytes(resolution, self.mipmaps),
        )
    }

    fn allocations(&self, texel: &str, res: [u32; 3], driver: &Driver) -> Vec<Allocation> {
        (0..3)
            .map(|d| {
                let (size, layers) = (image_size(res, d), array_layers(res[d]));
                Allocation {
                    what: format!("texel \"{texel}\"'s {} slice images", ["s", "t", "w"][d]),
                    bytes: texel_layers::image_bytes(size, self.mipmaps) * layers as u64,
                    shape: AllocationKind::Texture2d { size, layers },
                    driver: driver.clone(),
                }
            })
            .collect()
    }

    fn record(
        &self,
        ctx: &GpuContext,
        kernels: &mut Kernels,
        encoder: &mut wgpu::CommandEncoder,
        volume: &wgpu::Texture,
        resolution: [u32; 3],
    ) -> Result<Arc<dyn Made>> {
        let baked = bake(ctx, kernels.get(ctx, KERNEL)?, encoder, volume, resolution, self.mipmaps)?;
        if self.mipmaps {
            mip(ctx, kernels.get(ctx, texel_layers::MIP_KERNEL)?, encoder, &baked)?;
        }
        Ok(Arc::new(baked))
    }
}

/// A texel's AxisSlices slice images (Meyer & Neyret 1998), baked along s, t and w.
#[derive(Clone)]
pub struct AxisBaked {
    /// Per direction s, t, w: `Rgba16Float` premultiplied slice images, all levels as layers.
    pub arrays: [wgpu::Texture; 3],
    /// One word per (direction, level, slice), non-zero where the slice image is not empty.
    pub occupancy: wgpu::Buffer,
}

impl crate::gpu::cache::GpuBytes for AxisBaked {
    fn gpu_bytes(&self) -> u64 {
        self.arrays.iter().map(|a| a.gpu_bytes()).sum::<u64>() + self.occupancy.gpu_bytes()
    }
}

/// Image size of a direction's slices: s slices are (t, w) images, t slices (s, w), w slices (s, t).
pub(crate) fn image_size(res: [u32; 3], direction: usize) -> [u32; 2] {
    match direction {
        0 => [res[1], res[2]],
        1 => [res[0], res[2]],
        _ => [res[0], res[1]],
    }
}

/// Bytes of the slice arrays (f16 RGBA, with their MIP levels when `mipmaps`) and occupancy
/// words of a texel.
pub(crate) fn bytes(res: [u32; 3], mipmaps: bool) -> u64 {
    (0..3)
        .map(|d| (texel_layers::image_bytes(image_size(res, d), mipmaps) + 4) * array_layers(res[d]) as u64)
        .sum()
}

/// Records the bake of every level of every direction from `volume` (level 0 is read).
pub(crate) fn bake(
    ctx: &GpuContext,
    kernel: &mut ComputeKernel,
    encoder: &mut wgpu::CommandEncoder,
    volume: &wgpu::Texture,
    res: [u32; 3],
    mipmaps: bool,
) -> Result<AxisBaked> {
    let max_layers = ctx.limits.max_texture_array_layers;
    if let Some(d) = (0..3).find(|&d| array_layers(res[d]) > max_layers) {
        return Err(Error::Gpu(format!(
            "texel resolution {res:?}: {} slice layers along {} are beyond this adapter's limit of {max_layers} \
             array layers",
            array_layers(res[d]),
            ["s", "t", "w"][d]
        )));
    }
    let words: u32 = (0..3).map(|d| array_layers(res[d])).sum();
    let occupancy = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("axis_occupancy"),
        size: (words as u64 * 4).max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    encoder.clear_buffer(&occupancy, 0, None);
    let arrays = [0, 1, 2].map(|d| {
        let [w, h] = image_size(res, d);
        let label = ["axis_slices_s", "axis_slices_t", "axis_slices_w"][d];
        let levels = if mipmaps { texel_layers::image_levels([w, h]) } else { 1 };
        texel_layers::texture(ctx, label, [w, h], array_layers(res[d]), levels)
    });
    let source = crate::bake::level_view(volume, 0);
    for (d, array) in arrays.iter().enumerate() {
        let destination = array.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            mip_level_count: Some(1),
            ..Default::default()
        });
        for level in 0..level_count(res[d]) {
            let n = level_slices(res[d], level);
            let params = AxisBake {
                resolution: [res[0], res[1], res[2], d as u32],
                level: [level, level_layer(res[d], level), n, occupancy_base(res, d as u32, level)],
            };
            let mut inputs = Inputs::default();
            inputs.buffers.insert(
                "axis_bake".into(),
                crate::gpu::buffers::uniform(ctx, "axis_bake", bytemuck::bytes_of(&params)),
            );
            inputs.buffers.insert("axis_occupancy".into(), occupancy.clone());
            inputs.views.insert("volume".into(), source.clone());
            inputs.views.insert("destination".into(), destination.clone());
            let [w, h] = image_size(res, d);
            kernel.dispatch(ctx, encoder, &inputs, [w, h, n])?;
        }
    }
    Ok(AxisBaked { arrays, occupancy })
}

/// Records the MIP levels of every slice image of `baked` (level 0 baked), each from the one
/// above by a 2x2 box of premultiplied colour (`mip_layers.wgsl`); the w slices (the last
/// array) repeat along both axes, the s and t slices along their first.
pub(crate) fn mip(
    ctx: &GpuContext,
    kernel: &mut ComputeKernel,
    encoder: &mut wgpu::CommandEncoder,
    baked: &AxisBaked,
) -> Result<()> {
    for (direction, array) in baked.arrays.iter().enumerate() {
        texel_layers::record_mips(ctx, kernel, encoder, array, direction == 2)?;
    }
    Ok(())
}

// Layout of the slice-image arrays: power-of-two levels, finest first (mirrored in
// wgsl/shared/axis_slices.wgsl; the kernels and the AxisSlices twin both index by it).

/// Power-of-two levels of a slice set across `r` voxels: `floor(log2 r) + 1`.
pub fn level_count(r: u32) -> u32 {
    32 - r.max(1).leading_zeros()
}

/// Slices of `level` across `r` voxels: `ceil(r / 2^level)`.
pub fn level_slices(r: u32, level: u32) -> u32 {
    (r + (1 << level) - 1) >> level
}

/// First array layer of `level` in a direction's slice array (finest level first).
pub fn level_layer(r: u32, level: u32) -> u32 {
    (0..level).map(|l| level_slices(r, l)).sum()
}

/// Layers of a direction's slice array (all levels).
pub fn array_layers(r: u32) -> u32 {
    level_layer(r, level_count(r))
}

/// First occupancy word of (direction, level): directions s, t, w one after the other.
pub(crate) fn occupancy_base(resolution: [u32; 3], direction: u32, level: u32) -> u32 {
    (0..direction).map(|d| array_layers(resolution[d as usize])).sum::<u32>()
        + level_layer(resolution[direction as usize], level)
}

pub(crate) fn slice_layer(g: i32, n: u32) -> u32 {
    g.rem_euclid(n as i32) as u32
}
