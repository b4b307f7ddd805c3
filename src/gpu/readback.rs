//! Textures read back to the CPU (bakes checked by tests, exports, `voltex bake`).

use crate::error::Result;
use crate::gpu::GpuContext;

/// Reads every layer (or depth slice) of level 0 of a texture back, tightly packed, in slabs of
/// layers whose staging buffer stays under 64 MiB (a large float volume would pass the
/// adapter's buffer size limit in one copy).
pub fn read_texture(ctx: &GpuContext, texture: &wgpu::Texture, bytes_per_texel: u32) -> Result<Vec<u8>> {
    read_texture_level(ctx, texture, 0, bytes_per_texel)
}

/// [`read_texture`] of MIP level `level`.
pub fn read_texture_level(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    level: u32,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let size = texture.size().mip_level_size(level, texture.dimension());
    let row = size.width * bytes_per_texel;
    let padded = row.div_ceil(256) * 256;
    let layer = padded as u64 * size.height as u64;
    let per_slab = ((64u64 << 20) / layer).clamp(1, size.depth_or_array_layers as u64) as u32;
    let mut out =
        Vec::with_capacity(row as usize * size.height as usize * size.depth_or_array_layers as usize);
    for first in (0..size.depth_or_array_layers).step_by(per_slab as usize) {
        let layers = per_slab.min(size.depth_or_array_layers - first);
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture readback"),
            size: layer * layers as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: level,
                origin: wgpu::Origin3d { x: 0, y: 0, z: first },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(size.height),
                },
            },
            wgpu::Extent3d { depth_or_array_layers: layers, ..size },
        );
        ctx.queue.submit([enc.finish()]);
        let bytes = ctx.map_read(&staging)?;
        let rows = (size.height * layers) as usize;
        out.extend((0..rows).flat_map(|y| &bytes[y * padded as usize..][..row as usize]));
    }
    Ok(out)
}
