//! Mesh objects of hypertextures (Gilet & Dischler 2009, section 5.3): a closed triangle mesh,
//! welded and checked when the scene is loaded ([`MeshShape`]), baked by `bake_mesh_grid.wgsl`
//! into a grid of `n^3` samples holding the vector to the closest surface point and the signed
//! distance to the surface (positive inside), plus the largest inside distance. The density is
//! `clamp(inside distance / largest inside distance, 0, 1)`, the soft primitives' falloff (a
//! sphere's `1 - |x| / r` is its inside distance over its radius); the ray marcher samples the
//! grid trilinearly for the density and the closest-surface field.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::Path;

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::exec::Inputs;
use crate::mesh::Mesh;
use crate::types::MeshGridParams;

/// Most samples per axis of a mesh grid (16 bytes each: 32 MiB at 128).
pub const MAX_RESOLUTION: u32 = 128;

/// A closed triangle mesh in its node's frame, vertices welded by position.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshShape {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub lo: DVec3,
    pub hi: DVec3,
    /// Of positions and triangles: the bake cache's key.
    pub hash: u64,
}

/// Where a mesh grid's samples lie: `n` per axis at the vertices of the box `lo..hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    pub lo: DVec3,
    pub hi: DVec3,
    pub n: u32,
}

impl GridSpec {
    /// The sample `(i, j, k)` in object space.
    pub fn point(&self, i: u32, j: u32, k: u32) -> DVec3 {
        let f = DVec3::new(i as f64, j as f64, k as f64) / (self.n - 1) as f64;
        self.lo + (self.hi - self.lo) * f
    }

    pub fn params(&self, triangles: u32, nodes: u32) -> MeshGridParams {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        MeshGridParams { lo: f(self.lo), hi: f(self.hi), counts: [self.n, triangles, nodes, 0] }
    }
}

impl MeshShape {
    /// Welds `mesh` by position and checks that it is closed (every edge shared by an even
    /// number of triangles, so ray parity says inside or outside) and encloses a volume. Errors
    /// name `path` and the line of the offending face.
    pub fn new(mesh: &Mesh, path: &Path) -> std::result::Result<Self, String> {
        let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let weld: Vec<u32> = mesh
            .positions
            .iter()
            .map(|p| {
                *ids.entry(p.to_array().map(f64::to_bits)).or_insert_with(|| {
                    positions.push(*p);
                    positions.len() as u32 - 1
                })
            })
            .collect();
        let mut triangles = Vec::new();
        let mut lines = Vec::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| weld[i as usize]);
            // A triangle with a repeated vertex bounds nothing.
            if a != b && b != c && a != c {
                triangles.push([a, b, c]);
                lines.push(mesh.face_lines.get(t).copied().unwrap_or(0));
            }
        }
        let at = |t: usize| match lines.get(t) {
            Some(&l) if l > 0 => format!("{}:{l}:1", path.display()),
            _ => path.display().to_string(),
        };
        if triangles.is_empty() {
            return Err(format!("{}: degenerate mesh: every triangle repeats a vertex", path.display()));
        }
        let mut edges: HashMap<(u32, u32), (u32, usize)> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_insert((0, t)).0 += 1;
            }
        }
        let mut open: Vec<_> = edges.iter().filter(|(_, (count, _))| count % 2 == 1).collect();
        open.sort_by_key(|(_, (_, t))| *t);
        if let Some(((a, b), (count, t))) = open.first() {
            let (pa, pb) = (positions[*a as usize], positions[*b as usize]);
            return Err(format!(
                "{}: open mesh: the edge from ({}, {}, {}) to ({}, {}, {}) of this face belongs to {count} \
                 triangle(s) ({} open edges in all): expected a closed mesh, every edge shared by two triangles",
                at(*t),
                pa.x,
                pa.y,
                pa.z,
                pb.x,
                pb.y,
                pb.z,
                open.len()
            ));
        }
        let lo = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        let volume: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize] - lo);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let extent = (hi - lo).max_element();
        if volume.abs() <= 1e-9 * extent.powi(3) {
            return Err(format!(
                "{}: degenerate mesh: it encloses no volume (bounds {:?} to {:?})",
                path.display(),
                lo.to_array(),
                hi.to_array()
            ));
        }
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for p in &positions {
            p.to_array().map(f64::to_bits).hash(&mut h);
        }
        triangles.hash(&mut h);
        Ok(MeshShape { positions, triangles, lo, hi, hash: h.finish() })
    }

    /// The grid of `n` samples per axis over the mesh's bounds enlarged by the largest shift (the
    /// field is needed wherever a noise may shift a point from) and two cells.
    pub fn grid(&self, n: u32, max_shift: f64) -> GridSpec {
        let extent = (self.hi - self.lo).max_element() + 2.0 * max_shift;
        let pad = max_shift + 2.0 * extent / (n - 1) as f64;
        GridSpec { lo: self.lo - DVec3::splat(pad), hi: self.hi + DVec3::splat(pad), n }
    }

    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }
}

/// A baked mesh grid on the GPU: `n^3` samples (xyz: vector to the closest surface point; w:
/// signed distance, positive inside) and the largest inside distance (f32 bits, one word).
#[derive(Clone)]
pub struct MeshGrid {
    pub grid: wgpu::Buffer,
    pub depth: wgpu::Buffer,
}

/// Runs `bake_mesh_grid.wgsl` for `shape` over `spec`: one thread per sample, the closest point
/// found through a BVH over the triangles (`methods::reference::flat_bvh`).
pub fn bake(ctx: &GpuContext, shape: &MeshShape, spec: &GridSpec) -> Result<MeshGrid> {
    use crate::bake::{storage, uniform};
    use crate::gpu::kernel::ComputeKernel;
    let boxes: Vec<Aabb> = (0..shape.triangles.len())
        .map(|t| {
            let pts = shape.triangle(t).map(|p| Vec3A::new(p.x as f32, p.y as f32, p.z as f32));
            let b = Aabb::from_points(&pts);
            // Grown so that f32 rounding never loses a triangle.
            let pad = Vec3A::splat(1e-5 * (b.max - b.min).max_element() + 1e-6);
            Aabb::new(b.min - pad, b.max + pad)
        })
        .collect();
    let (nodes, order) = crate::methods::reference::flat_bvh(&boxes);
    let corners: Vec<[f32; 4]> = order
        .iter()
        .flat_map(|&t| shape.triangle(t as usize).map(|p| [p.x as f32, p.y as f32, p.z as f32, 0.0]))
        .collect();
    let params = spec.params(order.len() as u32, nodes.len() as u32);
    let mut inputs = Inputs::default();
    let b = &mut inputs.buffers;
    b.insert("grid_params".into(), uniform(ctx, "grid_params", bytemuck::bytes_of(&params)));
    b.insert("mesh_nodes".into(), storage(ctx, "mesh_nodes", bytemuck::cast_slice(&nodes)));
    b.insert("mesh_triangles".into(), storage(ctx, "mesh_triangles", bytemuck::cast_slice(&corners)));
    let n = spec.n as u64;
    let grid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mesh_grid"),
        size: n * n * n * 16,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let depth = storage(ctx, "mesh_depth", &[0u8; 16]);
    b.insert("mesh_grid".into(), grid.clone());
    b.insert("mesh_depth".into(), depth.clone());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    ComputeKernel::load(ctx, &crate::render::wgsl_root(), "bake_mesh_grid.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [spec.n; 3],
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.take_errors()?;
    Ok(MeshGrid { grid, depth })
}

/// The samples and the largest inside distance of a baked grid (twin tests).
pub fn read(ctx: &GpuContext, g: &MeshGrid) -> Result<(Vec<[f32; 4]>, f32)> {
    let cells = bytemuck::pod_collect_to_vec(&ctx.read_buffer(&g.grid, 0, g.grid.size())?);
    let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&ctx.read_buffer(&g.depth, 0, 4)?);
    Ok((cells, depth[0]))
}

/// Stand-ins bound for objects that are not meshes (the kernels declare the bindings).
pub fn unused(ctx: &GpuContext) -> MeshGrid {
    let b = |label| crate::bake::storage(ctx, label, &[0u8; 16]);
    MeshGrid { grid: b("mesh_grid"), depth: b("mesh_depth") }
}
