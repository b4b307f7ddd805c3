//! Mesh objects of hypertextures (Gilet & Dischler 2009, section 5.3): a closed triangle mesh,
//! welded and checked when the scene is loaded ([`MeshShape`]), baked by `bake_mesh_grid.wgsl`
//! into a grid of `n^3` samples holding the vector to the closest surface point and the signed
//! distance to the surface (positive inside), plus the largest inside distance. The density is
//! `clamp(inside distance / largest inside distance, 0, 1)`, the soft primitives' falloff (a
//! sphere's `1 - |x| / r` is its inside distance over its radius); the ray marcher samples the
//! grid trilinearly for the density and the closest-surface field.
//!
//! A mesh made of several closed parts (edge-connected components) is their union, so parts may
//! overlap (a teapot's spout and handle through its body): each sample keeps the part with the
//! largest signed distance, which is exact outside the union and never counts a surface buried
//! in another part as the object's boundary.

use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::{GpuContext, Inputs};
use crate::mesh::shape::{GridSpec, MeshShape};
use glam::Vec3A;
use obvhs::aabb::Aabb;

/// A baked mesh grid on the GPU: its samples (xyz: vector to the closest surface point; w:
/// signed distance, positive inside) and the largest inside distance (f32 bits, one word).
#[derive(Clone)]
pub struct MeshGrid {
    pub(crate) grid: wgpu::Buffer,
    pub(crate) depth: wgpu::Buffer,
    /// Coloured meshes: per sample the colour at its closest surface point (rgb, w = 1),
    /// interpolated from the closest triangle's corners.
    pub colors: Option<wgpu::Buffer>,
}

impl crate::gpu::cache::GpuBytes for MeshGrid {
    fn gpu_bytes(&self) -> u64 {
        self.grid.gpu_bytes() + self.depth.gpu_bytes() + self.colors.gpu_bytes()
    }
}

/// Runs `bake_mesh_grid.wgsl` for `shape` over `spec`: one thread per sample, closest points
/// and ray crossings found through a BVH per part (`mesh::bvh::flat_bvh`).
pub fn bake(ctx: &GpuContext, shape: &MeshShape, spec: &GridSpec) -> Result<MeshGrid> {
    use crate::gpu::buffers::{storage, uniform};
    use crate::gpu::kernel::ComputeKernel;
    // One BVH per part, concatenated: a part's root, then its nodes; leaves index the triangles
    // (in each part's leaf order), inner nodes their first child, both offset to the whole.
    let mut nodes = Vec::new();
    let mut corners: Vec<[f32; 4]> = Vec::new();
    let mut corner_colors: Vec<[f32; 4]> = Vec::new();
    let mut roots: Vec<[u32; 4]> = Vec::new();
    for &(first, count) in &shape.parts {
        let boxes: Vec<Aabb> = (first..first + count)
            .map(|t| {
                let pts = shape.triangle(t as usize).map(|p| Vec3A::new(p.x as f32, p.y as f32, p.z as f32));
                let b = Aabb::from_points(&pts);
                // Grown so that f32 rounding never loses a triangle.
                let pad = Vec3A::splat(1e-5 * (b.max - b.min).max_element() + 1e-6);
                Aabb::new(b.min - pad, b.max + pad)
            })
            .collect();
        let (part_nodes, order) = crate::mesh::bvh::flat_bvh(&boxes);
        let (node_base, tri_base) = (nodes.len() as u32, (corners.len() / 3) as u32);
        roots.push([node_base, first, count, 0]);
        nodes.extend(part_nodes.into_iter().map(|mut n| {
            let leaf = n.min[3].to_bits() > 0;
            let base = if leaf { tri_base } else { node_base };
            n.max[3] = f32::from_bits(n.max[3].to_bits() + base);
            n
        }));
        corners.extend(order.iter().flat_map(|&t| {
            shape.triangle((first + t) as usize).map(|p| [p.x as f32, p.y as f32, p.z as f32, 0.0])
        }));
        if let Some(colors) = &shape.colors {
            let rgba = |c: [f32; 3]| [c[0], c[1], c[2], 1.0];
            corner_colors.extend(order.iter().flat_map(|&t| colors[(first + t) as usize].map(rgba)));
        }
    }
    let params = spec.params(shape.triangles.len() as u32, nodes.len() as u32, roots.len() as u32);
    let mut inputs = Inputs::default();
    let b = &mut inputs.buffers;
    b.insert("grid_params".into(), uniform(ctx, "grid_params", bytemuck::bytes_of(&params)));
    b.insert("mesh_parts".into(), storage(ctx, "mesh_parts", bytemuck::cast_slice(&roots)));
    b.insert("mesh_nodes".into(), storage(ctx, "mesh_nodes", bytemuck::cast_slice(&nodes)));
    b.insert("mesh_triangles".into(), storage(ctx, "mesh_triangles", bytemuck::cast_slice(&corners)));
    let bytes = spec.samples() * 16;
    let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
    if bytes > limit {
        return Err(crate::error::Error::Invalid(format!(
            "a mesh grid of {:?} samples needs {} MiB in one storage buffer, beyond this adapter's limit of {} MiB",
            spec.n,
            bytes >> 20,
            limit >> 20
        )));
    }
    let grid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mesh_grid"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let depth = storage(ctx, "mesh_depth", &[0u8; 16]);
    b.insert("mesh_grid".into(), grid.clone());
    b.insert("mesh_depth".into(), depth.clone());
    // Colours only for coloured meshes (override `colored`); 16-byte stand-ins otherwise.
    let colored = !corner_colors.is_empty();
    let colors = colored.then(|| {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mesh_colors"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    });
    corner_colors.resize(corner_colors.len().max(1), [0.0; 4]);
    b.insert(
        "mesh_corner_colors".into(),
        storage(ctx, "mesh_corner_colors", bytemuck::cast_slice(&corner_colors)),
    );
    let stand_in = || storage(ctx, "mesh_colors", &[0u8; 16]);
    b.insert("mesh_colors".into(), colors.clone().unwrap_or_else(stand_in));
    inputs.constants.push(("colored".into(), colored as u32 as f64));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    ComputeKernel::load(ctx, &Sources::project()?, "bake/bake_mesh_grid.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        spec.n,
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.take_errors()?;
    Ok(MeshGrid { grid, depth, colors })
}

/// The samples and the largest inside distance of a baked grid (twin tests).
pub fn read(ctx: &GpuContext, g: &MeshGrid) -> Result<(Vec<[f32; 4]>, f32)> {
    let cells = bytemuck::pod_collect_to_vec(&ctx.read_buffer(&g.grid, 0, g.grid.size())?);
    let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&ctx.read_buffer(&g.depth, 0, 4)?);
    Ok((cells, depth[0]))
}

/// Stand-ins bound for objects that are not meshes (the kernels declare the bindings).
pub(crate) fn unused(ctx: &GpuContext) -> MeshGrid {
    let b = |label| crate::gpu::buffers::storage(ctx, label, &[0u8; 16]);
    MeshGrid { grid: b("mesh_grid"), depth: b("mesh_depth"), colors: None }
}
