//! A texel's layers (`ViewSlices(lod: Auto)`): its w slices as a 2D texture array whose MIP
//! levels filter s and t only, so that each fragment can sample the level of its own footprint
//! without blurring the height profile (a 3D MIP chain also halves w). Level 0 is the volume in
//! f16 (`layer_texel_volume.wgsl`), each level the one above by a 2x2 box within its layer,
//! wrapping as the texel repeats (`mip_layers.wgsl`, as AxisSlices' slice images; twin
//! `crate::cpu::mip_layers`).

use crate::error::Result;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::{GpuContext, Inputs};

/// The kernel copying a volume into layers, and the one making their MIP levels.
pub(crate) const COPY_KERNEL: &str = "bake/layer_texel_volume.wgsl";
pub(crate) const MIP_KERNEL: &str = "bake/mip_layers.wgsl";

/// MIP levels of the layers of a texel of `res`: s and t halve down to 1x1, w stays.
pub fn mip_levels(res: [u32; 3]) -> u32 {
    image_levels([res[0], res[1]])
}

/// Bytes of the layers of a texel of `res` (f16 RGBA, every level): one layer a w voxel.
pub(crate) fn bytes(res: [u32; 3]) -> u64 {
    image_bytes([res[0], res[1]], true) * res[2] as u64
}

/// MIP levels of a 2D image of `size` (a layer, a slice image), down to 1x1.
pub fn image_levels(size: [u32; 2]) -> u32 {
    32 - size[0].max(size[1]).max(1).leading_zeros()
}

/// Bytes of one f16 RGBA image of `size`, with its MIP levels when `mipmaps`.
pub(crate) fn image_bytes(size: [u32; 2], mipmaps: bool) -> u64 {
    let levels = if mipmaps { image_levels(size) } else { 1 };
    (0..levels).map(|l| (size[0] >> l).max(1) as u64 * (size[1] >> l).max(1) as u64 * 8).sum()
}

/// A 2D texture array of `layers` layers of `size`, `levels` MIP levels, f16 RGBA (texel layers,
/// AxisSlices' slice images).
pub(crate) fn texture(
    ctx: &GpuContext,
    label: &str,
    size: [u32; 2],
    layers: u32,
    levels: u32,
) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: layers },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// A view of the whole array (every level), as the slicing kernels sample it.
pub(crate) fn array_view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

/// A view of one MIP level of a 2D texture array.
pub(crate) fn level_view(t: &wgpu::Texture, level: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        base_mip_level: level,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

/// Records the layers of `volume` (level 0 baked) with every MIP level.
pub(crate) fn record(
    ctx: &GpuContext,
    (copy, mip): (&mut ComputeKernel, &mut ComputeKernel),
    encoder: &mut wgpu::CommandEncoder,
    volume: &wgpu::Texture,
    label: &str,
) -> Result<wgpu::Texture> {
    let res = [volume.width(), volume.height(), volume.depth_or_array_layers()];
    let layers = texture(ctx, label, [res[0], res[1]], res[2], mip_levels(res));
    let mut inputs = Inputs::default();
    inputs.views.insert("source".into(), super::level_view(volume, 0));
    inputs.views.insert("layers".into(), level_view(&layers, 0));
    copy.dispatch(ctx, encoder, &inputs, res)?;
    record_mips(ctx, mip, encoder, &layers, true)?;
    Ok(layers)
}

/// Records every MIP level of the 2D texture array `array` (level 0 made) with `mip_layers`,
/// each from the one above; rows wrap with `wrap_rows` (columns always do).
pub(crate) fn record_mips(
    ctx: &GpuContext,
    kernel: &mut ComputeKernel,
    encoder: &mut wgpu::CommandEncoder,
    array: &wgpu::Texture,
    wrap_rows: bool,
) -> Result<()> {
    for level in 1..array.mip_level_count() {
        let mut inputs = Inputs::default();
        inputs.views.insert("finer".into(), level_view(array, level - 1));
        inputs.views.insert("coarser".into(), level_view(array, level));
        inputs.constants.push(("wrap_rows".into(), wrap_rows as u32 as f64));
        let (w, h) = ((array.width() >> level).max(1), (array.height() >> level).max(1));
        kernel.dispatch(ctx, encoder, &inputs, [w, h, array.depth_or_array_layers()])?;
    }
    Ok(())
}
