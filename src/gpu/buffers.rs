//! Buffer helpers: uniform and storage buffers filled from bytes, and uninitialised work buffers.

use crate::gpu::GpuContext;

/// A uniform buffer holding `bytes` (padded to 4). Also bindable as read-only storage: kernels
/// whose loops depend on their parameters read them so (`composite_tiles`), since lavapipe's
/// uniform inlining overflows a fixed array on such kernels (a crash in Mesa 22.3).
pub(crate) fn uniform(ctx: &GpuContext, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    filled(
        ctx,
        label,
        bytes,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    )
}

/// A buffer holding `bytes` (padded to 4). Written through the queue: wgpu's
/// `create_buffer_init` maps the buffer at creation and panics when the device is lost.
fn filled(ctx: &GpuContext, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let mut data = bytes.to_vec();
    data.resize(bytes.len().next_multiple_of(4), 0);
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: data.len() as u64,
        usage,
        mapped_at_creation: false,
    });
    if !data.is_empty() {
        ctx.queue.write_buffer(&buffer, 0, &data);
    }
    buffer
}

/// An uninitialised storage buffer of `size` bytes (at least 16: empty bindings are invalid),
/// copyable both ways, with `extra` usages (e.g. INDIRECT).
pub(crate) fn work_buffer(
    ctx: &GpuContext,
    label: &str,
    size: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC
            | extra,
        mapped_at_creation: false,
    })
}

pub(crate) fn storage(ctx: &GpuContext, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
    filled(ctx, label, bytes, usage)
}
