//! ShellMarch objects of a frame as the renderer sees them: each object's knobs
//! ([`ShellPlan`]), and the one graph instance that marches them all ([`ShellSet`]).

use std::any::Any;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::filter;
use super::knobs::{Filter, ShellMarch};
use super::march_shell::{folds, Footprint, ShellObject};
use super::tiles::{self, TileLists};
use crate::gpu::bindings::counts as C;
use crate::bake::{occupancy, Baked};
use crate::cpu::prism_map::PrismCorners;
use crate::error::{Error, Result};
use crate::gpu::bindings::shell_march as B;
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::buffers::{storage, uniform};
use crate::gpu::cache::GpuCache;
use crate::gpu::{GpuContext, Inputs};
use crate::methods::reference::trace_reference::TraceView;
use crate::methods::reference::{build, default_step, twin_inputs, Member, ReferenceSet};
use crate::methods::view::View;
use crate::methods::{texels, BakePlan, InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::{Lighting, Method};
use crate::types::{FrameParams, ReferenceObject, ReferenceParams, ReferenceState, ShellFilter};

/// Mirrors `samples_per_dispatch` and the costs in march_shell.wgsl.
const BUDGET: f64 = 8192.0;
const PRISM_COST: f64 = 32.0;
const PIECE_COST: f64 = 16.0;
/// More dispatches than this means a scene far larger than its voxels.
const MAX_DISPATCHES: u32 = 4096;

/// One ShellMarch object: its knobs; it is drawn by the frame's [`ShellSet`].
pub(crate) struct ShellPlan {
    /// The knobs, lighting resolved.
    pub(crate) knobs: ShellMarch,
    /// Dispatches per frame of the set that marches it.
    pub(crate) dispatches: u32,
}

/// Plans `object`'s bake and lighting.
pub(crate) fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, m: &ShellMarch) -> Result<()> {
    object.per_pixel = m.lighting == Lighting::PerPixel;
    object.frames = object.per_pixel.then(|| crate::mesh::shell::vertex_frames(&object.object.surface));
    let texel = object.object.texel.clone().unwrap_or_default();
    let bake = texels::bake_index(cx.scene, &texel, object.per_pixel, cx.light, cx.time, cx.bakes)?;
    object.bake = Some(bake);
    // The footprint filter reads the layers' MIP levels (s and t halved, w kept).
    if m.filter == Filter::Footprint {
        cx.bakes[bake].request.layers = true;
    }
    object.methods.push(Box::new(ShellPlan { knobs: *m, dispatches: 0 }));
    Ok(())
}

/// Everything march_shell.wgsl reads, for all ShellMarch objects of a frame.
pub struct ShellSet {
    /// BVH, prisms (`uv2.z`: 1 where the map folds), shells, object table (`params`: opacity
    /// length, step, tolerance; `atlas.w`: the occupancy offset) and atlases.
    pub(crate) set: ReferenceSet,
    /// Per object: its knobs.
    pub(crate) knobs: Vec<ShellMarch>,
    /// Words of the occupancy pyramids (at least 1).
    pub(crate) occupancy_words: u64,
    /// Every prism binned into the image's tiles (`tiles::bin`); those whose texel is
    /// transparent over their uvs leave the lists once the atlas is known (`add_inputs`).
    pub(crate) tiles: TileLists,
    /// Per object its footprint filter (`shell_filters`), and the words of `shell_mips` (at
    /// least 1). A filtering object's prisms hold their voxel density in `uv2.w`.
    pub(crate) filters: Vec<ShellFilter>,
    pub(crate) mip_words: u64,
}

/// The frame's ShellMarch objects as the Reference's layout takes them.
fn members<'a>(objects: &'a [ObjectPlan], bakes: &[BakePlan]) -> Vec<(Member<'a>, ShellMarch)> {
    let member = |(index, o): (usize, &'a ObjectPlan)| {
        let knobs = o.method::<ShellPlan>()?.knobs;
        let bake = o.bake.unwrap_or(0);
        let resolution = bakes[bake].request.resolution;
        let member = Member {
            index,
            surface: &o.object.surface,
            shell: &o.shell,
            frames: o.frames.as_deref().filter(|_| o.per_pixel),
            opaque: o.object.base_color.is_some(),
            step: 2.0
                * default_step(&o.object.surface, o.object.prepared().frames(&o.object.surface), resolution)
                * knobs.step.min(1.0),
            bake,
            resolution,
            opacity_length: bakes[bake].opacity_length,
        };
        Some((member, knobs))
    };
    objects.iter().enumerate().filter_map(member).collect()
}

/// A bound on the work (budget units) along any ray through the object: a ray meets a shell in a
/// few stretches (four, for a torus seen edge-on), each no longer than its bounding diagonal.
fn work_bound(m: &Member) -> f64 {
    let s = m.surface;
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (p, h) in s.positions.iter().zip(&s.heights) {
        for q in [*p, *p + *h] {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let edges: f64 =
        s.triangles.iter().map(|t| (s.positions[t[1] as usize] - s.positions[t[0] as usize]).length()).sum();
    let edge = (edges / s.triangles.len().max(1) as f64).max(1e-12);
    let path = 4.0 * (hi - lo).length();
    let intervals = 2.0 * path / edge + 8.0;
    path / m.step + intervals * (PRISM_COST + 2.0 * PIECE_COST + 2.0)
}

/// The set of the frame's ShellMarch objects (see `Contribution::gather`).
pub(super) fn gather(objects: &mut [ObjectPlan], bakes: &[BakePlan], view: &View) -> Option<Box<dyn MethodPlan>> {
    let members = members(objects, bakes);
    if members.is_empty() {
        return None;
    }
    let camera = view.camera();
    let (r, u) = (camera.right.as_vec3(), camera.up.as_vec3());
    let params = ReferenceParams {
        right: [r.x, r.y, r.z, view.near as f32],
        up: [u.x, u.y, u.z, view.far as f32],
        counts: [0; 4],
    };
    let (list, knobs): (Vec<Member>, Vec<ShellMarch>) = members.into_iter().unzip();
    // No BVH: the kernel walks screen tiles' lists (`tiles.rs`).
    let mut set = build(&list, params, false);
    set.params.counts[3] = knobs.iter().all(|k| k.skip_empty) as u32;
    let filtering = knobs.iter().map(|k| (k.filter == Filter::Footprint).then_some(k.mip_bias));
    let (filters, mip_words) = filter::table(list.iter().map(|m| m.resolution).zip(filtering));
    let mut offset = 0u64;
    for (((entry, k), m), f) in set.table.iter_mut().zip(&knobs).zip(&list).zip(&filters) {
        entry.params[1] = k.step as f32;
        entry.params[2] = k.tolerance as f32;
        entry.atlas[3] = offset as u32;
        offset += occupancy::words(m.resolution) * pyramids(f) as u64;
    }
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    for p in &mut set.prisms {
        let ids = [p.vertices[0], p.vertices[1], p.vertices[2]];
        let corners = PrismCorners {
            bottom: ids.map(|v| v3(set.vertices[v as usize].bottom)),
            top: ids.map(|v| v3(set.vertices[v as usize].top)),
            ids,
        };
        p.uv2[2] = folds(&corners) as u32 as f32;
        let o = p.vertices[3] as usize;
        if filters[o].levels > 1 {
            let [x, y, z, _] = set.table[o].resolution;
            p.uv2[3] = filter::density(p, &set.vertices, [x, y, z]);
        }
    }
    let work: f64 = list.iter().map(work_bound).sum();
    // Twice the bound: each dispatch walks again to where the last one stopped.
    set.dispatches = ((2.0 * work / BUDGET).ceil() + 1.0).min(u32::MAX as f64) as u32;
    for o in objects.iter_mut().filter_map(|o| o.method_mut::<ShellPlan>()) {
        o.dispatches = set.dispatches;
    }
    let tiles = tiles::bin(&set.prisms, &set.vertices, &camera, view.size);
    Some(Box::new(ShellSet { set, knobs, occupancy_words: offset.max(1), tiles, filters, mip_words: mip_words.max(1) }))
}

impl ShellSet {
    /// Per prism its band (`prism_band`) from the `columns` of its object's pyramid that its
    /// filtered samples may skip by in a view of `size`.
    fn bands(&self, occupancy: &[&Occupancy], size: (u32, u32)) -> Vec<[f64; 2]> {
        let set = &self.set;
        let cone = filter::pixel_cone(set.params.right, set.params.up, size);
        let uv = |a: [f32; 4], i: usize| DVec2::new(a[i] as f64, a[i + 1] as f64);
        (set.prisms.iter())
            .map(|p| {
                let o = p.vertices[3] as usize;
                let pyramid = filter::prism_pyramid(p, &set.vertices, cone, &self.filters[o]) as usize;
                let columns = &occupancy[o][pyramid].1;
                prism_band(columns, &set.table[o], [uv(p.uv01, 0), uv(p.uv01, 2), uv(p.uv2, 0)])
            })
            .collect()
    }

    /// The objects that filter by footprint: filter, texel resolution, bake, lit per pixel.
    fn filtering(&self) -> impl Iterator<Item = (ShellFilter, [u32; 3], usize, bool)> + '_ {
        (self.filters.iter().zip(&self.set.table).zip(&self.set.copies))
            .filter(|((f, _), _)| f.levels > 1)
            .map(|((f, entry), &(bake, lit))| {
                let [x, y, z, _] = entry.resolution;
                (*f, [x, y, z], bake, lit)
            })
    }

    /// Words of `shell_normal_mips`: the places of `shell_mips` where a filtering object is lit
    /// per pixel, else 1 (the binding exists).
    fn normal_mip_words(&self) -> u64 {
        if self.filtering().any(|o| o.3) {
            self.mip_words
        } else {
            1
        }
    }

    /// `shell_filters`; `shell_mips` with levels 1.. of each filtering object's texel layers, and
    /// `shell_normal_mips` (the same places) with its normals' where it is lit per pixel.
    fn copy_mips(&self, ctx: &GpuContext, inputs: &mut Inputs, baked: &[Baked]) {
        let b = &mut inputs.buffers;
        b.insert(B::SHELL_FILTERS.into(), storage(ctx, "shell_filters", bytemuck::cast_slice(&self.filters)));
        let objects: Vec<_> = self.filtering().collect();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let buffers = [(B::SHELL_MIPS, 0, self.mip_words), (B::SHELL_NORMAL_MIPS, 1, self.normal_mip_words())];
        for (name, layer, words) in buffers {
            let mips = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: words * 8,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let copies: Vec<_> = (objects.iter())
                .filter(|o| layer == 0 || o.3)
                .map(|&(f, res, bake, _)| (f, res, &baked[bake].layers[layer]))
                .collect();
            filter::copy_levels(&mut encoder, &mips, &copies);
            b.insert(name.into(), mips);
        }
        if !objects.is_empty() {
            ctx.queue.submit([encoder.finish()]);
        }
    }

    /// The kernel's override constants: the lowest cutoff of its objects, and whether one
    /// filters by footprint. (Skipping, on unless an object turns it off, is
    /// `shell_params.counts.w`.)
    fn constants(&self) -> Vec<(String, f64)> {
        let cutoff = self.knobs.iter().map(|k| k.min_transmittance).fold(1.0, f64::min);
        let filtering = self.filters.iter().any(|f| f.levels > 1);
        vec![("min_transmittance".into(), cutoff), ("filtering".into(), filtering as u32 as f64)]
    }

    /// Per-pixel state and counters, the tables, the atlases (copied from the bakes) and the
    /// occupancy pyramids (made from the atlas, read back once).
    fn add_inputs(&self, cx: &InputCx, inputs: &mut Inputs) -> Result<()> {
        let (ctx, set) = (cx.ctx, &self.set);
        inputs.counts.insert(C::SHELL_MARCH_DISPATCHES.into(), set.dispatches);
        inputs.constants.extend(self.constants());
        let pixels = cx.size.0 as u64 * cx.size.1 as u64;
        let empty = |label: &str, bytes: u64, read: bool| {
            let read = if read { wgpu::BufferUsages::COPY_SRC } else { wgpu::BufferUsages::empty() };
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | read,
                mapped_at_creation: false,
            })
        };
        let state_bytes = pixels * std::mem::size_of::<ReferenceState>() as u64;
        let b = &mut inputs.buffers;
        b.insert(B::SHELL_MARCH_STATE.into(), empty("shell_march_state", state_bytes, true));
        b.insert(B::SHELL_MARCH_COUNTS.into(), empty("shell_march_counts", 16, true));
        b.insert(B::SHELL_PARAMS.into(), uniform(ctx, "shell_params", bytemuck::bytes_of(&set.params)));
        b.insert(B::SHELL_PRISMS.into(), storage(ctx, "shell_prisms", bytemuck::cast_slice(&set.prisms)));
        b.insert(B::SHELL_OBJECTS.into(), storage(ctx, "shell_objects", bytemuck::cast_slice(&set.table)));
        b.insert(B::SHELL_VERTICES.into(), storage(ctx, "shell_vertices", bytemuck::cast_slice(&set.vertices)));
        b.insert(B::VERTEX_FRAMES.into(), storage(ctx, "vertex_frames", bytemuck::cast_slice(&set.frames)));
        for (name, words) in [(B::TEXEL_ATLAS, set.atlas_words), (B::NORMAL_ATLAS, set.normal_words)] {
            b.insert(name.into(), empty(name, words * 4, true));
        }
        set.copy_volumes(ctx, inputs, cx.baked);
        self.copy_mips(ctx, inputs, cx.baked);
        let b = &mut inputs.buffers;
        // Made in `prepare`, once per bake (a camera move plans again, reads nothing back).
        let occupancy = cx.prepared.and_then(|p| p.downcast_ref::<Vec<Arc<Occupancy>>>());
        let occupancy = occupancy.ok_or_else(|| Error::Invalid("ShellMarch: no occupancy prepared".into()))?;
        let occupancy: Vec<&Occupancy> = occupancy.iter().map(|o| &**o).collect();
        let mut pyramids = Vec::with_capacity(self.occupancy_words as usize);
        for (pyramid, _) in occupancy.iter().flat_map(|o| o.iter()) {
            pyramids.extend_from_slice(pyramid);
        }
        pyramids.resize(self.occupancy_words as usize, 0);
        b.insert(B::SHELL_OCCUPANCY.into(), storage(ctx, "shell_occupancy", bytemuck::cast_slice(&pyramids)));
        let bands: Vec<[f32; 2]> =
            self.bands(&occupancy, cx.size).into_iter().map(|band| band.map(|w| w as f32)).collect();
        // Prisms whose texel is transparent are left out of the lists, but for their opaque bases.
        let listed: Vec<bool> = (set.prisms.iter().zip(&bands))
            .map(|(p, band)| band[0] <= band[1] || set.table[p.vertices[3] as usize].resolution[3] & 2 != 0)
            .collect();
        let t = self.tiles.only(&listed);
        // Bindings exist even where nothing is listed.
        let entries = if t.entries.is_empty() { &[0][..] } else { &t.entries };
        let bounds = if t.bounds.is_empty() { &[[0.0; 4]][..] } else { &t.bounds };
        let bands = if bands.is_empty() { &[[1.0, 0.0]][..] } else { &bands };
        b.insert(B::SHELL_TILES.into(), storage(ctx, "shell_tiles", bytemuck::cast_slice(&t.tiles)));
        b.insert(B::SHELL_TILE_PRISMS.into(), storage(ctx, "shell_tile_prisms", bytemuck::cast_slice(entries)));
        b.insert(B::SHELL_BOUNDS.into(), storage(ctx, "shell_bounds", bytemuck::cast_slice(bounds)));
        b.insert(B::SHELL_BANDS.into(), storage(ctx, "shell_bands", bytemuck::cast_slice(bands)));
        Ok(())
    }
}

/// Inputs of the f64 twin for a frame, from its objects, bakes and set and the atlases the kernel
/// read.
pub fn frame_twin_inputs(
    objects: &[ObjectPlan],
    bakes: &[BakePlan],
    set: &ShellSet,
    frame: (&FrameParams, (u32, u32), DVec3),
    texel_atlas: &[u8],
    normal_atlas: &[u8],
) -> (TraceView, Vec<ShellObject>) {
    let (list, knobs): (Vec<Member>, Vec<ShellMarch>) = members(objects, bakes).into_iter().unzip();
    let size = frame.1;
    let (view, traced) = twin_inputs(&set.set, &list, frame, texel_atlas, normal_atlas);
    let occupancy: Vec<Occupancy> =
        (set.set.table.iter().zip(&set.filters)).map(|(entry, f)| occupancy_of(texel_atlas, entry, f)).collect();
    let mut bands = set.bands(&occupancy.iter().collect::<Vec<_>>(), size).into_iter();
    let mut prisms = set.set.prisms.iter();
    let cone = filter::pixel_cone(set.set.params.right, set.set.params.up, size);
    let objects = (traced.into_iter().zip(knobs).zip(&set.filters))
        .map(|((trace, k), f)| {
            let n = trace.prisms.len();
            let bands = bands.by_ref().take(n).collect();
            let density = prisms.by_ref().take(n).map(|p| p.uv2[3] as f64).collect();
            let normals = trace.per_pixel.as_ref().map(|pp| &pp.normals);
            let filter = (f.levels > 1).then(|| Footprint::of(&trace.volume, normals, *f, density, cone));
            ShellObject { trace, step: k.step, tolerance: k.tolerance, bands, filter }
        })
        .collect();
    (view, objects)
}

/// An object's occupancy: per pyramid, its words and the w extents of its level-0 columns. The
/// texel's own pyramid, then where the object filters one per MIP level c from 1 on, of the
/// opacity dilated by `filter::radius(c)` in s and t (what a sample mixing level c reads).
type Occupancy = Vec<(Vec<u32>, Vec<Option<(u32, u32)>>)>;

/// Pyramids of an object with filter `f` in `shell_occupancy`.
fn pyramids(f: &ShellFilter) -> u32 {
    f.levels.max(1)
}

/// An object's [`Occupancy`] from the texel atlas the kernel reads.
fn occupancy_of(atlas: &[u8], entry: &ReferenceObject, f: &ShellFilter) -> Occupancy {
    let res = [entry.resolution[0], entry.resolution[1], entry.resolution[2]];
    occupancy_from_alpha(&occupancy::atlas_alpha(atlas, res, entry.atlas[0], entry.atlas[1]), res, f)
}

fn occupancy_from_alpha(alpha: &[u8], res: [u32; 3], f: &ShellFilter) -> Occupancy {
    (0..pyramids(f))
        .map(|c| {
            let dilated;
            let alpha = match filter::radius(c) {
                0 => alpha,
                r => {
                    dilated = occupancy::dilate_st(alpha, res, r);
                    &dilated
                }
            };
            let pyramid = occupancy::pyramid(alpha, res);
            let columns = occupancy::columns(&pyramid, res);
            (pyramid, columns)
        })
        .collect()
}

/// The band of w of a prism with corner uvs `uv` (its texel repeating) outside which its samples
/// are transparent, [1, 0] where all are: over the box of its uvs, which holds every sample's s
/// and t (barycentrics are interpolated or mapped inside the prism).
fn prism_band(columns: &[Option<(u32, u32)>], entry: &ReferenceObject, uv: [DVec2; 3]) -> [f64; 2] {
    let scale = DVec2::new(entry.resolution[0] as f64, entry.resolution[1] as f64);
    let (lo, hi) = (uv[0].min(uv[1]).min(uv[2]) * scale, uv[0].max(uv[1]).max(uv[2]) * scale);
    let res = [entry.resolution[0], entry.resolution[1], entry.resolution[2]];
    occupancy::band(columns, res, lo.to_array(), hi.to_array()).unwrap_or([1.0, 0.0])
}

fn lighting(object: &ObjectPlan) -> Lighting {
    if object.per_pixel {
        Lighting::PerPixel
    } else {
        Lighting::Baked
    }
}

impl MethodPlan for ShellPlan {
    fn parts(&self) -> Vec<PartDecl> {
        Vec::new()
    }

    fn add_inputs(&self, _cx: &InputCx, _object: &ObjectPlan, _part: usize, _inputs: &mut Inputs) {}

    fn summary(&self, object: &ObjectPlan) -> String {
        let k = &self.knobs;
        let filter = match k.filter {
            Filter::Off => String::new(),
            Filter::Footprint => format!(", filtered over the footprint (MIP bias {})", k.mip_bias),
        };
        format!(
            "ShellMarch step {} voxel(s), tolerance {} voxel(s), stop below {}, skipping {}{filter}, lighting {:?}, {} dispatch(es) per frame",
            k.step,
            k.tolerance,
            k.min_transmittance,
            if k.skip_empty { "on" } else { "off" },
            lighting(object),
            self.dispatches
        )
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        self.scene_method(object).map(|m| m.text()).unwrap_or_default()
    }

    fn memory(&self, _object: &ObjectPlan, _size: (u32, u32)) -> Vec<(String, u64)> {
        Vec::new()
    }

    fn scene_method(&self, object: &ObjectPlan) -> Option<Method> {
        Some(Method::ShellMarch(ShellMarch { lighting: lighting(object), ..self.knobs }))
    }

    crate::any_plan!();
}

impl MethodPlan for ShellSet {
    fn parts(&self) -> Vec<PartDecl> {
        vec![PartDecl { filters: vec!["ShellMarch"], order: 0 }]
    }

    fn distance(&self, _eye: DVec3) -> Option<f64> {
        Some(0.0)
    }

    fn members(&self) -> &[usize] {
        &self.set.objects
    }

    /// Samples composited (not those skipped) over the frame.
    fn evaluations(&self, read: &mut dyn FnMut(&str) -> Result<Vec<u8>>) -> Result<Option<f64>> {
        let counts: Vec<u32> = bytemuck::pod_collect_to_vec(&read(B::SHELL_MARCH_COUNTS)?);
        Ok(counts.first().map(|&n| n as f64))
    }

    fn constants(&self) -> Vec<(String, f64)> {
        ShellSet::constants(self)
    }

    /// Per object, its [`Occupancy`] from its bake's volume (level 0 read back), kept in the
    /// cache under the bake's key and the filter's levels: made once per bake, not per frame.
    fn prepare(
        &self,
        ctx: &GpuContext,
        cache: &mut GpuCache,
        baked: &[Baked],
        bake_keys: &[u64],
    ) -> Result<Option<Box<dyn Any + Send>>> {
        let mut out: Vec<Arc<Occupancy>> = Vec::with_capacity(self.set.table.len());
        for ((entry, &(bake, _)), f) in self.set.table.iter().zip(&self.set.copies).zip(&self.filters) {
            let key = crate::gpu::cache::key(&("shell_march occupancy", bake_keys[bake], pyramids(f)));
            let made = match cache.take::<Arc<Occupancy>>(key) {
                Some(o) => o,
                None => {
                    let res = [entry.resolution[0], entry.resolution[1], entry.resolution[2]];
                    let rgba = crate::gpu::readback::read_texture(ctx, &baked[bake].volume, 4)?;
                    let alpha: Vec<u8> = rgba.chunks_exact(4).map(|p| p[3]).collect();
                    Arc::new(occupancy_from_alpha(&alpha, res, f))
                }
            };
            cache.put(key, made.clone());
            out.push(made);
        }
        Ok(Some(Box::new(out)))
    }

    fn check_limits(&self, _object: &ObjectPlan, limits: &wgpu::Limits) -> Result<()> {
        if self.set.dispatches > MAX_DISPATCHES {
            return Err(Error::Invalid(format!(
                "ShellMarch: {} dispatches per frame (at most {MAX_DISPATCHES}): the objects are too large \
                 for their voxels; use a larger `step`",
                self.set.dispatches
            )));
        }
        self.set.check_limits(limits.max_storage_buffer_binding_size)
    }

    fn add_inputs(&self, cx: &InputCx, _object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        // A failed read-back leaves the pyramid out: the plan's binding check then names it.
        if let Err(e) = ShellSet::add_inputs(self, cx, inputs) {
            eprintln!("ShellMarch: {e}");
        }
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        let folded = self.set.prisms.iter().filter(|p| p.uv2[2] != 0.0).count();
        format!(
            "ShellMarch set of {} object(s): {} prisms ({folded} folded, mapped exactly), {} dispatch(es) per frame",
            self.set.objects.len(),
            self.set.prisms.len(),
            self.set.dispatches
        )
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        self.summary(object)
    }

    fn allocations(&self, _object: &ObjectPlan, size: (u32, u32)) -> Vec<Allocation> {
        vec![Allocation {
            what: format!("the ShellMarch per-pixel state at {}x{}", size.0, size.1),
            bytes: size.0 as u64 * size.1 as u64 * std::mem::size_of::<ReferenceState>() as u64,
            shape: AllocationKind::Buffer { storage: true },
            driver: Driver::Output,
        }]
    }

    fn memory(&self, _object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        let s = &self.set;
        vec![(
            format!(
                "shell march: {} prisms with bounds and bands, {} tile list entries at most, shells, texel atlas{}{}, \
                 occupancy pyramids, per-pixel state",
                s.prisms.len(),
                self.tiles.entries.len(),
                if s.normal_words > 1 { " + normal atlas" } else { "" },
                if self.mip_words > 1 { " + its s,t MIP levels (f16)" } else { "" }
            ),
            (s.prisms.len() * (48 + 32 + 8) + s.vertices.len() * 32 + s.frames.len() * 32) as u64
                + (self.tiles.tiles.len() * 8 + self.tiles.entries.len() * 4) as u64
                + (s.atlas_words + s.normal_words + self.occupancy_words) * 4
                + (self.mip_words + self.normal_mip_words()) * 8
                + self.filters.len() as u64 * 16
                + size.0 as u64 * size.1 as u64 * 32,
        )]
    }

    crate::any_plan!();
}
