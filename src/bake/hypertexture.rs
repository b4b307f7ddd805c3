//! Texels baked from a hypertexture (Meyer & Neyret 1998, section 3.3): a box of the
//! hypertexture's object space maps onto texel space `[0, 1]^3` and `bake_hypertexture.wgsl`
//! evaluates the density and colour transfer at each voxel centre, after `bake_transfer.wgsl`
//! has sampled the transfer functions (and, for mesh objects, `bake_mesh_grid.wgsl` the mesh).
//!
//! Opacity: a voxel stores the transfer function's opacity as it is, the opacity reached over the
//! hypertexture's opacity length, a world length for RayMarch whatever the node's scale; the
//! texel takes that same length (`scene::Texel::opacity_length`), so a slab of voxels is as opaque
//! as RayMarch makes the same world length of the hypertexture drawn at the texel's scale.

use glam::DVec3;

use crate::cpu::bake_transfer::TRANSFER_SIZE;
use crate::error::Result;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::hypertexture::{self, mesh, Packed};
use crate::scene::Hypertexture;
use crate::types::HyperParams;

/// Voxels one dispatch bakes at most: a large volume goes in slabs of whole layers.
pub const VOXELS_PER_DISPATCH: u32 = 1 << 20;

/// A hypertexture packed for the bake, with the texel's box and the gradient offset in its
/// `HyperParams` (see the kernel). Shown in `Debug` (the bake cache's key) by everything the
/// kernels read, the mesh by its digest.
#[derive(Clone)]
pub struct HyperTexel {
    /// The hypertexture's noises, transfer tables and mesh, as the kernels read them.
    pub packed: Packed,
    /// The object's parameters, with the texel's box and the gradient offset.
    pub params: HyperParams,
}

impl HyperTexel {
    /// The box `bounds` (default: the hypertexture's enlarged bounds) sampled by `resolution`
    /// voxels at `time` (only animated noises read it: a still hypertexture bakes the same at
    /// every time, and its cache key says so).
    pub fn new(h: &Hypertexture, bounds: Option<(DVec3, DVec3)>, resolution: [u32; 3], time: f64) -> Self {
        let packed = hypertexture::pack(h);
        let (lo, hi) = bounds.unwrap_or(packed.bounds);
        let time = if hypertexture::animated(&packed.noises) { time } else { 0.0 };
        let mut params = packed.params(time);
        params.bounds_min = [lo.x as f32, lo.y as f32, lo.z as f32, 0.0];
        params.bounds_max[..3].copy_from_slice(&[hi.x as f32, hi.y as f32, hi.z as f32]);
        // Central differences over half the smallest voxel edge, as the implicit bakes take them.
        let voxel = (hi - lo) / DVec3::new(resolution[0] as f64, resolution[1] as f64, resolution[2] as f64);
        params.march[1] = (0.5 * voxel.min_element()) as f32;
        HyperTexel { packed, params }
    }

    /// The box of object space the texel holds.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let p = &self.params;
        let v = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
        (v(p.bounds_min), v(p.bounds_max))
    }

    /// The kernels' override constants.
    pub(crate) fn constants(&self) -> Vec<(String, f64)> {
        match hypertexture::animated(&self.packed.noises) {
            true => vec![("animated".into(), 1.0)],
            false => Vec::new(),
        }
    }

    /// Bakes the transfer tables and then the volume (`inputs` holds `volume`, `normals` and
    /// `per_pixel_lighting`); `params` is the bake's `BakeParams`.
    pub(crate) fn bake(
        &self,
        ctx: &GpuContext,
        kernels: (&mut ComputeKernel, &mut ComputeKernel),
        encoder: &mut wgpu::CommandEncoder,
        inputs: &mut Inputs,
        params: crate::types::BakeParams,
    ) -> Result<()> {
        use crate::gpu::buffers::{storage, uniform};
        let grid = match self.packed.bake_grid(ctx)? {
            Some(grid) => grid,
            None => mesh::unused(ctx),
        };
        inputs.constants.extend(self.constants());
        let b = &mut inputs.buffers;
        b.insert("mesh_grid".into(), grid.grid);
        b.insert("mesh_depth".into(), grid.depth);
        b.insert("hyper".into(), uniform(ctx, "hyper", bytemuck::bytes_of(&self.params)));
        b.insert(
            "hyper_noises".into(),
            storage(ctx, "hyper_noises", bytemuck::cast_slice(&self.packed.noises)),
        );
        let p = &self.packed;
        b.insert("transfer_points".into(), storage(ctx, "transfer_points", bytemuck::cast_slice(&p.points)));
        b.insert(
            "transfer_functions".into(),
            storage(ctx, "transfer_functions", bytemuck::cast_slice(&p.functions)),
        );
        let words = (p.functions.len() * TRANSFER_SIZE) as u64;
        b.insert(
            "transfer_tables".into(),
            crate::gpu::buffers::work_buffer(ctx, "transfer_tables", words * 4, wgpu::BufferUsages::empty()),
        );
        let (transfer, bake) = kernels;
        transfer.dispatch(ctx, encoder, inputs, [TRANSFER_SIZE as u32, p.functions.len() as u32, 1])?;
        let [w, h, d] = [params.resolution[0], params.resolution[1], params.resolution[2]];
        let layers = (VOXELS_PER_DISPATCH / (w * h)).clamp(1, d);
        for first in (0..d).step_by(layers as usize) {
            let mut slab = params;
            slab.resolution[3] = first;
            inputs
                .buffers
                .insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&slab)));
            bake.dispatch(ctx, encoder, inputs, [w, h, layers.min(d - first)])?;
        }
        Ok(())
    }
}

impl std::fmt::Debug for HyperTexel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = &self.packed;
        let mesh = p.grid_key();
        write!(
            f,
            "HyperTexel({:?}, {:?}, {:?}, {:?}, mesh {:?})",
            self.params, p.noises, p.functions, p.points, mesh
        )
    }
}
