//! Executing a planned graph: graph textures, pipelines (specialised by `override` constants and
//! cached), bind groups resolved by name, and one frame recorded into a single submission.

use std::borrow::Cow;
use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::gpu::cache::{self, GpuCache, Layout, Pipeline};
use crate::gpu::inputs::override_values;
use crate::gpu::reflect::{self, BindingKind};
use crate::gpu::timing::Timer;
use crate::gpu::{GpuContext, Inputs};
use crate::graph::plan::{self, Plan, PlannedPass};
use crate::graph::{Blend, Clear, Dispatch, Draw, Graph, PassDecl, ResourceDecl, TextureSize};

struct Texture {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    clear: Option<Clear>,
}

struct Buffer {
    buffer: wgpu::Buffer,
    clear: bool,
}

/// A planned graph with its resources allocated: records and runs frames on the GPU.
pub struct Executor {
    graph: Graph,
    textures: HashMap<String, Texture>,
    /// Graph buffers and parameters (uniform buffers holding their value).
    buffers: HashMap<String, Buffer>,
    modules: HashMap<String, wgpu::ShaderModule>,
    layouts: Vec<Layout>,
    pipelines: HashMap<(usize, String), Pipeline>,
}

impl Executor {
    /// Graph textures, shader modules and layouts for a plan; modules and layouts come from
    /// `cache` when their source and bindings are unchanged.
    pub fn new(
        ctx: &GpuContext,
        graph: Graph,
        plan: &Plan,
        size: (u32, u32),
        cache: &mut GpuCache,
    ) -> Result<Self> {
        let max2d = ctx.limits.max_texture_dimension_2d;
        if size.0 > max2d || size.1 > max2d {
            return Err(Error::Gpu(format!(
                "output {}x{} is beyond this adapter's 2D texture limit of {max2d}",
                size.0, size.1
            )));
        }
        for p in &plan.passes {
            check_counts(&graph, &p.decl, &plan.vocabulary.counts)?;
        }
        plan::check_buffer_limits(&graph, plan, &ctx.limits)?;
        let mut buffers = HashMap::new();
        for (name, b) in &plan.buffers {
            let usage = wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC
                | if b.indirect { wgpu::BufferUsages::INDIRECT } else { wgpu::BufferUsages::empty() };
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: b.bytes.next_multiple_of(4),
                usage,
                mapped_at_creation: false,
            });
            buffers.insert(name.clone(), Buffer { buffer, clear: b.clear });
        }
        for (name, v) in &plan.parameters {
            let bytes = v.bytes();
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: bytes.len() as u64,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            ctx.queue.write_buffer(&buffer, 0, &bytes);
            buffers.insert(name.clone(), Buffer { buffer, clear: false });
        }
        let blended: Vec<&str> = plan
            .passes
            .iter()
            .filter_map(|p| match &p.decl {
                PassDecl::Raster { targets, .. } => Some(targets),
                _ => None,
            })
            .flatten()
            .filter(|t| t.blend != Blend::Replace)
            .map(|t| t.resource.as_str())
            .collect();
        // Textures some compute pass writes as storage textures.
        let stored: Vec<&str> = plan
            .passes
            .iter()
            .flat_map(|p| &p.bindings)
            .filter(|b| matches!(b.kind, BindingKind::StorageTexture { .. }))
            .map(|b| b.name.as_str())
            .collect();
        let mut textures = HashMap::new();
        for (name, decl) in &plan.textures {
            let ResourceDecl::Texture { format, size: tsize, clear } = decl else { continue };
            let (w, h) = match tsize {
                TextureSize::Output => size,
                TextureSize::Fixed(w, h) => (*w, *h),
            };
            // In a scope: an error left uncaptured would surface in a later, unrelated render.
            let made = ctx.scoped(&format!("texture `{name}`"), || {
                ctx.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(name),
                    size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: texture_format(ctx, &graph, name, format.wgpu(), &blended),
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | wgpu::TextureUsages::COPY_SRC
                        | if stored.contains(&name.as_str()) {
                            wgpu::TextureUsages::STORAGE_BINDING
                        } else {
                            wgpu::TextureUsages::empty()
                        },
                    view_formats: &[],
                })
            });
            let texture = made.map_err(|e| graph.error_at_resource(name, e.to_string()))?;
            let view = texture.create_view(&Default::default());
            textures.insert(name.clone(), Texture { texture, view, clear: *clear });
        }
        let mut modules = HashMap::new();
        let mut layouts = Vec::new();
        for p in &plan.passes {
            let name = p.decl.shader().to_string();
            let label = format!("shader {name}");
            let module = cache.module(p.kernel.source_hash, || {
                ctx.scoped(&label, || {
                    ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(&label),
                        source: wgpu::ShaderSource::Naga(Cow::Owned(p.kernel.module.clone())),
                    })
                })
            })?;
            modules.insert(name, module);
            let entries: Vec<wgpu::BindGroupLayoutEntry> =
                p.bindings.iter().map(reflect::layout_entry).collect();
            let groups: Vec<u32> = p.bindings.iter().map(|b| b.group).collect();
            layouts.push(cache.layout(cache::key(&(&entries, &groups)), || pass_layout(ctx, p)));
        }
        Ok(Self { graph, textures, buffers, modules, layouts, pipelines: HashMap::new() })
    }

    pub(crate) fn texture(&self, name: &str) -> Option<&wgpu::Texture> {
        self.textures.get(name).map(|t| &t.texture)
    }

    /// A graph buffer (or a parameter's uniform buffer).
    pub(crate) fn buffer(&self, name: &str) -> Option<&wgpu::Buffer> {
        self.buffers.get(name).map(|b| &b.buffer)
    }

    /// A buffer bound by name: the instance's, then the frame's, then the graph's.
    fn resolve<'a>(&'a self, inst: &'a Inputs, frame: &'a Inputs, name: &str) -> Option<&'a wgpu::Buffer> {
        resolve_buffer(inst, frame, name).or_else(|| self.buffer(name))
    }

    /// Zeroes the graph buffers with `clear: Zero` that pass `pass` is the first this frame to use.
    fn clear_buffers(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pass: &PlannedPass,
        written: &mut Vec<String>,
    ) {
        for name in pass.reads.iter().chain(&pass.writes) {
            if let Some(b) = self.buffers.get(name) {
                if !written.contains(name) {
                    written.push(name.clone());
                    if b.clear {
                        encoder.clear_buffer(&b.buffer, 0, None);
                    }
                }
            }
        }
    }

    /// Creates every pipeline the frame will use now, so that errors come before any work.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        plan: &Plan,
        frame: &Inputs,
        objects: &[Inputs],
        cache: &mut GpuCache,
    ) -> Result<()> {
        for i in 0..plan.passes.len() {
            for inst in instance_inputs(&plan.passes[i], frame, objects) {
                self.pipeline(ctx, plan, i, frame, inst, cache)
                    .map_err(|e| self.at_pass(&plan.passes[i].decl, e))?;
            }
        }
        Ok(())
    }

    /// A wgpu error met while making or recording pass `decl`, at the pass in the graph file
    /// (a lost device stays what it is: nothing in the graph caused it).
    fn at_pass(&self, decl: &PassDecl, e: Error) -> Error {
        match e {
            Error::Gpu(msg) => {
                self.graph.error_at(decl.name(), format!("pass `{}` ({}): {msg}", decl.name(), decl.shader()))
            }
            e => e,
        }
    }

    fn pipeline(
        &mut self,
        ctx: &GpuContext,
        plan: &Plan,
        index: usize,
        frame: &Inputs,
        inst: &Inputs,
        cache: &mut GpuCache,
    ) -> Result<()> {
        let pass = &plan.passes[index];
        let constants = specialisation(pass, frame, inst).map_err(|name| {
            self.graph.error_at(
                pass.decl.name(),
                format!(
                    "{}: override `{name}` has no default and no value from the scene",
                    pass.decl.shader()
                ),
            )
        })?;
        let key = (index, constants_key(&constants));
        if self.pipelines.contains_key(&key) {
            return Ok(());
        }
        let module = &self.modules[pass.decl.shader()];
        let layout = &self.layouts[index].pipeline;
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            zero_initialize_workgroup_memory: true,
        };
        let label = format!("{} ({})", pass.decl.name(), pass.decl.shader());
        let formats: Vec<wgpu::TextureFormat> = match &pass.decl {
            PassDecl::Raster { targets, depth, .. } => targets
                .iter()
                .map(|t| &t.resource)
                .chain(depth.iter().map(|d| &d.resource))
                .map(|r| self.textures[r].texture.format())
                .collect(),
            PassDecl::Compute { .. } => Vec::new(),
        };
        // Everything that defines the pipeline: source, bindings, the pass (entries, blending,
        // depth), target formats and specialisation.
        let desc = cache::key(&(pass.kernel.source_hash, &pass.bindings, &pass.decl, &formats, &constants));
        let pipeline = cache.pipeline(desc, || {
            Ok(match &pass.decl {
                PassDecl::Compute { entry, .. } => ctx.scoped(&label, || {
                    Pipeline::Compute(ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(&label),
                        layout: Some(layout),
                        module,
                        entry_point: Some(entry),
                        compilation_options: options.clone(),
                        cache: None,
                    }))
                })?,
                PassDecl::Raster { vertex, fragment, targets, depth, .. } => {
                    let color: Vec<Option<wgpu::ColorTargetState>> = targets
                        .iter()
                        .map(|t| {
                            Some(wgpu::ColorTargetState {
                                format: self.textures[&t.resource].texture.format(),
                                blend: match t.blend {
                                    Blend::Replace => None,
                                    Blend::PremultipliedOver => {
                                        Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)
                                    }
                                    Blend::Add => {
                                        let add = wgpu::BlendComponent {
                                            src_factor: wgpu::BlendFactor::One,
                                            dst_factor: wgpu::BlendFactor::One,
                                            operation: wgpu::BlendOperation::Add,
                                        };
                                        Some(wgpu::BlendState { color: add, alpha: add })
                                    }
                                },
                                write_mask: wgpu::ColorWrites::ALL,
                            })
                        })
                        .collect();
                    let depth_stencil = depth.as_ref().map(|d| wgpu::DepthStencilState {
                        format: self.textures[&d.resource].texture.format(),
                        depth_write_enabled: Some(d.write),
                        depth_compare: Some(d.compare.wgpu()),
                        stencil: Default::default(),
                        bias: Default::default(),
                    });
                    ctx.scoped(&label, || {
                        Pipeline::Render(ctx.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                            label: Some(&label),
                            layout: Some(layout),
                            vertex: wgpu::VertexState {
                                module,
                                entry_point: Some(vertex),
                                compilation_options: options.clone(),
                                buffers: &[],
                            },
                            primitive: wgpu::PrimitiveState::default(),
                            depth_stencil,
                            multisample: Default::default(),
                            fragment: Some(wgpu::FragmentState {
                                module,
                                entry_point: Some(fragment),
                                compilation_options: options.clone(),
                                targets: &color,
                            }),
                            multiview_mask: None,
                            cache: None,
                        }))
                    })?
                }
            })
        })?;
        self.pipelines.insert(key, pipeline);
        Ok(())
    }

    /// Records and submits one frame.
    pub fn run(
        &mut self,
        ctx: &GpuContext,
        plan: &Plan,
        frame: &Inputs,
        objects: &[Inputs],
        timer: &mut Timer,
    ) -> Result<()> {
        let mut encoder =
            ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        // Whole dispatches start at the first pixel (a frame in steps may have left a tile's).
        if let Some(origin) = frame.buffers.get(STEP_ORIGIN) {
            ctx.queue.write_buffer(origin, 0, &[0; 16]);
        }
        let mut written: Vec<String> = Vec::new();
        for index in 0..plan.passes.len() {
            ctx.fault_at_pass();
            self.record(ctx, plan, index, frame, objects, &mut encoder, timer, &mut written, 0..u64::MAX)
                .map_err(|e| self.at_pass(&plan.passes[index].decl, e))?;
        }
        timer.resolve(&mut encoder);
        // The encoder reports a pass's error at `finish`; wgpu's message quotes the pass's label.
        let commands = ctx.scoped("recording the frame", || encoder.finish()).map_err(|e| {
            let culprit = match &e {
                Error::Gpu(msg) => plan.passes.iter().find(|p| msg.contains(&format!("'{}'", p.decl.name()))),
                _ => None,
            };
            match culprit {
                Some(p) => self.at_pass(&p.decl, e),
                None => e,
            }
        })?;
        ctx.queue.submit([commands]);
        ctx.take_errors()
    }

    /// Units of work of pass `index` (see [`Executor::step`]): a compute pass's dispatches over its
    /// instances, 1 for a raster pass.
    fn units(plan: &Plan, index: usize, frame: &Inputs, objects: &[Inputs]) -> u64 {
        let pass = &plan.passes[index];
        match &pass.decl {
            PassDecl::Compute { repeat, .. } => instance_inputs(pass, frame, objects)
                .iter()
                .map(|i| count(repeat, i, frame) as u64 * tiles(pass, i, frame).map_or(1, |t| t.count()))
                .sum(),
            PassDecl::Raster { .. } => 1,
        }
    }

    /// For a tiled pass, the units left from `unit` to the end of its tile; `None` otherwise.
    /// Of a tiled pass, the units left in the tile holding `unit`, and a whole tile's.
    fn tile_left(
        plan: &Plan,
        index: usize,
        frame: &Inputs,
        objects: &[Inputs],
        unit: u64,
    ) -> Option<(u64, u64)> {
        let pass = &plan.passes[index];
        let PassDecl::Compute { repeat, .. } = &pass.decl else { return None };
        let mut first = 0u64;
        for inst in instance_inputs(pass, frame, objects) {
            let t = tiles(pass, inst, frame)?;
            let repeats = count(repeat, inst, frame) as u64;
            let units = repeats * t.count();
            if unit < first + units {
                return Some((repeats - (unit - first) % repeats.max(1), repeats));
            }
            first += units;
        }
        Some((1, 1))
    }

    /// A frame to be rendered in steps ([`Executor::step`]): what is left of it.
    pub(crate) fn begin_steps(plan: &Plan, frame: &Inputs, objects: &[Inputs]) -> Steps {
        let total = (0..plan.passes.len()).map(|i| Self::units(plan, i, frame, objects).max(1)).sum();
        Steps { pass: 0, unit: 0, done: 0, total, written: Vec::new(), submitted: None, starts_tile: false }
    }

    /// Records and submits the next `max_units` units of work of `steps`' frame (at least one),
    /// splitting a repeated compute pass between its dispatches: the same dispatches in the same
    /// order as [`Executor::run`], so the finished frame is the same bit for bit, but in submissions
    /// short enough for other work (a window's frames) to run between them. Each part of a pass
    /// is timed on its own by `timer` (one made for [`Steps::progress`]'s total). Returns whether
    /// the frame is finished.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step(
        &mut self,
        ctx: &GpuContext,
        plan: &Plan,
        frame: &Inputs,
        objects: &[Inputs],
        steps: &mut Steps,
        max_units: u64,
        timer: &mut Timer,
    ) -> Result<bool> {
        let mut encoder =
            ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame step") });
        let mut budget = max_units.max(1);
        let mut recorded_any = false;
        while budget > 0 && steps.pass < plan.passes.len() {
            let index = steps.pass;
            let units = Self::units(plan, index, frame, objects).max(1);
            // A tiled pass's units set their tile's origin, which one submission holds one of:
            // it takes the units of one tile (its dispatches).
            let tile_left = Self::tile_left(plan, index, frame, objects, steps.unit).map(|t| t.0);
            if tile_left.is_some() && recorded_any {
                break;
            }
            let tiled = tile_left.is_some();
            let take = budget.min(tile_left.unwrap_or(units - steps.unit));
            recorded_any = true;
            ctx.fault_at_pass();
            let range = steps.unit..steps.unit + take;
            let mut written = std::mem::take(&mut steps.written);
            let recorded =
                self.record(ctx, plan, index, frame, objects, &mut encoder, timer, &mut written, range);
            steps.written = written;
            recorded.map_err(|e| self.at_pass(&plan.passes[index].decl, e))?;
            budget -= take;
            steps.done += take;
            steps.unit += take;
            if steps.unit == units {
                steps.pass += 1;
                steps.unit = 0;
            }
            if tiled {
                break;
            }
        }
        steps.starts_tile = steps.pass < plan.passes.len()
            && Self::tile_left(plan, steps.pass, frame, objects, steps.unit).is_some_and(|(l, w)| l == w);
        timer.resolve(&mut encoder);
        let commands = ctx.scoped("recording a frame step", || encoder.finish())?;
        steps.submitted = Some(ctx.queue.submit([commands]));
        ctx.take_errors()?;
        Ok(steps.pass == plan.passes.len())
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        ctx: &GpuContext,
        plan: &Plan,
        index: usize,
        frame: &Inputs,
        objects: &[Inputs],
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut Timer,
        written: &mut Vec<String>,
        units: std::ops::Range<u64>,
    ) -> Result<()> {
        let pass = &plan.passes[index];
        // A later part of a split pass: its clears were recorded with its first part.
        let first_part = units.start == 0;
        let instances = instance_inputs(pass, frame, objects);
        let groups: Vec<Vec<wgpu::BindGroup>> = instances
            .iter()
            .map(|inst| self.bind_groups(ctx, pass, index, frame, inst))
            .collect::<Result<_>>()?;
        if first_part {
            self.clear_buffers(encoder, pass, written);
        }
        let pipeline_of = |inst: &Inputs| -> &Pipeline {
            // `prepare` made every pipeline, so the specialisation is known to succeed here.
            &self.pipelines[&(index, constants_key(&specialisation(pass, frame, inst).unwrap_or_default()))]
        };
        match &pass.decl {
            PassDecl::Compute { name, entry, clear, dispatch, repeat, .. } => {
                for inst in instances.iter().filter(|_| first_part) {
                    for b in clear {
                        let buf = self
                            .resolve(inst, frame, b)
                            .ok_or_else(|| plan::unknown_resource(&self.graph, name, b))?;
                        encoder.clear_buffer(buf, 0, None);
                    }
                }
                // Graph textures a compute pass touches before any pass wrote them this frame start
                // from their clear value (e.g. the depth buffer when no base surface is drawn).
                for b in pass.bindings.iter().filter(|_| first_part) {
                    if self.textures.contains_key(&b.name) && !written.contains(&b.name) {
                        written.push(b.name.clone());
                        if !matches!(b.kind, BindingKind::StorageTexture { .. }) {
                            self.clear_texture(encoder, &b.name);
                        }
                    }
                }
                let wg = reflect::workgroup_size(&pass.kernel, entry).unwrap_or([1, 1, 1]);
                let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: timer.compute(name),
                });
                // Units of work: each dispatch of each instance, in order (of each tile, when a
                // part of a tiled pass is recorded); `units` picks some.
                let whole = units == (0..u64::MAX);
                let mut unit = 0u64;
                for (inst, bgs) in instances.iter().zip(&groups) {
                    let tiling = tiles(pass, inst, frame).filter(|_| !whole);
                    let repeats = count(repeat, inst, frame) as u64 * tiling.map_or(1, |t| t.count());
                    let mine = units.start.max(unit)..units.end.min(unit + repeats);
                    let first_unit = unit;
                    unit += repeats;
                    if mine.is_empty() {
                        continue;
                    }
                    let Pipeline::Compute(p) = pipeline_of(inst) else { unreachable!("compute pass") };
                    let (counts, per_group) = match dispatch {
                        Dispatch::Threads(x, y, z) => ([x, y, z], false),
                        Dispatch::Groups(x, y, z) => ([x, y, z], true),
                    };
                    let mut g = [0u32; 3];
                    for axis in 0..3 {
                        let n = count(counts[axis], inst, frame);
                        g[axis] = if per_group { n } else { n.div_ceil(wg[axis].max(1)) };
                        if g[axis] > ctx.limits.max_compute_workgroups_per_dimension {
                            return Err(Error::Gpu(format!(
                                "pass {name}: {} workgroups on axis {axis} exceed the adapter's limit of {}",
                                g[axis], ctx.limits.max_compute_workgroups_per_dimension
                            )));
                        }
                    }
                    if g.contains(&0) {
                        continue;
                    }
                    cpass.set_pipeline(p);
                    for (i, bg) in bgs.iter().enumerate() {
                        cpass.set_bind_group(i as u32, bg, &[]);
                    }
                    for u in mine {
                        match tiling {
                            // One unit a submission (`step`): the tile's origin is written for it.
                            Some(t) => {
                                // Tile by tile, each tile's dispatches in turn.
                                let (origin, groups) = t.tile((u - first_unit) / (repeats / t.count()), g);
                                let buffer = frame
                                    .buffers
                                    .get(STEP_ORIGIN)
                                    .ok_or_else(|| plan::unknown_resource(&self.graph, name, STEP_ORIGIN))?;
                                ctx.queue.write_buffer(
                                    buffer,
                                    0,
                                    bytemuck::cast_slice(&[origin[0], origin[1], 0, 0]),
                                );
                                cpass.dispatch_workgroups(groups[0], groups[1], groups[2]);
                            }
                            None => cpass.dispatch_workgroups(g[0], g[1], g[2]),
                        }
                    }
                }
            }
            PassDecl::Raster { name, targets, depth, draw, .. } => {
                let load = |res: &str, written: &mut Vec<String>| {
                    let first = !written.iter().any(|w| w == res);
                    if first {
                        written.push(res.to_string());
                    }
                    (first, self.textures[res].clear)
                };
                let color: Vec<Option<wgpu::RenderPassColorAttachment>> = targets
                    .iter()
                    .map(|t| {
                        let (first, clear) = load(&t.resource, written);
                        let load = match (first, clear) {
                            (true, Some(Clear::Color(r, g, b, a))) => wgpu::LoadOp::Clear(wgpu::Color {
                                r: r as f64,
                                g: g as f64,
                                b: b as f64,
                                a: a as f64,
                            }),
                            (true, _) => wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            _ => wgpu::LoadOp::Load,
                        };
                        Some(wgpu::RenderPassColorAttachment {
                            view: &self.textures[&t.resource].view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
                        })
                    })
                    .collect();
                let depth_att = depth.as_ref().map(|d| {
                    let (first, clear) = load(&d.resource, written);
                    let load = match (first, clear) {
                        (true, Some(Clear::Depth(v))) => wgpu::LoadOp::Clear(v),
                        (true, _) => wgpu::LoadOp::Clear(1.0),
                        _ => wgpu::LoadOp::Load,
                    };
                    wgpu::RenderPassDepthStencilAttachment {
                        view: &self.textures[&d.resource].view,
                        depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Store }),
                        stencil_ops: None,
                    }
                });
                let mut rpass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(name),
                    color_attachments: &color,
                    depth_stencil_attachment: depth_att,
                    timestamp_writes: timer.render(name),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                // (instance, byte offset into the per-plane arguments or None for a whole draw).
                let items: Vec<(usize, Option<u64>)> = match draw {
                    Draw::DepthSorted { .. } => depth_sorted(&instances),
                    _ => (0..instances.len()).map(|i| (i, None)).collect(),
                };
                let mut bound = None;
                for (i, plane) in items {
                    let inst = instances[i];
                    if bound != Some(i) {
                        let Pipeline::Render(p) = pipeline_of(inst) else { unreachable!("raster pass") };
                        rpass.set_pipeline(p);
                        for (g, bg) in groups[i].iter().enumerate() {
                            rpass.set_bind_group(g as u32, bg, &[]);
                        }
                        bound = Some(i);
                    }
                    let buffer = |b: &str| {
                        self.resolve(inst, frame, b)
                            .ok_or_else(|| plan::unknown_resource(&self.graph, name, b))
                    };
                    match (draw, plane) {
                        (Draw::Vertices(n), _) => rpass.draw(0..count(n, inst, frame), 0..1),
                        (Draw::Indirect(b), _) | (Draw::DepthSorted { whole: b, .. }, None) => {
                            rpass.draw_indirect(buffer(b)?, 0)
                        }
                        (Draw::DepthSorted { per_plane, .. }, Some(offset)) => {
                            rpass.draw_indirect(buffer(per_plane)?, offset)
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Clears a graph texture to its declared clear value (transparent black or depth 1 if none).
    fn clear_texture(&self, encoder: &mut wgpu::CommandEncoder, name: &str) {
        let t = &self.textures[name];
        let depth = t.texture.format().is_depth_stencil_format();
        let color = match t.clear {
            Some(Clear::Color(r, g, b, a)) => {
                wgpu::Color { r: r as f64, g: g as f64, b: b as f64, a: a as f64 }
            }
            _ => wgpu::Color::TRANSPARENT,
        };
        let depth_value = match t.clear {
            Some(Clear::Depth(v)) => v,
            _ => 1.0,
        };
        let color_att = [Some(wgpu::RenderPassColorAttachment {
            view: &t.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(color), store: wgpu::StoreOp::Store },
        })];
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("clear"),
            color_attachments: if depth { &[] } else { &color_att },
            depth_stencil_attachment: depth.then_some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth_value),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }

    fn bind_groups(
        &self,
        ctx: &GpuContext,
        pass: &PlannedPass,
        index: usize,
        frame: &Inputs,
        inst: &Inputs,
    ) -> Result<Vec<wgpu::BindGroup>> {
        let bgls = &self.layouts[index].groups;
        let mut out = Vec::new();
        for (group, bgl) in bgls.iter().enumerate() {
            let mut entries = Vec::new();
            for b in pass.bindings.iter().filter(|b| b.group as usize == group) {
                let resource = match &b.kind {
                    BindingKind::Uniform | BindingKind::Storage { .. } => {
                        self.resolve(inst, frame, &b.name).map(|buf| buf.as_entire_binding())
                    }
                    BindingKind::Texture { .. } | BindingKind::StorageTexture { .. } => inst
                        .views
                        .get(&b.name)
                        .or_else(|| frame.views.get(&b.name))
                        .or_else(|| self.textures.get(&b.name).map(|t| &t.view))
                        .map(wgpu::BindingResource::TextureView),
                    BindingKind::Sampler => inst
                        .samplers
                        .get(&b.name)
                        .or_else(|| frame.samplers.get(&b.name))
                        .map(wgpu::BindingResource::Sampler),
                };
                let resource =
                    resource.ok_or_else(|| plan::unknown_resource(&self.graph, pass.decl.name(), &b.name))?;
                entries.push(wgpu::BindGroupEntry { binding: b.binding, resource });
            }
            let label = format!("{} group {group}", pass.decl.name());
            out.push(ctx.scoped(&label, || {
                ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&label),
                    layout: bgl,
                    entries: &entries,
                })
            })?);
        }
        Ok(out)
    }
}

/// The format of a graph texture: as declared, except that a blended Rgba32Float target falls
/// back to Rgba16Float (with a warning) on adapters without FLOAT32_BLENDABLE.
fn texture_format(
    ctx: &GpuContext,
    graph: &Graph,
    name: &str,
    format: wgpu::TextureFormat,
    blended: &[&str],
) -> wgpu::TextureFormat {
    if format == wgpu::TextureFormat::Rgba32Float
        && blended.contains(&name)
        && !ctx.features.contains(wgpu::Features::FLOAT32_BLENDABLE)
    {
        eprintln!(
            "warning: {}: `{name}` blends in Rgba16Float: the adapter lacks FLOAT32_BLENDABLE",
            graph.path.display()
        );
        return wgpu::TextureFormat::Rgba16Float;
    }
    format
}

/// A pass's constants for an instance: the instance's values first, then the frame's.
fn specialisation<'a>(
    pass: &PlannedPass,
    frame: &'a Inputs,
    inst: &'a Inputs,
) -> std::result::Result<Vec<(&'a str, f64)>, String> {
    override_values(&pass.kernel, &[inst, frame])
}

/// Draw order of slice instances, back to front: an instance whose planes' depth range overlaps
/// no other instance's is one whole draw; the planes of overlapping instances are interleaved by
/// depth (ties keep instance order), each a draw of its own.
fn depth_sorted(instances: &[&Inputs]) -> Vec<(usize, Option<u64>)> {
    let range = |inst: &Inputs| {
        let d = &inst.plane_depths;
        (d.iter().copied().fold(f64::INFINITY, f64::min), d.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    };
    let ranges: Vec<(f64, f64)> = instances.iter().map(|i| range(i)).collect();
    let overlaps = |i: usize| {
        (0..ranges.len()).any(|j| j != i && ranges[j].0 <= ranges[i].1 && ranges[i].0 <= ranges[j].1)
    };
    let stride = std::mem::size_of::<crate::types::DrawIndirect>() as u64;
    let mut items: Vec<(f64, usize, Option<u64>)> = Vec::new();
    for (i, inst) in instances.iter().enumerate() {
        if overlaps(i) {
            items.extend(inst.plane_depths.iter().enumerate().map(|(k, &d)| (d, i, Some(k as u64 * stride))));
        } else {
            items.push((ranges[i].1, i, None));
        }
    }
    items.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    items.into_iter().map(|(_, i, plane)| (i, plane)).collect()
}

fn constants_key(constants: &[(&str, f64)]) -> String {
    format!("{constants:?}")
}

fn pass_layout(ctx: &GpuContext, pass: &PlannedPass) -> Layout {
    let count = pass.bindings.iter().map(|b| b.group + 1).max().unwrap_or(0);
    let groups: Vec<wgpu::BindGroupLayout> = (0..count)
        .map(|g| {
            let entries: Vec<_> =
                pass.bindings.iter().filter(|b| b.group == g).map(reflect::layout_entry).collect();
            ctx.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &entries })
        })
        .collect();
    let refs: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(Some).collect();
    let pipeline = ctx.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(pass.decl.name()),
        bind_group_layouts: &refs,
        immediate_size: 0,
    });
    Layout { groups, pipeline }
}

fn instance_inputs<'a>(pass: &PlannedPass, frame: &'a Inputs, objects: &'a [Inputs]) -> Vec<&'a Inputs> {
    match &pass.instances {
        None => vec![frame],
        Some(ids) => ids.iter().map(|&i| &objects[i]).collect(),
    }
}

fn resolve_buffer<'a>(inst: &'a Inputs, frame: &'a Inputs, name: &str) -> Option<&'a wgpu::Buffer> {
    inst.buffers.get(name).or_else(|| frame.buffers.get(name))
}

/// The frame resource (a uniform, xy the first pixel) through which a kernel learns where the
/// tile it is dispatched over starts: a compute pass binding it is split into tiles of about
/// [`TILE_PIXELS`] pixels when a frame renders in steps, one tile a submission.
pub(crate) const STEP_ORIGIN: &str = "step_origin";
/// Pixels of a tile of a split pass: about 60 ms of the exact Reference's first dispatch on
/// llvmpipe (its later dispatches, going on with the longer rays, are cheaper).
const TILE_PIXELS: u32 = 512;

/// What is left of a frame rendered in steps ([`Executor::step`]).
#[derive(Debug, Clone)]
pub struct Steps {
    pass: usize,
    unit: u64,
    done: u64,
    total: u64,
    written: Vec<String>,
    /// The last submission made, to wait for it alone.
    submitted: Option<wgpu::SubmissionIndex>,
    /// Whether the next unit starts a tile of a tiled pass (whose units may cost a hundred times
    /// the last tile's).
    starts_tile: bool,
}

impl Steps {
    /// Units of work done and in all (a compute pass counts one per dispatch).
    pub fn progress(&self) -> (u64, u64) {
        (self.done, self.total)
    }

    /// The submission of the last step (`None` before the first).
    pub(crate) fn last_submission(&self) -> Option<wgpu::SubmissionIndex> {
        self.submitted.clone()
    }

    /// Whether the next unit starts a tile of a tiled pass.
    pub(crate) fn starts_tile(&self) -> bool {
        self.starts_tile
    }
}

/// How a tiled pass (one binding [`STEP_ORIGIN`]) is cut when a frame renders in steps: tiles of
/// whole workgroups, about [`TILE_PIXELS`] threads each.
#[derive(Debug, Clone, Copy)]
struct Tiling {
    /// Workgroup size (x, y).
    group: [u32; 2],
    /// Workgroups per tile along x and y.
    per_tile: [u32; 2],
    /// Tiles along x and y.
    tiles: [u32; 2],
}

impl Tiling {
    fn count(&self) -> u64 {
        self.tiles[0] as u64 * self.tiles[1] as u64
    }

    /// Tile `k` (row by row) of a dispatch of `groups` workgroups: its first thread (x, y) and
    /// its workgroups.
    fn tile(&self, k: u64, groups: [u32; 3]) -> ([u32; 2], [u32; 3]) {
        let (tx, ty) = ((k % self.tiles[0] as u64) as u32, (k / self.tiles[0] as u64) as u32);
        let first = [tx * self.per_tile[0], ty * self.per_tile[1]];
        let n = [0, 1].map(|a| self.per_tile[a].min(groups[a] - first[a]));
        ([first[0] * self.group[0], first[1] * self.group[1]], [n[0], n[1], groups[2]])
    }
}

/// The tiling of a compute pass that binds [`STEP_ORIGIN`] for instance `inst`, else `None`.
fn tiles(pass: &PlannedPass, inst: &Inputs, frame: &Inputs) -> Option<Tiling> {
    let PassDecl::Compute { entry, dispatch, .. } = &pass.decl else { return None };
    if !pass.bindings.iter().any(|b| b.name == STEP_ORIGIN) {
        return None;
    }
    let wg = reflect::workgroup_size(&pass.kernel, entry).unwrap_or([1, 1, 1]);
    let (counts, per_group) = match dispatch {
        Dispatch::Threads(x, y, z) => ([x, y, z], false),
        Dispatch::Groups(x, y, z) => ([x, y, z], true),
    };
    let groups: Vec<u32> = (0..2)
        .map(|a| {
            let n = count(counts[a], inst, frame);
            if per_group {
                n
            } else {
                n.div_ceil(wg[a].max(1))
            }
        })
        .collect();
    let group = [wg[0].max(1), wg[1].max(1)];
    // Rows of one workgroup, as many workgroups along x as make about TILE_PIXELS threads.
    let per_tile = [(TILE_PIXELS / (group[0] * group[1])).max(1).min(groups[0].max(1)), 1];
    let tiles = [groups[0].div_ceil(per_tile[0]).max(1), groups[1].max(1)];
    Some(Tiling { group, per_tile, tiles })
}

fn count(name: &str, inst: &Inputs, frame: &Inputs) -> u32 {
    name.parse()
        .ok()
        .or_else(|| inst.counts.get(name).or_else(|| frame.counts.get(name)).copied())
        .unwrap_or(0)
}

/// Checks the dispatch and draw counts of a pass against the runtime's `counts` (called by the
/// planner, so `voltex plan` reports them without a GPU).
pub(crate) fn check_counts(graph: &Graph, decl: &PassDecl, counts: &[&str]) -> Result<()> {
    match decl {
        PassDecl::Compute {
            dispatch: Dispatch::Threads(x, y, z) | Dispatch::Groups(x, y, z),
            repeat,
            ..
        } => {
            for c in [x, y, z, repeat] {
                plan::check_count(graph, c, counts)?;
            }
        }
        PassDecl::Raster { draw: Draw::Vertices(n), .. } => plan::check_count(graph, n, counts)?,
        PassDecl::Raster { .. } => {}
    }
    Ok(())
}
