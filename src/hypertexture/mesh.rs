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

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::Path;

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;
use crate::graph::exec::Inputs;
use crate::mesh::Mesh;
use crate::types::MeshGridParams;

/// Most samples per axis of a mesh grid (16 bytes each: 32 MiB at 128).
pub const MAX_RESOLUTION: u32 = 128;
/// Most voxels of a mesh texel (its grid: 256 MiB, e.g. 256^3).
pub const MAX_TEXEL_SAMPLES: u64 = 1 << 24;
/// Most closed parts of one mesh (the bake walks each part's BVH per sample).
pub const MAX_PARTS: usize = 16;

/// A closed triangle mesh in its node's frame, vertices welded by position.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshShape {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub lo: DVec3,
    pub hi: DVec3,
    /// Closed parts: (first triangle, triangle count); triangles are grouped by part.
    pub parts: Vec<(u32, u32)>,
    /// Per triangle, its corners' colours (OBJ vertex colours), when the mesh has any.
    pub colors: Option<Vec<[[f32; 3]; 3]>>,
    /// Of positions and triangles: the bake cache's key.
    pub hash: u64,
}

/// Where a mesh grid's samples lie: `n[a]` along axis `a` at the vertices of the box `lo..hi`.
/// `parity: false` skips the inside test (open patterns drawn as shells): every distance is
/// then negative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    pub lo: DVec3,
    pub hi: DVec3,
    pub n: [u32; 3],
    pub parity: bool,
}

impl GridSpec {
    /// The sample `(i, j, k)` in object space.
    pub fn point(&self, i: u32, j: u32, k: u32) -> DVec3 {
        let [x, y, z] = self.n.map(|n| (n - 1) as f64);
        let f = DVec3::new(i as f64 / x, j as f64 / y, k as f64 / z);
        self.lo + (self.hi - self.lo) * f
    }

    /// Samples in all.
    pub fn samples(&self) -> u64 {
        self.n.iter().map(|&n| n as u64).product()
    }

    pub fn params(&self, triangles: u32, nodes: u32, parts: u32) -> MeshGridParams {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        let [x, y, z] = self.n;
        MeshGridParams {
            lo: f(self.lo),
            hi: f(self.hi),
            counts: [x, triangles, nodes, parts],
            size: [x, y, z, self.parity as u32],
        }
    }
}

impl MeshShape {
    /// Welds `mesh` by position and checks that it is closed (every edge shared by an even
    /// number of triangles, so ray parity says inside or outside) and encloses a volume. Errors
    /// name `path` and the line of the offending face.
    pub fn new(mesh: &Mesh, path: &Path) -> std::result::Result<Self, String> {
        let (positions, triangles, lines, sources) = weld(mesh, path)?;
        let at = |t: usize| match lines.get(t) {
            Some(&l) if l > 0 => format!("{}:{l}:1", path.display()),
            _ => path.display().to_string(),
        };
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
        // Parts: triangles joined by shared vertices (union-find), grouped in order of first face.
        let mut root: Vec<u32> = (0..positions.len() as u32).collect();
        fn find(root: &mut [u32], mut i: u32) -> u32 {
            while root[i as usize] != i {
                root[i as usize] = root[root[i as usize] as usize];
                i = root[i as usize];
            }
            i
        }
        for t in &triangles {
            for e in 1..3 {
                let (a, b) = (find(&mut root, t[0]), find(&mut root, t[e]));
                root[a.max(b) as usize] = a.min(b);
            }
        }
        let mut part_of: HashMap<u32, usize> = HashMap::new();
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (t, tri) in triangles.iter().enumerate() {
            let r = find(&mut root, tri[0]);
            let g = *part_of.entry(r).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            groups[g].push(t);
        }
        if groups.len() > MAX_PARTS {
            return Err(format!(
                "{}: {} separate closed parts: expected at most {MAX_PARTS}",
                path.display(),
                groups.len()
            ));
        }
        let extent = (hi - lo).max_element();
        let mut parts = Vec::new();
        let mut grouped = Vec::with_capacity(triangles.len());
        let mut order = Vec::with_capacity(triangles.len());
        for g in &groups {
            let volume: f64 = g
                .iter()
                .map(|&t| {
                    let [a, b, c] = triangles[t].map(|i| positions[i as usize] - lo);
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            if volume.abs() <= 1e-9 * extent.powi(3) {
                return Err(format!(
                    "{}: degenerate mesh: the part of this face encloses no volume (bounds {:?} to {:?})",
                    at(g[0]),
                    lo.to_array(),
                    hi.to_array()
                ));
            }
            parts.push((grouped.len() as u32, g.len() as u32));
            grouped.extend(g.iter().map(|&t| triangles[t]));
            order.extend(g.iter().map(|&t| sources[t]));
        }
        let triangles = grouped;
        let colors = corner_colors(mesh, &order);
        let hash = digest(&positions, &triangles, &colors);
        Ok(MeshShape { positions, triangles, lo, hi, parts, colors, hash })
    }

    /// The welded mesh as one part, closed or not: only its unsigned distance means anything
    /// (a mesh texel's shell). Errors only when no triangle is left.
    pub fn open(mesh: &Mesh, path: &Path) -> std::result::Result<Self, String> {
        let (positions, triangles, _, sources) = weld(mesh, path)?;
        let lo = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        let parts = vec![(0, triangles.len() as u32)];
        let colors = corner_colors(mesh, &sources);
        let hash = digest(&positions, &triangles, &colors);
        Ok(MeshShape { positions, triangles, lo, hi, parts, colors, hash })
    }

    /// The grid of `n` samples per axis over the mesh's bounds enlarged by the largest shift (the
    /// field is needed wherever a noise may shift a point from) and two cells.
    pub fn grid(&self, n: u32, max_shift: f64) -> GridSpec {
        let extent = (self.hi - self.lo).max_element() + 2.0 * max_shift;
        let pad = max_shift + 2.0 * extent / (n - 1) as f64;
        GridSpec { lo: self.lo - DVec3::splat(pad), hi: self.hi + DVec3::splat(pad), n: [n; 3], parity: true }
    }

    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }
}

/// Positions welded (equal coordinates become one vertex) and triangles that still bound
/// something, with the OBJ line of each and its index in the mesh.
type Welded = (Vec<DVec3>, Vec<[u32; 3]>, Vec<u32>, Vec<usize>);

/// Per triangle of `mesh` in `order`, its corners' vertex colours (before welding, so that a
/// seam keeps both sides' colours).
fn corner_colors(mesh: &Mesh, order: &[usize]) -> Option<Vec<[[f32; 3]; 3]>> {
    let colors = mesh.colors.as_ref()?;
    let corner = |v: u32| colors[v as usize].map(|c| c as f32);
    Some(order.iter().map(|&t| mesh.triangles[t].map(corner)).collect())
}

fn weld(mesh: &Mesh, path: &Path) -> std::result::Result<Welded, String> {
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let weld: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            // `+ 0.0` makes -0 and 0 one coordinate (OBJ writers print both).
            *ids.entry(p.to_array().map(|c| (c + 0.0).to_bits())).or_insert_with(|| {
                positions.push(*p);
                positions.len() as u32 - 1
            })
        })
        .collect();
    let mut triangles = Vec::new();
    let mut lines = Vec::new();
    let mut sources = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| weld[i as usize]);
        // A triangle with a repeated vertex bounds nothing.
        if a != b && b != c && a != c {
            triangles.push([a, b, c]);
            lines.push(mesh.face_lines.get(t).copied().unwrap_or(0));
            sources.push(t);
        }
    }
    if triangles.is_empty() {
        return Err(format!("{}: degenerate mesh: every triangle repeats a vertex", path.display()));
    }
    Ok((positions, triangles, lines, sources))
}

fn digest(positions: &[DVec3], triangles: &[[u32; 3]], colors: &Option<Vec<[[f32; 3]; 3]>>) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in positions {
        p.to_array().map(f64::to_bits).hash(&mut h);
    }
    triangles.hash(&mut h);
    for c in colors.iter().flatten().flatten().flatten() {
        c.to_bits().hash(&mut h);
    }
    h.finish()
}

/// A baked mesh grid on the GPU: its samples (xyz: vector to the closest surface point; w:
/// signed distance, positive inside) and the largest inside distance (f32 bits, one word).
#[derive(Clone)]
pub struct MeshGrid {
    pub grid: wgpu::Buffer,
    pub depth: wgpu::Buffer,
    /// Coloured meshes: per sample the colour at its closest surface point (rgb, w = 1),
    /// interpolated from the closest triangle's corners.
    pub colors: Option<wgpu::Buffer>,
}

/// Runs `bake_mesh_grid.wgsl` for `shape` over `spec`: one thread per sample, closest points
/// and ray crossings found through a BVH per part (`methods::reference::flat_bvh`).
pub fn bake(ctx: &GpuContext, shape: &MeshShape, spec: &GridSpec) -> Result<MeshGrid> {
    use crate::bake::{storage, uniform};
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
        let (part_nodes, order) = crate::methods::reference::flat_bvh(&boxes);
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
    ComputeKernel::load(ctx, &Sources::project()?, "bake_mesh_grid.wgsl")?.dispatch(
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
pub fn unused(ctx: &GpuContext) -> MeshGrid {
    let b = |label| crate::bake::storage(ctx, label, &[0u8; 16]);
    MeshGrid { grid: b("mesh_grid"), depth: b("mesh_depth"), colors: None }
}
