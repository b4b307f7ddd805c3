//! Splat sets of hypertexture objects (Gilet & Dischler 2009, section 5), baked on the GPU by
//! `bake_splats.wgsl` (CPU twin `cpu::bake_splats`): a lattice over the object's enlarged bounds,
//! a surface splat (disk, outward normal) per cell the splat surface crosses and an interior
//! splat (sphere) per cell whose centre is inside. The splat surface is where the support
//! distance equals the largest shift plus half a cell: the boundary the bounds' enlargement
//! describes, pushed out a little so that disks, which cut inside concave parts, clip no detail.

use glam::DVec3;

use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;
use crate::graph::exec::Inputs;
use crate::hypertexture::mesh::MeshGrid;
use crate::types::{HyperParams, SegmentParams, Splat};

/// Footprint pixels one invocation of `peel_segments.wgsl` tests at most (lavapipe ends every
/// loop of an invocation after 65535 iterations).
pub const FOOTPRINT_BLOCK: u32 = 32768;

/// Where the splats come from: the lattice and the splat surface's level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Cells along the bounds' longest axis (the scene's `splat_grid`).
    pub grid: u32,
    pub min: DVec3,
    pub cell: f64,
    pub counts: [u32; 3],
    /// Support distance of the splat surface.
    pub level: f64,
}

impl Lattice {
    /// `bounds`: the enlarged bounds; `shift`: the largest shift (as the kernels test it);
    /// `grid`: cells along the longest axis.
    pub fn new(bounds: (DVec3, DVec3), shift: f64, grid: u32) -> Self {
        let cell = (bounds.1 - bounds.0).max_element() / grid as f64;
        let level = shift + 0.5 * cell;
        // Beyond the bounds by the level and a cell: mesh support distances are lower bounds
        // (the splat surface may lie farther out than the bounds' enlargement).
        let pad = DVec3::splat(level + cell);
        let (lo, hi) = (bounds.0 - pad, bounds.1 + pad);
        let counts = ((hi - lo) / cell).ceil().to_array().map(|c| c as u32);
        Lattice { grid, min: lo, cell, counts, level }
    }

    pub fn cells(&self) -> u32 {
        self.counts.iter().product()
    }

    /// The centre of cell `(i, j, k)` (object space).
    pub fn centre(&self, i: u32, j: u32, k: u32) -> DVec3 {
        self.min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.cell
    }

    /// Fills the lattice fields of `params`.
    pub fn write(&self, params: &mut SegmentParams) {
        let m = self.min;
        params.lattice_min = [m.x as f32, m.y as f32, m.z as f32, self.cell as f32];
        let c = self.counts;
        params.lattice = [c[0], c[1], c[2], self.cells()];
        params.surface[0] = self.level as f32;
    }
}

/// A baked splat set on the GPU: both sets at full capacity (one splat per lattice cell) and how
/// many each holds.
#[derive(Debug, Clone)]
pub struct SplatSet {
    pub surface: wgpu::Buffer,
    pub interior: wgpu::Buffer,
    pub counts: [u32; 2],
}

/// Bytes of a splat set with `cells` lattice cells.
pub fn bytes(cells: u32) -> u64 {
    2 * cells as u64 * std::mem::size_of::<Splat>() as u64 + 16
}

/// Runs `bake_splats.wgsl` for an object (`grid`: its mesh grid, or stand-ins) and reads back
/// the splat counts.
pub fn bake(
    ctx: &GpuContext,
    hyper: &HyperParams,
    segments: &SegmentParams,
    grid: &MeshGrid,
) -> Result<SplatSet> {
    use crate::bake::{storage, uniform};
    use crate::gpu::kernel::ComputeKernel;
    let mut inputs = Inputs::default();
    let b = &mut inputs.buffers;
    b.insert("hyper".into(), uniform(ctx, "hyper", bytemuck::bytes_of(hyper)));
    b.insert("segments".into(), uniform(ctx, "segments", bytemuck::bytes_of(segments)));
    b.insert("mesh_grid".into(), grid.grid.clone());
    b.insert("mesh_depth".into(), grid.depth.clone());
    let capacity = segments.lattice[3] as u64 * std::mem::size_of::<Splat>() as u64;
    let set = |label| {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity.max(32),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    };
    let (surface, interior) = (set("surface_splats"), set("interior_splats"));
    b.insert("surface_splats".into(), surface.clone());
    b.insert("interior_splats".into(), interior.clone());
    b.insert("splat_counts".into(), storage(ctx, "splat_counts", &[0u8; 16]));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let l = segments.lattice;
    ComputeKernel::load(ctx, &Sources::project()?, "bake_splats.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [l[0], l[1], l[2]],
    )?;
    ctx.queue.submit([encoder.finish()]);
    let counts: Vec<u32> =
        bytemuck::pod_collect_to_vec(&ctx.read_buffer(&inputs.buffers["splat_counts"], 0, 8)?);
    ctx.take_errors()?;
    Ok(SplatSet { surface, interior, counts: [counts[0], counts[1]] })
}

/// The surface and interior splats of a baked set (twin tests), in the kernel's (arbitrary) order.
pub fn read(ctx: &GpuContext, set: &SplatSet) -> Result<(Vec<Splat>, Vec<Splat>)> {
    let size = std::mem::size_of::<Splat>() as u64;
    let get = |buffer: &wgpu::Buffer, count: u32| -> Result<Vec<Splat>> {
        if count == 0 {
            return Ok(Vec::new());
        }
        Ok(bytemuck::pod_collect_to_vec(&ctx.read_buffer(buffer, 0, count as u64 * size)?))
    };
    Ok((get(&set.surface, set.counts[0])?, get(&set.interior, set.counts[1])?))
}
