//! `voltex export --world`: a textured object's look (its texel tiled over its shell) resampled
//! into world-space voxels, one sparse grid per object. Voxel `(i, j, k)` is centred at world
//! `(i, j, k) * voxel`, the same lattice for every object of the scene, so files line up. Only the
//! 8^3 leaves that a prism's bounds meet are computed (by `export/resample_world.wgsl`, one
//! workgroup per leaf, with the prisms listed for it here); a voxel is the mean extinction of
//! `samples^3` sub-points over its cell, each mapped into the texel by the exact inverse prism map.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DMat4, DVec3, IVec3};

use crate::bake::{occupancy, BakeRequest, Baker};
use crate::error::{Error, Result};
use crate::gpu::bindings::export as B;
use crate::gpu::buffers::{storage, uniform, work_buffer};
use crate::gpu::inputs::Inputs;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;
use crate::io::vdb::Voxels;
use crate::mesh::shell::Shell;
use crate::mesh::BaseSurface;
use crate::types::WorldParams;

/// Voxels along one side of a leaf (OpenVDB's leaf nodes).
pub(crate) const LEAF: i32 = 8;
/// Voxels per leaf.
pub(crate) const LEAF_VOXELS: usize = 512;
/// Most sub-points per axis of one voxel.
pub const MAX_SAMPLES: u32 = 8;
/// Leaves per dispatch: one workgroup each (at most 65535 per dimension), 8 KiB of output each.
const BATCH_LEAVES: usize = 8192;

/// How `--world` resamples: the voxel size and the sub-points per axis, each derived from the
/// texel and the shell where not given.
#[derive(Debug, Clone, Copy, Default)]
pub struct WorldOptions {
    /// Voxel side in world units.
    pub voxel: Option<f64>,
    /// Sub-points per axis of a voxel (the footprint filter).
    pub samples: Option<u32>,
}

/// One textured object's world voxels to compute: its shell, its texel and the leaves it touches.
#[derive(Debug)]
pub struct WorldShell {
    /// The base surface with its height vectors, world space.
    pub(crate) surface: Arc<BaseSurface>,
    /// The texel's bake (unlit albedo at full precision).
    pub(crate) request: BakeRequest,
    /// World length over which a voxel's alpha is reached.
    pub(crate) opacity_length: f64,
    /// Voxel side, world units.
    pub voxel: f64,
    /// Sub-points per axis of a voxel.
    pub samples: u32,
    /// The voxel whose centre the shell is made relative to (f32 precision near the object).
    pub(crate) anchor: IVec3,
    /// First voxel of each leaf the shell's prisms may reach, in OpenVDB's order.
    pub(crate) leaves: Vec<IVec3>,
    /// Leaf `k`'s prisms are `prism_ids[firsts[k]..firsts[k + 1]]`.
    pub(crate) firsts: Vec<u32>,
    pub(crate) prism_ids: Vec<u32>,
}

/// The mean world size of one texel voxel on `surface` along s, t and w: s and t from world area
/// over uv area (tiling included), w from the mean height.
pub(crate) fn texel_voxel_size(surface: &BaseSurface, resolution: [u32; 3]) -> Option<DVec3> {
    let (st, height) = surface.mean_scale();
    let size =
        DVec3::new(st / resolution[0] as f64, st / resolution[1] as f64, height / resolution[2] as f64);
    (size.is_finite() && size.min_element() > 0.0).then_some(size)
}

impl WorldShell {
    /// The leaves of `surface`'s shell at `voxel` (default: a texel voxel's mean world size),
    /// with `samples` sub-points per axis (default: enough for a sub-point per texel voxel).
    /// Fails, before any GPU work, where the voxels would pass `max_voxels`.
    pub(crate) fn new(
        what: &str,
        surface: Arc<BaseSurface>,
        request: BakeRequest,
        opacity_length: f64,
        opts: WorldOptions,
        max_voxels: u64,
    ) -> Result<Self> {
        let texel_voxel = texel_voxel_size(&surface, request.resolution)
            .ok_or_else(|| Error::Invalid(format!("{what}: its shell has no area or no height to export")))?;
        let voxel = opts.voxel.unwrap_or_else(|| texel_voxel.element_product().cbrt());
        let samples = opts
            .samples
            .unwrap_or_else(|| ((voxel / texel_voxel.min_element()).ceil() as u32).clamp(1, MAX_SAMPLES));
        // Each prism's corner box (its bilinear sides lie in the corners' hull), grown by the half
        // voxel a sub-point may lie from its voxel's centre, in voxel indices.
        let mut lists: HashMap<IVec3, Vec<u32>> = HashMap::new();
        let (mut lo_all, mut hi_all) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for t in 0..surface.triangles.len() {
            let corners = surface.prism(t);
            let lo = corners.iter().fold(DVec3::INFINITY, |a, &c| a.min(c));
            let hi = corners.iter().fold(DVec3::NEG_INFINITY, |a, &c| a.max(c));
            lo_all = lo_all.min(lo);
            hi_all = hi_all.max(hi);
            let (first, last) = leaf_range(lo, hi, voxel);
            let count = (last - first + 1).as_i64vec3();
            if count.x * count.y * count.z > max_voxels as i64 / LEAF_VOXELS as i64 {
                return Err(too_many(what, (count.x * count.y * count.z) as u64 * 512, voxel, max_voxels));
            }
            for leaf in leaves_between(first, last) {
                lists.entry(leaf).or_default().push(t as u32);
            }
            if lists.len() as u64 * LEAF_VOXELS as u64 > max_voxels {
                let voxels = lists.len() as u64 * LEAF_VOXELS as u64;
                return Err(too_many(what, voxels, voxel, max_voxels));
            }
        }
        let mut leaves: Vec<IVec3> = lists.keys().copied().collect();
        leaves.sort_by_key(|l| l.to_array());
        let mut firsts = vec![0u32];
        let mut prism_ids = Vec::new();
        for l in &leaves {
            prism_ids.extend(&lists[l]);
            firsts.push(prism_ids.len() as u32);
        }
        let anchor = ((lo_all + hi_all) / 2.0 / voxel).round().as_ivec3();
        Ok(Self { surface, request, opacity_length, voxel, samples, anchor, leaves, firsts, prism_ids })
    }

    /// Voxels computed (active or not): every voxel of every leaf.
    pub fn voxels(&self) -> u64 {
        self.leaves.len() as u64 * LEAF_VOXELS as u64
    }

    /// Voxel `(i, j, k)` to world.
    pub(crate) fn index_to_world(&self) -> DMat4 {
        DMat4::from_scale(DVec3::splat(self.voxel))
    }

    /// The box of the leaves, in voxels per axis.
    pub(crate) fn extent(&self) -> [u32; 3] {
        let lo = self.leaves.iter().fold(IVec3::MAX, |a, &l| a.min(l));
        let hi = self.leaves.iter().fold(IVec3::MIN, |a, &l| a.max(l + LEAF));
        if self.leaves.is_empty() {
            [0; 3]
        } else {
            (hi - lo).as_uvec3().to_array()
        }
    }

    /// The world position of the anchor voxel's centre.
    pub(crate) fn anchor_world(&self) -> DVec3 {
        self.anchor.as_dvec3() * self.voxel
    }

    /// Per leaf, whether a non-empty part of the texel can reach it (`texel`: [`texel`]'s
    /// read-back). Each prism is cut into sub-prisms (its triangle into k^2, its height into m)
    /// about one occupancy brick of the texel each; a sub-prism is itself a prism of the same
    /// map, so its corners' box holds it, and its uv box and w range bound the texel space its
    /// points map to. Only the leaves the boxes of sub-prisms over occupied bricks meet are
    /// kept: the others would only sample exactly transparent texels.
    pub(crate) fn occupied(&self, texel: &[[f32; 4]]) -> Vec<bool> {
        let res = self.request.resolution;
        let brick = occupancy::BRICKS[0];
        let bricks = res.map(|n| n.div_ceil(brick) as i64);
        let level0 = &occupancy::pyramid(&occupancy::float_alpha(texel), res)
            [..(bricks.iter().product::<i64>()) as usize];
        // Whether any brick over texel voxels [lo, hi] (s and t repeating, w clamped) is occupied.
        let any = |lo: DVec3, hi: DVec3| {
            let first = (lo / brick as f64).floor().as_i64vec3();
            let last = (hi / brick as f64).floor().as_i64vec3();
            let (z0, z1) = (first.z.clamp(0, bricks[2] - 1), last.z.clamp(0, bricks[2] - 1));
            if last.x - first.x >= bricks[0] && last.y - first.y >= bricks[1] {
                return level0.iter().any(|&v| v > 0);
            }
            (z0..=z1).any(|z| {
                (first.y..=last.y.min(first.y + bricks[1] - 1)).any(|y| {
                    (first.x..=last.x.min(first.x + bricks[0] - 1)).any(|x| {
                        let at =
                            (z * bricks[1] + y.rem_euclid(bricks[1])) * bricks[0] + x.rem_euclid(bricks[0]);
                        level0[at as usize] > 0
                    })
                })
            })
        };
        let scale = DVec3::new(res[0] as f64, res[1] as f64, res[2] as f64);
        let m = res[2].div_ceil(brick).clamp(1, 16) as usize;
        let s = &self.surface;
        let mut keep: std::collections::HashSet<IVec3> = Default::default();
        for (t, tri) in s.triangles.iter().enumerate() {
            let uv = s.corner_uvs[t].map(|u| u * glam::DVec2::new(scale.x, scale.y));
            let extent = [uv[1] - uv[0], uv[2] - uv[0], uv[2] - uv[1]]
                .iter()
                .map(|e| e.abs().max_element())
                .fold(0.0, f64::max);
            let k = ((extent / brick as f64).ceil() as usize).clamp(1, 16);
            let v = tri.map(|i| i as usize);
            let at = |b: [f64; 3], w: f64| {
                (0..3).map(|i| (s.positions[v[i]] + s.heights[v[i]] * w) * b[i]).sum::<DVec3>()
            };
            let bary = |i: usize, j: usize| {
                [(k - i - j) as f64 / k as f64, i as f64 / k as f64, j as f64 / k as f64]
            };
            let mut subs = Vec::new();
            for i in 0..k {
                for j in 0..k - i {
                    subs.push([bary(i, j), bary(i + 1, j), bary(i, j + 1)]);
                    if i + j + 1 < k {
                        subs.push([bary(i + 1, j), bary(i + 1, j + 1), bary(i, j + 1)]);
                    }
                }
            }
            for sub in subs {
                let st = sub.map(|b| uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2]);
                let (st_lo, st_hi) = (st[0].min(st[1]).min(st[2]), st[0].max(st[1]).max(st[2]));
                for l in 0..m {
                    let (w0, w1) = (l as f64 / m as f64, (l + 1) as f64 / m as f64);
                    // Texel voxel coordinates (centres at i + 0.5) the sub-prism's points take.
                    let lo = DVec3::new(st_lo.x, st_lo.y, w0 * scale.z) - 0.5;
                    let hi = DVec3::new(st_hi.x, st_hi.y, w1 * scale.z) - 0.5;
                    if !any(lo, hi) {
                        continue;
                    }
                    let corners = [w0, w1].map(|w| sub.map(|b| at(b, w)));
                    let lo = corners.iter().flatten().fold(DVec3::INFINITY, |a, &c| a.min(c));
                    let hi = corners.iter().flatten().fold(DVec3::NEG_INFINITY, |a, &c| a.max(c));
                    let (first, last) = leaf_range(lo, hi, self.voxel);
                    keep.extend(leaves_between(first, last));
                }
            }
        }
        self.leaves.iter().map(|l| keep.contains(l)).collect()
    }

    /// The dispatch parameters for `leaves` leaves.
    fn params(&self, leaves: usize) -> WorldParams {
        let r = self.request.resolution;
        WorldParams {
            anchor: [self.anchor.x, self.anchor.y, self.anchor.z, self.samples as i32],
            voxel: [self.voxel as f32, (1.0 / self.opacity_length) as f32, 0.0, 0.0],
            counts: [leaves as u32, 0, 0, 0],
            resolution: [r[0], r[1], r[2], 0],
        }
    }
}

/// The first and last leaf (in leaves, not voxels) holding a voxel whose cell meets the box
/// `lo..hi` (world), grown by a hair so that rounding never drops a voxel on its edge.
fn leaf_range(lo: DVec3, hi: DVec3, voxel: f64) -> (IVec3, IVec3) {
    const HAIR: f64 = 1e-4;
    let first = (lo / voxel - 0.5 - HAIR).ceil().as_ivec3();
    let last = (hi / voxel + 0.5 + HAIR).floor().as_ivec3();
    (first.div_euclid(IVec3::splat(LEAF)), last.div_euclid(IVec3::splat(LEAF)))
}

/// The first voxels of the leaves `first..=last` (in leaves).
fn leaves_between(first: IVec3, last: IVec3) -> impl Iterator<Item = IVec3> {
    (first.x..=last.x).flat_map(move |x| {
        (first.y..=last.y).flat_map(move |y| (first.z..=last.z).map(move |z| IVec3::new(x, y, z) * LEAF))
    })
}

fn too_many(what: &str, voxels: u64, voxel: f64, max: u64) -> Error {
    Error::Invalid(format!(
        "{what}: {voxels} voxels or more at a voxel size of {voxel:.6} world units, beyond the {max} one export \
         may have (16 bytes a voxel are read back): give a larger --voxel"
    ))
}

/// Bakes `shell`'s texel with `baker` (full precision) and resamples it on the GPU: per leaf, 512
/// voxels in OpenVDB's order (x slowest, z fastest), each (extinction per world unit, colour).
/// Leaves only empty texel space reaches ([`WorldShell::occupied`]) are 0 without a dispatch.
pub(crate) fn resample(ctx: &GpuContext, baker: &mut Baker, shell: &WorldShell) -> Result<Vec<[f32; 4]>> {
    let baked = baker.bake(ctx, &shell.request)?;
    let rgba: Vec<[f32; 4]> =
        bytemuck::pod_collect_to_vec(&crate::gpu::readback::read_texture(ctx, &baked.volume, 16)?);
    let todo: Vec<usize> =
        shell.occupied(&rgba).iter().enumerate().filter(|(_, &o)| o).map(|(k, _)| k).collect();
    let gpu_shell = Shell::new(&shell.surface, shell.anchor_world());
    let mut kernel = ComputeKernel::load(ctx, &Sources::project()?, "export/resample_world.wgsl")?;
    let mut inputs = Inputs::default();
    let b = &mut inputs.buffers;
    b.insert(
        B::SHELL_VERTICES.into(),
        storage(ctx, "shell_vertices", bytemuck::cast_slice(&gpu_shell.vertices)),
    );
    b.insert(B::SHELL_PRISMS.into(), storage(ctx, "shell_prisms", bytemuck::cast_slice(&gpu_shell.prisms)));
    b.insert(
        B::PRISM_SPHERES.into(),
        storage(ctx, "prism_spheres", bytemuck::cast_slice(&gpu_shell.spheres)),
    );
    inputs.views.insert(B::TEXEL_VOLUME.into(), baked.volume.create_view(&Default::default()));
    let mut out = vec![[0.0; 4]; shell.voxels() as usize];
    for batch in todo.chunks(BATCH_LEAVES) {
        // The batch's leaves with their prism lists, numbered from 0 and ended by one more entry.
        let (mut leaves, mut ids) = (Vec::with_capacity(batch.len() + 1), Vec::new());
        for &k in batch {
            let l = shell.leaves[k];
            leaves.push([l.x, l.y, l.z, ids.len() as i32]);
            ids.extend_from_slice(&shell.prism_ids[shell.firsts[k] as usize..shell.firsts[k + 1] as usize]);
        }
        leaves.push([0, 0, 0, ids.len() as i32]);
        let bytes = (batch.len() * LEAF_VOXELS * 16) as u64;
        let voxels = work_buffer(ctx, "world_voxels", bytes, wgpu::BufferUsages::empty());
        let params = shell.params(batch.len());
        let b = &mut inputs.buffers;
        b.insert(B::WORLD_PARAMS.into(), uniform(ctx, "world_params", bytemuck::bytes_of(&params)));
        b.insert(B::WORLD_LEAVES.into(), storage(ctx, "world_leaves", bytemuck::cast_slice(&leaves)));
        b.insert(B::WORLD_PRISM_IDS.into(), storage(ctx, "world_prism_ids", bytemuck::cast_slice(&ids)));
        b.insert(B::WORLD_VOXELS.into(), voxels.clone());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        kernel.dispatch(ctx, &mut encoder, &inputs, [(batch.len() * 64) as u32, 1, 1])?;
        ctx.queue.submit([encoder.finish()]);
        ctx.take_errors()?;
        let values: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&ctx.read_buffer(&voxels, 0, bytes)?);
        for (&k, leaf) in batch.iter().zip(values.chunks(LEAF_VOXELS)) {
            out[k * LEAF_VOXELS..(k + 1) * LEAF_VOXELS].copy_from_slice(leaf);
        }
    }
    Ok(out)
}

/// `shell`'s texel baked with `baker` (full precision) and read back: premultiplied RGBA, x
/// fastest, then y, then z (what [`resample_world`] samples).
///
/// [`resample_world`]: crate::render::export::resample_world::resample_world
pub fn texel(ctx: &GpuContext, baker: &mut Baker, shell: &WorldShell) -> Result<Vec<[f32; 4]>> {
    let baked = baker.bake(ctx, &shell.request)?;
    Ok(bytemuck::pod_collect_to_vec(&crate::gpu::readback::read_texture(ctx, &baked.volume, 16)?))
}

/// The `density` and `Cd` grids of `shell`'s resampled voxels ([`resample`]): active where the
/// extinction is above 0.
pub(crate) fn world_grids(shell: &WorldShell, voxels: &[[f32; 4]]) -> (Voxels<f32>, Voxels<[f32; 3]>) {
    let (mut density, mut colour) = (Voxels::new(), Voxels::new());
    for (leaf, values) in shell.leaves.iter().zip(voxels.chunks(LEAF_VOXELS)) {
        let active = |n: usize| values[n][0] > 0.0;
        density.insert_leaf(leaf.to_array(), |n| active(n).then_some(values[n][0]));
        colour.insert_leaf(leaf.to_array(), |n| {
            active(n).then_some([values[n][1], values[n][2], values[n][3]])
        });
    }
    (density, colour)
}

/// `shell`'s base surface as Wavefront OBJ text, world space: its welded vertices, each triangle
/// corner's uv (tiling applied) and the triangles, named `name`.
pub fn surface_obj(shell: &WorldShell, name: &str) -> String {
    use std::fmt::Write;
    let s = &shell.surface;
    let mut out = format!("# voltex export --world --with-mesh: the base surface of \"{name}\"\no {name}\n");
    for p in &s.positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    for uv in s.corner_uvs.iter().flatten() {
        let _ = writeln!(out, "vt {} {}", uv.x, uv.y);
    }
    for (t, tri) in s.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| v + 1);
        let k = 3 * t + 1;
        let _ = writeln!(out, "f {a}/{k} {b}/{} {c}/{}", k + 1, k + 2);
    }
    out
}
