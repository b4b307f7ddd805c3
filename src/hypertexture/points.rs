//! Point-set objects of hypertextures (Gilet & Dischler 2009, section 5.1: a volumetric object
//! defined by point samples, each with a radial kernel): baked into a grid whose first block is
//! a mesh grid's (vector to the closest surface point, signed distance, positive inside) for the
//! boundary of the union of the kernels' balls, and whose second block holds the kernel sum over
//! the saturation, the object's density. `bake_point_grid.wgsl` finds the closest ball of each
//! outside sample and the kernel sums through a BVH over the kernels' boxes
//! (`mesh::bvh::flat_bvh`), so each sample visits only the kernels near it;
//! `flood_point_grid.wgsl` then carries the outside samples' closest boundary points inwards by
//! jump flooding (passes of halving steps), so that inside samples get about their closest
//! boundary point: a field that turns smoothly, where the kernel sum's gradient deep inside a
//! cloud points anywhere.

use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::{GpuContext, Inputs};
use crate::hypertexture::mesh::MeshGrid;
use crate::mesh::points::PointSet;
use crate::mesh::shape::GridSpec;
use glam::Vec3A;
use obvhs::aabb::Aabb;

/// A point set's kernels as the bake reads them, and how far they reach.
#[derive(Debug, Clone, PartialEq)]
pub struct PointObject {
    /// The points.
    pub set: std::sync::Arc<PointSet>,
    /// The kernel radius (a PLY `radius` property scales it per point).
    pub radius: f64,
    /// The kernel sum read as density 1.
    pub saturation: f64,
    /// Where the grid's samples lie.
    pub spec: GridSpec,
}

impl PointObject {
    /// GPU bytes of the grid (two blocks of 16-byte samples), the flooding's scratch block, the
    /// kernels and their BVH.
    pub(crate) fn bytes(&self) -> u64 {
        let n = self.set.centres.len() as u64;
        3 * self.spec.samples() * 16 + n * 16 + 2 * n * 32
    }

    /// The bake cache's key.
    pub(crate) fn key(&self) -> u64 {
        crate::gpu::cache::key(&(
            "points",
            self.set.hash,
            self.radius.to_bits(),
            self.saturation.to_bits(),
            self.spec,
        ))
    }
}

/// Runs `bake_point_grid.wgsl` for `object`: one thread per sample, kernels found through a BVH.
pub fn bake(ctx: &GpuContext, object: &PointObject) -> Result<MeshGrid> {
    use crate::gpu::buffers::{storage, uniform};
    use crate::gpu::kernel::ComputeKernel;
    let set = &object.set;
    let boxes: Vec<Aabb> = (0..set.centres.len())
        .map(|i| {
            let c = set.centres[i];
            let r = set.radius(i, object.radius);
            // Grown so that f32 rounding never loses a kernel.
            let pad = r * (1.0 + 1e-5) + 1e-5 * c.abs().max_element() + 1e-6;
            let c = Vec3A::new(c.x as f32, c.y as f32, c.z as f32);
            Aabb::new(c - Vec3A::splat(pad as f32), c + Vec3A::splat(pad as f32))
        })
        .collect();
    let (nodes, order) = crate::mesh::bvh::flat_bvh(&boxes);
    let kernels: Vec<[f32; 4]> = order
        .iter()
        .map(|&i| {
            let c = set.centres[i as usize];
            [c.x as f32, c.y as f32, c.z as f32, set.radius(i as usize, object.radius) as f32]
        })
        .collect();
    let mut params = object.spec.params(kernels.len() as u32, nodes.len() as u32, 0);
    params.hi[3] = (1.0 / object.saturation) as f32;
    let bytes = 2 * object.spec.samples() * 16;
    let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
    if bytes > limit {
        return Err(crate::error::Error::Invalid(format!(
            "a point grid of {:?} samples needs {} MiB in one storage buffer, beyond this adapter's limit of {} MiB",
            object.spec.n,
            bytes >> 20,
            limit >> 20
        )));
    }
    let mut inputs = Inputs::default();
    let b = &mut inputs.buffers;
    b.insert("grid_params".into(), uniform(ctx, "grid_params", bytemuck::bytes_of(&params)));
    b.insert("point_nodes".into(), storage(ctx, "point_nodes", bytemuck::cast_slice(&nodes)));
    b.insert("point_kernels".into(), storage(ctx, "point_kernels", bytemuck::cast_slice(&kernels)));
    let grid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("point_grid"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    b.insert("mesh_grid".into(), grid.clone());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let root = Sources::project()?;
    ComputeKernel::load(ctx, &root, "bake/bake_point_grid.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        object.spec.n,
    )?;
    // The inside samples' closest boundary points, flooded between the grid and a scratch
    // buffer; an even number of passes ends in the grid.
    let mut flood = ComputeKernel::load(ctx, &root, "bake/flood_point_grid.wgsl")?;
    let scratch =
        crate::gpu::buffers::work_buffer(ctx, "flood_scratch", bytes / 2, wgpu::BufferUsages::empty());
    for (pass, step) in crate::cpu::flood_point_grid::flood_steps(object.spec.n[0]).into_iter().enumerate() {
        let mut params = params;
        params.counts[3] = step;
        let (from, to) = if pass % 2 == 0 { (&grid, &scratch) } else { (&scratch, &grid) };
        let mut inputs = Inputs::default();
        let b = &mut inputs.buffers;
        b.insert("grid_params".into(), uniform(ctx, "grid_params", bytemuck::bytes_of(&params)));
        b.insert("flood_from".into(), from.clone());
        b.insert("flood_to".into(), to.clone());
        flood.dispatch(ctx, &mut encoder, &inputs, object.spec.n)?;
    }
    ctx.queue.submit([encoder.finish()]);
    ctx.take_errors()?;
    // The largest inside distance is a mesh's density scale: unused here, 1 for the readers.
    let depth = storage(ctx, "mesh_depth", bytemuck::cast_slice(&[1.0f32, 0.0, 0.0, 0.0]));
    Ok(MeshGrid { grid, depth, colors: None })
}
