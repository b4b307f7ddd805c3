//! Splat sets of hypertexture objects (Gilet & Dischler 2009, section 5), baked on the GPU by
//! `bake_splats.wgsl` (CPU twin `cpu::bake_splats`): a lattice over the object's enlarged bounds,
//! a surface splat (disk, outward normal) per cell the splat surface crosses and an interior
//! splat (sphere) per cell whose centre is inside. The splat surface is where the support
//! distance equals the largest shift plus half a cell: the boundary the bounds' enlargement
//! describes, pushed out a little so that disks, which cut inside concave parts, clip no detail.

use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::hypertexture::mesh::MeshGrid;
use crate::types::{HyperParams, SegmentParams, Splat};

/// Footprint pixels one invocation of `peel_segments.wgsl` tests at most (lavapipe ends every
/// loop of an invocation after 65535 iterations).
pub(crate) const FOOTPRINT_BLOCK: u32 = 32768;

pub(crate) use crate::cpu::bake_splats::Lattice;

/// A baked splat set on the GPU: both sets at full capacity (one splat per lattice cell) and how
/// many each holds.
#[derive(Debug, Clone)]
pub struct SplatSet {
    pub(crate) surface: wgpu::Buffer,
    pub(crate) interior: wgpu::Buffer,
    pub(crate) counts: [u32; 2],
}

impl crate::gpu::cache::GpuBytes for SplatSet {
    fn gpu_bytes(&self) -> u64 {
        self.surface.gpu_bytes() + self.interior.gpu_bytes()
    }
}

/// Bytes of a splat set with `cells` lattice cells.
pub(crate) fn bytes(cells: u32) -> u64 {
    2 * cells as u64 * std::mem::size_of::<Splat>() as u64 + 16
}

/// Runs `kernel` (the method's `bake_splats.wgsl`) for an object (`grid`: its mesh grid, or
/// stand-ins) and reads back the splat counts.
pub(crate) fn bake(
    ctx: &GpuContext,
    kernel: &str,
    hyper: &HyperParams,
    segments: &SegmentParams,
    grid: &MeshGrid,
) -> Result<SplatSet> {
    use crate::gpu::buffers::{storage, uniform};
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
    ComputeKernel::load(ctx, &Sources::project()?, kernel)?.dispatch(
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
