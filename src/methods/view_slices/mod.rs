//! Host side of view-aligned prism slicing (2002 paper): the plane sweep of one object and the
//! buffers its kernels (`count_slices`, `scan_plane_offsets`, `emit_slices`) and `draw_slices` use.

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::view_slices as knobs;
pub mod lod;
mod object;
pub(crate) mod plugin;
pub mod slice_prisms;
pub(crate) mod tile_buffers;
pub mod tiles;

pub use object::{plan, ViewSlicesPlan};

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::view_slices as B;
use crate::error::{Error, Result};
use crate::mesh::shell::Shell;
use crate::types::{SliceParams, SliceVertex};

/// The planes of the instance's chunk: a count for graphs (no built-in graph dispatches by it,
/// so `gpu::bindings::counts` has no constant for it).
const PLANES: &str = "planes";

/// What ViewSlices brings to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "ViewSlices",
    filters: &["ViewSlices", "ViewSlicesRaster", "ViewSlicesTiles"],
    resources: &[
        B::SLICE_PARAMS,
        B::SHELL_VERTICES,
        B::PRISMS,
        B::PRISM_SPHERES,
        B::PLANE_CURSORS,
        B::DRAW_ARGS,
        B::PLANE_DRAWS,
        B::SLICE_VERTICES,
        B::VOLUME,
        B::NORMALS,
        B::VOLUME_LAYERS,
        B::NORMAL_LAYERS,
        B::VERTEX_FRAMES,
        B::TILE_PARAMS,
        B::TILE_TRIANGLES,
        B::TILE_ATTRIBUTES,
        B::TILE_CURSORS,
        B::TILE_ENTRIES,
        B::TILE_LAYER,
    ],
    counts: &[C::PRISMS, PLANES, C::PLANE_BLOCKS, C::SLICE_TRIANGLES, C::TILES_X, C::TILES_Y],
    texel_resources: &[B::VOLUME, B::NORMALS, B::VOLUME_LAYERS, B::NORMAL_LAYERS],
    gather: None,
};

/// The plane sweep: `planes` planes orthogonal to the view direction spanning the shell's depth
/// range (clipped to the near plane), back to front, each in the middle of its slab.
pub fn sweep(shell: &Shell, forward: [f32; 3], planes: u32, near: f64) -> SliceParams {
    let (lo, hi) = shell.depth_range(forward);
    let lo = lo.max(near);
    // A flat range still gets distinct planes, far from the origin too.
    let hi = hi.max(lo + 1e-9 * lo.abs().max(1.0));
    let spacing = (hi - lo) / planes as f64;
    SliceParams {
        plane_normal: [forward[0], forward[1], forward[2], 0.0],
        first_plane: (hi - 0.5 * spacing) as f32,
        spacing: spacing as f32,
        plane_count: planes,
        prism_count: shell.prisms.len() as u32,
        vertex_capacity: 0,
        _pad: [0; 3],
    }
}

/// Planes one thread of `count_slices` / `emit_slices` loops over (WGSL override
/// `planes_per_thread`; the dispatch's y size is the plane count divided by it).
pub(crate) const PLANES_PER_THREAD: u32 = 32;

/// Slice-vertex budget of one chunk of a sweep: the storage-binding size every WebGPU adapter
/// offers (128 MiB), so a chunk binds everywhere.
pub(crate) const CHUNK_BYTES: u64 = 128 << 20;

/// A run of consecutive planes of a sweep with its own buffers, sized to fit one binding.
#[derive(Clone, Copy, Debug)]
pub struct SliceChunk {
    /// The chunk's planes (`first_plane` and `plane_count` of the chunk; the spacing of the sweep).
    pub params: SliceParams,
    /// Slice-vertex capacity (an upper bound of what the chunk emits).
    pub(crate) capacity: u64,
}

/// Upper bound of the triangle-list vertices each plane of the sweep emits: per prism, 9 (a
/// pentagon is 3 triangles) on every plane its depth range crosses. Allocating this, not
/// planes x prisms x 9, keeps memory proportional to what is drawn.
pub(crate) fn plane_bounds(shell: &Shell, params: &SliceParams) -> Vec<u64> {
    // Difference array: +9 where a prism's plane range starts, -9 after it ends; in four lanes,
    // so that neighbouring prisms (mostly on the same planes) do not wait on each other's sums.
    let mut diff = vec![[0i64; 4]; params.plane_count as usize + 1];
    let planes = PrismPlanes::new(shell, params);
    for (i, p) in shell.triangles.iter().enumerate() {
        if let Some((k_min, k_max)) = planes.of(p) {
            diff[k_min as usize][i % 4] += 9;
            diff[k_max as usize + 1][i % 4] -= 9;
        }
    }
    let mut running = 0i64;
    diff[..params.plane_count as usize]
        .iter()
        .map(|d| {
            running += d.iter().sum::<i64>();
            running as u64
        })
        .collect()
}

/// The planes of a sweep (or chunk) each prism's corners span: per prism `[k_min, k_max]`,
/// the planes k with `lo <= first - k * spacing <= hi` over its six corners' depths, widened by
/// one plane for f32 rounding.
///
/// Made per vertex, then combined per prism: `floor((first - d) / spacing)` never rises as the
/// depth `d` grows (each operation rounds monotonically), so a prism's bound is the least (or
/// greatest) of its vertices' and equals the bound of its corners' depth range exactly, at a
/// sixth of the dot products (a camera move plans every prism of a million-triangle shell).
pub(crate) struct PrismPlanes {
    /// Per shell vertex: `floor((first - hi) / spacing)` and `ceil((first - lo) / spacing)` of
    /// its bottom's and top's depths.
    vertices: Vec<(i64, i64)>,
    last: i64,
}

impl PrismPlanes {
    pub(crate) fn new(shell: &Shell, params: &SliceParams) -> Self {
        let n = params.plane_normal.map(|x| x as f64);
        let spacing = params.spacing as f64;
        let first = params.first_plane as f64;
        let depth = |c: [f32; 4]| n[0] * c[0] as f64 + n[1] * c[1] as f64 + n[2] * c[2] as f64;
        // `x.floor() as i64` and `x.ceil() as i64` (saturating, NaN to 0) without the calls to
        // libm that the baseline x86-64 target makes of `floor` and `ceil`.
        let floor = |x: f64| {
            let i = x as i64;
            if i as f64 > x { i.saturating_sub(1) } else { i }
        };
        let ceil = |x: f64| {
            let i = x as i64;
            if (i as f64) < x { i.saturating_add(1) } else { i }
        };
        let vertices = shell
            .vertices
            .iter()
            .map(|v| {
                let (b, t) = (depth(v.bottom), depth(v.top));
                let (lo, hi) = (b.min(t), b.max(t));
                (floor((first - hi) / spacing), ceil((first - lo) / spacing))
            })
            .collect();
        Self { vertices, last: params.plane_count as i64 - 1 }
    }

    /// The planes `[k_min, k_max]` prism `p` (of the shell this was made for) spans; `None` when
    /// there is none.
    pub(crate) fn of(&self, ids: &[u32; 3]) -> Option<(u32, u32)> {
        let v = |i: usize| self.vertices[ids[i] as usize];
        let (a, b, c) = (v(0), v(1), v(2));
        let k_min = a.0.min(b.0).min(c.0).saturating_sub(1).max(0);
        let k_max = a.1.max(b.1).max(c.1).saturating_add(1).min(self.last);
        (k_max >= k_min).then_some((k_min as u32, k_max as u32))
    }
}

/// Total slice-vertex capacity of a sweep (see `plane_bounds`).
pub fn vertex_capacity(shell: &Shell, params: &SliceParams) -> u64 {
    plane_bounds(shell, params).iter().sum()
}

/// Splits a sweep into chunks of consecutive planes whose vertex bound fits `CHUNK_BYTES`,
/// back to front.
pub fn chunks(shell: &Shell, params: &SliceParams) -> Vec<SliceChunk> {
    let budget = CHUNK_BYTES / std::mem::size_of::<SliceVertex>() as u64;
    let bounds = plane_bounds(shell, params);
    let mut out = Vec::new();
    let (mut start, mut capacity) = (0usize, 0u64);
    let close = |start: usize, end: usize, capacity: u64, out: &mut Vec<SliceChunk>| {
        let mut p = *params;
        p.first_plane = (params.first_plane as f64 - start as f64 * params.spacing as f64) as f32;
        p.plane_count = (end - start) as u32;
        p.vertex_capacity = capacity.max(3) as u32;
        out.push(SliceChunk { params: p, capacity: capacity.max(3) });
    };
    for (k, &b) in bounds.iter().enumerate() {
        if capacity + b > budget && k > start {
            close(start, k, capacity, &mut out);
            (start, capacity) = (k, 0);
        }
        capacity += b;
    }
    close(start, bounds.len(), capacity, &mut out);
    out
}

/// Most slice-vertex memory one object may use (all chunks together).
pub(crate) const MAX_SLICE_BYTES: u64 = 1 << 30;

/// Checks a sweep's slice-vertex memory against [`MAX_SLICE_BYTES`].
pub(crate) fn check_budget(chunks: &[SliceChunk], object: &str, planes: u32) -> Result<()> {
    let bytes = chunks.iter().map(|c| c.capacity).sum::<u64>() * std::mem::size_of::<SliceVertex>() as u64;
    if bytes > MAX_SLICE_BYTES {
        return Err(Error::Invalid(format!(
            "object `{object}`: {planes} planes need up to {:.0} MiB of slice vertices, beyond the limit of \
             {} MiB per object; use fewer planes",
            bytes as f64 / 1048576.0,
            MAX_SLICE_BYTES >> 20
        )));
    }
    Ok(())
}

/// Checks that a chunk's slice-vertex buffer fits the adapter's limits.
pub(crate) fn check_capacity(capacity: u64, max_binding: u64, object: &str, planes: u32) -> Result<()> {
    let bytes = capacity * std::mem::size_of::<SliceVertex>() as u64;
    if bytes > max_binding || capacity > u32::MAX as u64 {
        return Err(Error::Gpu(format!(
            "object `{object}`: {planes} planes need up to {:.1} MiB of slice vertices in one binding, beyond \
             this adapter's storage-binding limit of {:.1} MiB",
            bytes as f64 / 1048576.0,
            max_binding as f64 / 1048576.0
        )));
    }
    Ok(())
}

/// Adds the buffers and counts of one sliced shell to `inputs` (the names the kernels use).
pub fn add_inputs(
    ctx: &crate::gpu::GpuContext,
    inputs: &mut crate::gpu::Inputs,
    shell: &Shell,
    params: &SliceParams,
    capacity: u64,
    trivial_reject: bool,
) {
    use crate::gpu::buffers::{storage, uniform};
    let buffer = |label: &str, size: u64, extra| crate::gpu::buffers::work_buffer(ctx, label, size, extra);
    let b = &mut inputs.buffers;
    b.insert(B::SLICE_PARAMS.into(), uniform(ctx, "slice_params", bytemuck::bytes_of(params)));
    b.insert(B::SHELL_VERTICES.into(), storage(ctx, "shell_vertices", bytemuck::cast_slice(&shell.vertices)));
    b.insert(B::PRISMS.into(), storage(ctx, "prisms", bytemuck::cast_slice(&shell.prisms)));
    b.insert(B::PRISM_SPHERES.into(), storage(ctx, "prism_spheres", bytemuck::cast_slice(&shell.spheres)));
    b.insert(
        "plane_cursors".into(),
        buffer("plane_cursors", params.plane_count as u64 * 4, wgpu::BufferUsages::empty()),
    );
    b.insert(B::DRAW_ARGS.into(), buffer("draw_args", 16, wgpu::BufferUsages::INDIRECT));
    let per_plane = params.plane_count as u64 * std::mem::size_of::<crate::types::DrawIndirect>() as u64;
    b.insert(B::PLANE_DRAWS.into(), buffer("plane_draws", per_plane, wgpu::BufferUsages::INDIRECT));
    inputs.plane_depths = (0..params.plane_count)
        .map(|k| params.first_plane as f64 - k as f64 * params.spacing as f64)
        .collect();
    let bytes = capacity * std::mem::size_of::<SliceVertex>() as u64;
    b.insert(B::SLICE_VERTICES.into(), buffer("slice_vertices", bytes, wgpu::BufferUsages::empty()));
    inputs.counts.insert(C::PRISMS.into(), shell.prisms.len() as u32);
    inputs.counts.insert(PLANES.into(), params.plane_count);
    inputs.counts.insert(C::PLANE_BLOCKS.into(), params.plane_count.div_ceil(PLANES_PER_THREAD));
    inputs.constants.push(("planes_per_thread".into(), PLANES_PER_THREAD as f64));
    inputs.constants.push(("trivial_reject".into(), trivial_reject as u32 as f64));
}

/// Reads back the triangle-list vertices of each plane after a frame (tests, debugging): after
/// `emit_slices`, `plane_cursors[k]` is the end of plane k's range.
pub fn read_back(
    ctx: &crate::gpu::GpuContext,
    inputs: &crate::gpu::Inputs,
    plane_count: u32,
) -> Result<Vec<Vec<SliceVertex>>> {
    let args = ctx.read_buffer(&inputs.buffers["draw_args"], 0, 16)?;
    let drawn = bytemuck::pod_read_unaligned::<u32>(&args[..4]) as usize;
    let ends = ctx.read_buffer(&inputs.buffers["plane_cursors"], 0, plane_count as u64 * 4)?;
    let ends: Vec<u32> = bytemuck::pod_collect_to_vec(&ends);
    let bytes = if drawn > 0 {
        ctx.read_buffer(&inputs.buffers["slice_vertices"], 0, drawn as u64 * 32)?
    } else {
        Vec::new()
    };
    let all: Vec<SliceVertex> = bytemuck::pod_collect_to_vec(&bytes);
    let mut start = 0usize;
    Ok(ends
        .into_iter()
        .map(|end| {
            let end = (end as usize).min(all.len());
            let plane = all[start.min(end)..end].to_vec();
            start = end;
            plane
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prism's planes by their definition: the depth range of its six corners.
    fn by_corners(shell: &Shell, ids: &[u32; 3], params: &SliceParams) -> Option<(u32, u32)> {
        let n = params.plane_normal.map(|x| x as f64);
        let (spacing, first) = (params.spacing as f64, params.first_plane as f64);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in ids {
            let sv = &shell.vertices[v as usize];
            for c in [sv.bottom, sv.top] {
                let d = n[0] * c[0] as f64 + n[1] * c[1] as f64 + n[2] * c[2] as f64;
                (lo, hi) = (lo.min(d), hi.max(d));
            }
        }
        let k_min = (((first - hi) / spacing).floor() as i64 - 1).max(0);
        let k_max = (((first - lo) / spacing).ceil() as i64 + 1).min(params.plane_count as i64 - 1);
        (k_max >= k_min).then_some((k_min as u32, k_max as u32))
    }

    /// Per-vertex plane ranges combined per prism equal the corners' ranges exactly, for sweeps
    /// from several views with few and many planes (chunks too: a later first plane).
    #[test]
    fn prism_planes_from_vertices_equal_the_corners_ranges() {
        let surface = crate::mesh::shell::tests::bumpy(30);
        let mut spanned = 0usize;
        for (k, eye) in [glam::DVec3::new(0.5, -4.0, 3.0), glam::DVec3::new(4.0, 2.0, 1.0)].into_iter().enumerate() {
            let shell = Shell::new(&surface, eye);
            let forward = (-eye).normalize().as_vec3().to_array();
            for planes in [1, 7, 64, 1000] {
                let mut params = sweep(&shell, forward, planes, 1e-3);
                params.first_plane -= k as f32 * 3.0 * params.spacing;
                let fast = PrismPlanes::new(&shell, &params);
                for p in shell.triangles.iter() {
                    let range = fast.of(p);
                    assert_eq!(range, by_corners(&shell, p, &params), "{planes} planes, prism {p:?}");
                    spanned += range.is_some() as usize;
                }
            }
        }
        assert!(spanned > 10_000, "{spanned}");
    }
}

