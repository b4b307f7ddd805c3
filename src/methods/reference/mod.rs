//! Host side of the `Reference` method: one BVH over the prisms of every Reference object (built
//! with obvhs, flattened so the kernel walks it with a small stack), their shells concatenated,
//! and level 0 of their baked volumes packed into one storage buffer (the kernel filters by hand,
//! as the sampler would, so all objects fit in one dispatch without binding arrays).

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::reference as knobs;
mod object;
pub(crate) mod plugin;
pub mod trace_reference;

pub use object::{frame_twin_inputs, plan, ReferencePlan};

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::reference as B;
use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::cpu::prism_map::PrismCorners;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::mesh::bvh::flat_bvh;
use crate::mesh::shell;
use crate::mesh::shell::Shell;
use crate::mesh::BaseSurface;
use crate::methods::reference::trace_reference::{DecodedTexel, PerPixel, TraceObject, TraceView};
use crate::types::{
    FrameParams, ReferenceNode, ReferenceObject, ReferenceParams, ReferencePrism, ReferenceState,
    ShellVertex, VertexFrame,
};

/// What Reference brings to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "Reference",
    filters: &["Reference"],
    resources: &[
        B::REFERENCE_PARAMS,
        B::REFERENCE_NODES,
        B::REFERENCE_PRISMS,
        B::REFERENCE_OBJECTS,
        B::TEXEL_ATLAS,
        B::NORMAL_ATLAS,
        B::REFERENCE_STATE,
        B::VERTEX_FRAMES,
    ],
    counts: &[C::REFERENCE_DISPATCHES],
    texel_resources: &[B::TEXEL_ATLAS],
    gather: Some(object::gather),
};

/// Everything the reference kernel reads, for all Reference objects of a frame.
pub struct ReferenceSet {
    /// Indices of the Reference objects in the blueprint.
    pub(crate) objects: Vec<usize>,
    pub(crate) params: ReferenceParams,
    pub(crate) nodes: Vec<ReferenceNode>,
    pub(crate) prisms: Vec<ReferencePrism>,
    pub(crate) vertices: Vec<ShellVertex>,
    pub(crate) frames: Vec<VertexFrame>,
    pub(crate) table: Vec<ReferenceObject>,
    /// Per object: its bake, copied to `table[i].atlas.x` (volume) and `.z` (normals, per-pixel only).
    pub(crate) copies: Vec<(usize, bool)>,
    /// Atlas sizes in u32 words (at least 1: the bindings exist).
    pub(crate) atlas_words: u64,
    pub(crate) normal_words: u64,
    /// Dispatches of the tracer per frame (each marches SAMPLES_PER_DISPATCH steps of a ray).
    pub(crate) dispatches: u32,
}

/// Mirrors the default of `samples_per_dispatch` and `WINDOW_COST` in trace_reference.wgsl.
const SAMPLES_PER_DISPATCH: f64 = 512.0;
const WINDOW_COST: f64 = 16.0;
const MAX_SEGMENTS: f64 = 16.0;
/// More dispatches than this means a step far finer than the scene needs.
pub(crate) const MAX_DISPATCHES: u32 = 20_000;

/// A bound on the work along any ray through the object: a ray meets a shell in a few stretches
/// (four, for a torus seen edge-on), each no longer than the shell's bounding diagonal.
fn work_bound(s: &BaseSurface, step: f64) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for (p, h) in s.positions.iter().zip(&s.heights) {
        for q in [*p, *p + *h] {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let diagonal = (hi - lo).length();
    let edges: f64 =
        s.triangles.iter().map(|t| (s.positions[t[1] as usize] - s.positions[t[0] as usize]).length()).sum();
    let edge = (edges / s.triangles.len().max(1) as f64).max(1e-12);
    let path = 4.0 * diagonal;
    let intervals = 2.0 * path / edge + 8.0;
    path / step + intervals + WINDOW_COST * (intervals / MAX_SEGMENTS + 1.0)
}

/// Half the smallest world extent of a voxel over the object (height along w; `dP/ds`, `dP/dt`
/// lengths along s and t, from its vertex frames), averaged over its vertices.
pub(crate) fn default_step(s: &BaseSurface, frames: &[VertexFrame], resolution: [u32; 3]) -> f64 {
    let n = s.heights.len().max(1) as f64;
    let h = s.heights.iter().map(|h| h.length()).sum::<f64>() / n;
    let mean = |f: &dyn Fn(&VertexFrame) -> [f32; 4]| {
        let v: Vec<f64> = frames
            .iter()
            .map(|fr| {
                let a = f(fr);
                DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64).length()
            })
            .filter(|l| *l > 0.0)
            .collect();
        if v.is_empty() {
            f64::INFINITY
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let ds = mean(&|f| f.ds);
    let dt = mean(&|f| f.dt);
    let extent = (h / resolution[2] as f64).min(ds / resolution[0] as f64).min(dt / resolution[1] as f64);
    0.5 * extent.max(1e-9)
}

/// Words per row of a volume copied out of a texture (rows padded to 256 bytes).
fn row_pitch(width: u32) -> u32 {
    (width * 4).div_ceil(256) * 64
}

/// One object drawn by the Reference method, as the set needs it.
pub(crate) struct Member<'a> {
    /// Index of the object in the frame.
    pub(crate) index: usize,
    pub(crate) surface: &'a BaseSurface,
    pub(crate) shell: &'a Shell,
    /// Per-vertex texel frames (per-pixel lighting only).
    pub(crate) frames: Option<&'a [VertexFrame]>,
    /// The base surface is drawn opaque.
    pub(crate) opaque: bool,
    /// Ray step (world units).
    pub(crate) step: f64,
    /// The bake it samples: index, resolution and opacity length.
    pub(crate) bake: usize,
    pub(crate) resolution: [u32; 3],
    pub(crate) opacity_length: f32,
}

impl Member<'_> {
    fn per_pixel(&self) -> bool {
        self.frames.is_some()
    }
}

/// The layout of `members` for the kernels; with `bvh`, a BVH over the prisms (in its leaf order),
/// else the prisms in the members' order and no nodes.
pub(crate) fn build(members: &[Member], params: ReferenceParams, bvh: bool) -> ReferenceSet {
    let mut set = ReferenceSet {
        objects: members.iter().map(|m| m.index).collect(),
        params,
        nodes: Vec::new(),
        prisms: Vec::new(),
        vertices: Vec::new(),
        frames: Vec::new(),
        table: Vec::new(),
        copies: Vec::new(),
        atlas_words: 0,
        normal_words: 0,
        dispatches: 1,
    };
    let mut work = 0.0;
    let mut prisms = Vec::new();
    let mut boxes = Vec::new();
    for (k, o) in members.iter().enumerate() {
        let first = set.vertices.len() as u32;
        set.vertices.extend_from_slice(&o.shell.vertices);
        match o.frames {
            Some(frames) => set.frames.extend_from_slice(frames),
            None => set.frames.extend(std::iter::repeat_n(VertexFrame::default(), o.shell.vertices.len())),
        }
        for p in o.shell.prisms.iter() {
            let ids = [p.vertices[0], p.vertices[1], p.vertices[2]];
            if bvh {
                let corners = ids.iter().flat_map(|&v| {
                    let sv = &o.shell.vertices[v as usize];
                    [Vec3A::from_slice(&sv.bottom[..3]), Vec3A::from_slice(&sv.top[..3])]
                });
                let pts: Vec<Vec3A> = corners.collect();
                let b = Aabb::from_points(&pts);
                // Grown by a relative epsilon so that f32 rounding in the slab test never loses a prism.
                let pad = Vec3A::splat(1e-5 * (b.max - b.min).max_element() + 1e-7);
                boxes.push(Aabb::new(b.min - pad, b.max + pad));
            }
            prisms.push(ReferencePrism {
                vertices: [ids[0] + first, ids[1] + first, ids[2] + first, k as u32],
                uv01: p.uv01,
                uv2: p.uv2,
            });
        }
        let res = o.resolution;
        let pitch = row_pitch(res[0]);
        let words = pitch as u64 * res[1] as u64 * res[2] as u64;
        work += work_bound(o.surface, o.step);
        set.table.push(ReferenceObject {
            resolution: [res[0], res[1], res[2], o.per_pixel() as u32 | (o.opaque as u32) << 1],
            atlas: [set.atlas_words as u32, pitch, set.normal_words as u32, 0],
            params: [o.opacity_length, o.step as f32, 0.0, 0.0],
        });
        set.copies.push((o.bake, o.per_pixel()));
        set.atlas_words += words;
        if o.per_pixel() {
            set.normal_words += words;
        }
    }
    if !bvh {
        set.prisms = prisms;
    } else if !prisms.is_empty() {
        let (nodes, order) = flat_bvh(&boxes);
        // Prisms in leaf order, so leaves index them directly.
        set.prisms = order.iter().map(|&i| prisms[i as usize]).collect();
        set.nodes = nodes;
    }
    set.params.counts = [set.nodes.len() as u32, set.prisms.len() as u32, set.table.len() as u32, 0];
    set.dispatches = ((work / SAMPLES_PER_DISPATCH).ceil() + 1.0).min(u32::MAX as f64) as u32;
    set.atlas_words = set.atlas_words.max(1);
    set.normal_words = set.normal_words.max(1);
    set
}

impl ReferenceSet {
    /// Checks the atlases against the adapter's storage-buffer limit, and the dispatch count.
    pub(crate) fn check_limits(&self, max_binding: u64) -> Result<()> {
        if self.dispatches > MAX_DISPATCHES {
            return Err(Error::Invalid(format!(
                "the Reference step is too fine for this scene: {} dispatches per frame (at most {MAX_DISPATCHES}); \
                 use a larger `step`",
                self.dispatches
            )));
        }
        for (what, words) in [("texel", self.atlas_words), ("normal", self.normal_words)] {
            if words * 4 > max_binding {
                return Err(Error::Invalid(format!(
                    "the Reference objects' {what} volumes need {} MiB in one storage buffer, beyond the \
                     adapter's limit of {} MiB: use smaller texel resolutions or another method",
                    (words * 4) >> 20,
                    max_binding >> 20
                )));
            }
        }
        Ok(())
    }

    /// Buffers of the reference instance; the atlases are filled from the bakes by `copy_volumes`.
    pub(crate) fn add_inputs(&self, ctx: &GpuContext, inputs: &mut Inputs, size: (u32, u32)) {
        inputs.counts.insert(C::REFERENCE_DISPATCHES.into(), self.dispatches);
        let state = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("reference_state"),
            size: size.0 as u64 * size.1 as u64 * std::mem::size_of::<ReferenceState>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        inputs.buffers.insert(B::REFERENCE_STATE.into(), state);
        use crate::gpu::buffers::{storage, uniform};
        let b = &mut inputs.buffers;
        b.insert(
            "reference_params".into(),
            uniform(ctx, "reference_params", bytemuck::bytes_of(&self.params)),
        );
        let nodes = if self.nodes.is_empty() { vec![ReferenceNode::default()] } else { self.nodes.clone() };
        b.insert(B::REFERENCE_NODES.into(), storage(ctx, "reference_nodes", bytemuck::cast_slice(&nodes)));
        b.insert(
            "reference_prisms".into(),
            storage(ctx, "reference_prisms", bytemuck::cast_slice(&self.prisms)),
        );
        b.insert(
            "reference_objects".into(),
            storage(ctx, "reference_objects", bytemuck::cast_slice(&self.table)),
        );
        b.insert(
            "shell_vertices".into(),
            storage(ctx, "shell_vertices", bytemuck::cast_slice(&self.vertices)),
        );
        b.insert(B::VERTEX_FRAMES.into(), storage(ctx, "vertex_frames", bytemuck::cast_slice(&self.frames)));
        for (name, words) in [("texel_atlas", self.atlas_words), ("normal_atlas", self.normal_words)] {
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: words * 4,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            b.insert(name.into(), buffer);
        }
    }

    /// Copies level 0 of each object's volume (and normals) into the atlases.
    pub(crate) fn copy_volumes(&self, ctx: &GpuContext, inputs: &Inputs, baked: &[crate::bake::Baked]) {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        for (entry, &(bake, per_pixel)) in self.table.iter().zip(&self.copies) {
            let [w, h, d, _] = entry.resolution;
            let mut copy = |texture: &wgpu::Texture, atlas: &str, offset: u32| {
                enc.copy_texture_to_buffer(
                    texture.as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &inputs.buffers[atlas],
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: offset as u64 * 4,
                            bytes_per_row: Some(entry.atlas[1] * 4),
                            rows_per_image: Some(h),
                        },
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: d },
                );
            };
            copy(&baked[bake].volume, "texel_atlas", entry.atlas[0]);
            if per_pixel {
                copy(&baked[bake].normals, "normal_atlas", entry.atlas[2]);
            }
        }
        ctx.queue.submit([enc.finish()]);
    }
}

/// The same frame for the f64 CPU twin: corners made camera-relative in f64 from the scene's
/// surfaces, volumes decoded from the atlases the kernel read (`texel_atlas`, `normal_atlas`
/// bytes as copied from the GPU).
/// `members` are those the set was built from; `size` and `eye` the frame's.
pub(crate) fn twin_inputs(
    set: &ReferenceSet,
    members: &[Member],
    (frame, size, eye): (&FrameParams, (u32, u32), DVec3),
    texel_atlas: &[u8],
    normal_atlas: &[u8],
) -> (TraceView, Vec<TraceObject>) {
    let f = frame;
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let view = TraceView {
        width: size.0,
        height: size.1,
        forward: v3(f.forward),
        right: v3(set.params.right),
        up: v3(set.params.up),
        near: set.params.right[3] as f64,
        light_dir: v3(f.light_dir),
        light_color: [f.light_color[0] as f64, f.light_color[1] as f64, f.light_color[2] as f64],
        ambient: f.light_dir[3] as f64,
    };
    let decode = |bytes: &[u8], entry: &ReferenceObject, offset: u32, snorm: bool| {
        let [w, h, d, _] = entry.resolution;
        let pitch = entry.atlas[1] as usize;
        let mut texels = Vec::with_capacity((w * h * d) as usize);
        for z in 0..d as usize {
            for y in 0..h as usize {
                for x in 0..w as usize {
                    let at = (offset as usize + (z * h as usize + y) * pitch + x) * 4;
                    let b = &bytes[at..at + 4];
                    texels.push(std::array::from_fn(|c| {
                        if snorm {
                            (b[c] as i8 as f64 / 127.0).max(-1.0)
                        } else {
                            b[c] as f64 / 255.0
                        }
                    }));
                }
            }
        }
        DecodedTexel { resolution: [w, h, d], texels }
    };
    let mut objects = Vec::new();
    for (o, entry) in members.iter().zip(&set.table) {
        let s = o.surface;
        let rel = |p: DVec3| p - eye;
        let prisms = s
            .triangles
            .iter()
            .map(|t| {
                let ids = *t;
                let idx = t.map(|v| v as usize);
                PrismCorners {
                    bottom: idx.map(|v| rel(s.positions[v])),
                    top: idx.map(|v| rel(s.positions[v] + s.heights[v])),
                    ids,
                }
            })
            .collect();
        let per_pixel = o.per_pixel().then(|| {
            let frames = shell::vertex_frames(s);
            PerPixel {
                normals: decode(normal_atlas, entry, entry.atlas[2], true),
                frames: s
                    .triangles
                    .iter()
                    .map(|t| t.map(|v| (v3(frames[v as usize].ds), v3(frames[v as usize].dt))))
                    .collect(),
            }
        });
        objects.push(TraceObject {
            prisms,
            uvs: s.corner_uvs.clone(),
            volume: decode(texel_atlas, entry, entry.atlas[0], false),
            per_pixel,
            opacity_length: entry.params[0] as f64,
            step: o.step,
            opaque_base: o.opaque,
        });
    }
    (view, objects)
}
