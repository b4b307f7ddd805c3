//! Buffers and counts of the `Tiles` compositor for one chunk of a ViewSlices sweep (its kernels
//! and their twins: [`super::tiles`]).

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::view_slices as B;
use super::tiles::{tile_params, MAX_TRIANGLES, TILE_SIZE};
use crate::gpu::buffers::{uniform, work_buffer};
use crate::mesh::shell::Shell;
use crate::types::{SliceParams, TileAttributes, TileParams, TileTriangle};

/// Most bytes of tile-list entries per chunk by default: past them, segments are composited from
/// their planes' triangles (slower, same image).
pub(crate) const MAX_ENTRY_BYTES: u64 = 128 << 20;

/// Upper bound of a chunk's tile-list entries: per prism, the triangles its slices can have (3 per
/// plane it spans: a pentagon's fan) times the tiles its projected corners' bounding box meets
/// (every tile when a corner lies behind the camera).
pub(crate) fn entry_bound(
    shell: &Shell,
    params: &SliceParams,
    view_proj: &[[f32; 4]; 4],
    size: (u32, u32),
) -> u64 {
    let m = glam::Mat4::from_cols_array_2d(view_proj);
    let tiles = |n: u32| n.div_ceil(TILE_SIZE) as i64;
    let all = (tiles(size.0) * tiles(size.1)) as u64;
    let mut total = 0u64;
    let planes = super::PrismPlanes::new(shell, params);
    for ids in shell.triangles.iter() {
        let Some((k_min, k_max)) = planes.of(ids) else { continue };
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::splat(f32::NEG_INFINITY));
        let mut behind = false;
        for &v in ids {
            let sv = &shell.vertices[v as usize];
            for c in [sv.bottom, sv.top] {
                let clip = m * glam::Vec4::new(c[0], c[1], c[2], 1.0);
                behind |= clip.w <= 0.0;
                let q = glam::Vec2::new(clip.x, -clip.y) / clip.w * 0.5 + 0.5;
                let q = q * glam::Vec2::new(size.0 as f32, size.1 as f32);
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        let covered = if behind || !(lo.is_finite() && hi.is_finite()) {
            all
        } else {
            let span = |lo: f32, hi: f32, n: u32| {
                let a = ((lo - 1.0).floor() as i64).clamp(0, n as i64 - 1) / TILE_SIZE as i64;
                let b = ((hi + 1.0).ceil() as i64).clamp(0, n as i64 - 1) / TILE_SIZE as i64;
                (b - a + 1) as u64
            };
            span(lo.x, hi.x, size.0) * span(lo.y, hi.y, size.1)
        };
        total += 3 * (k_max - k_min + 1) as u64 * covered;
    }
    total
}

/// The entries a chunk's lists get: `requested` (tests, `RenderOptions::tile_entries`), else its
/// bound up to [`MAX_ENTRY_BYTES`].
pub(crate) fn entry_capacity(bound: u64, requested: Option<u32>) -> u32 {
    requested.unwrap_or(bound.clamp(1024, MAX_ENTRY_BYTES / 4) as u32).max(1)
}

/// Bytes of each buffer the compositor adds for a chunk: triangles, their texel coordinates,
/// cursors, entries, layer.
pub(crate) fn tile_bytes(params: &TileParams, vertex_capacity: u64) -> [(&'static str, u64); 5] {
    let segments = (params.tiles_x * params.tiles_y * params.blocks) as u64;
    let triangles = (vertex_capacity / 3).max(1);
    [
        ("tile_triangles", triangles * std::mem::size_of::<TileTriangle>() as u64),
        ("tile_attributes", triangles * std::mem::size_of::<TileAttributes>() as u64),
        ("tile_cursors", segments * 4),
        ("tile_entries", params.entry_capacity as u64 * 4),
        ("tile_layer", params.width as u64 * params.height as u64 * 16),
    ]
}

/// Adds a chunk's compositor buffers and counts to `inputs`.
pub(crate) fn add_inputs(
    ctx: &crate::gpu::GpuContext,
    inputs: &mut crate::gpu::Inputs,
    size: (u32, u32),
    planes: u32,
    entry_capacity: u32,
    vertex_capacity: u64,
) {
    let params = tile_params(size, planes, entry_capacity);
    let b = &mut inputs.buffers;
    b.insert(B::TILE_PARAMS.into(), uniform(ctx, "tile_params", bytemuck::bytes_of(&params)));
    for (name, bytes) in tile_bytes(&params, vertex_capacity) {
        b.insert(name.into(), work_buffer(ctx, name, bytes, wgpu::BufferUsages::empty()));
    }
    let triangles = (vertex_capacity / 3).min(MAX_TRIANGLES - 1) as u32;
    inputs.counts.insert(C::SLICE_TRIANGLES.into(), triangles);
    inputs.counts.insert(C::TILES_X.into(), params.tiles_x);
    inputs.counts.insert(C::TILES_Y.into(), params.tiles_y);
}
