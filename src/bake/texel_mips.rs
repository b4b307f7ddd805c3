//! MIP levels of a texel volume (`ViewSlices(lod: Auto)`): each level from the one above by a
//! 2x2x2 box (`mip_texel_volume.wgsl`; twin `crate::cpu::mip_texel_volume`).

use crate::error::Result;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::{GpuContext, Inputs};

/// MIP levels of a 3D texture of `res`, down to 1x1x1 (each axis halves, at least 1).
pub fn mip_levels(res: [u32; 3]) -> u32 {
    32 - res[0].max(res[1]).max(res[2]).max(1).leading_zeros()
}

/// Voxels of a volume of `res` with its MIP levels (`mipmaps`) or level 0 alone.
pub(crate) fn voxels(res: [u32; 3], mipmaps: bool) -> u64 {
    let levels = if mipmaps { mip_levels(res) } else { 1 };
    (0..levels).map(|l| res.iter().map(|&r| (r >> l).max(1) as u64).product::<u64>()).sum()
}

/// Records every MIP level of `texture` (level 0 baked), each from the one above.
pub(crate) fn record(
    ctx: &GpuContext,
    kernel: &mut ComputeKernel,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> Result<()> {
    for level in 1..texture.mip_level_count() {
        let mut inputs = Inputs::default();
        inputs.views.insert("finer".into(), super::level_view(texture, level - 1));
        inputs.views.insert("coarser".into(), super::level_view(texture, level));
        let size = texture.size().mip_level_size(level, wgpu::TextureDimension::D3);
        kernel.dispatch(ctx, encoder, &inputs, [size.width, size.height, size.depth_or_array_layers])?;
    }
    Ok(())
}
