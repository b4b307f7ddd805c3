//! Self-shadowing baked into a texel (Meyer & Neyret 1998, 3.1): after the source's bake,
//! `bake/shadow_texel.wgsl` scales every voxel's colour by its transmittance towards a fixed
//! light through the texel's own opacity, into a new volume that replaces the first.

use crate::error::Result;
use crate::gpu::buffers::uniform;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::{GpuContext, Inputs};

/// The kernel's file under `wgsl/`.
pub const KERNEL: &str = "bake/shadow_texel.wgsl";

/// A texel's baked shadows: the light's texel-space direction (towards it), the extinction of
/// alpha-1 matter per texel unit and the light kept in full shadow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shadow {
    /// The direction towards the light, in texel space (normalised by the kernel).
    pub toward_light: [f32; 3],
    /// Extinction per unit of texel height at opacity 1 (times each voxel's alpha).
    pub extinction: f32,
    /// The share of the colour left in full shadow.
    pub ambient: f32,
    /// Voxels the march skips from each voxel's centre (see `cpu::shadow_texel`).
    pub bias: f32,
}

impl Shadow {
    /// The kernel's uniform for a texel of resolution `res`.
    pub fn params(&self, res: [u32; 3]) -> crate::types::ShadowParams {
        crate::cpu::shadow_texel::shadow_params(
            res,
            self.toward_light,
            self.extinction,
            self.ambient,
            self.bias,
        )
    }
}

/// Records the shadow pass reading `volume` and returns the shadowed volume (same size, format
/// usages and MIP level count; only level 0 is written, the levels below are made afterwards).
pub(crate) fn apply(
    ctx: &GpuContext,
    kernel: &mut ComputeKernel,
    encoder: &mut wgpu::CommandEncoder,
    volume: &wgpu::Texture,
    shadow: &Shadow,
) -> Result<wgpu::Texture> {
    let size = volume.size();
    let res = [size.width, size.height, size.depth_or_array_layers];
    let shadowed = super::volume_texture(ctx, "shadowed texel volume", res, volume.format());
    let params = shadow.params(res);
    let mut inputs = Inputs::default();
    inputs.buffers.insert("shadow".into(), uniform(ctx, "shadow", bytemuck::bytes_of(&params)));
    inputs.views.insert("source".into(), super::level_view(volume, 0));
    inputs.views.insert("volume".into(), super::level_view(&shadowed, 0));
    kernel.dispatch(ctx, encoder, &inputs, res)?;
    Ok(shadowed)
}
