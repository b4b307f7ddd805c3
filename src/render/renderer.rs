//! GPU side of a blueprint: bakes, per-instance buffers, the graph executor, frames and readback.

use crate::bake::{self, Baker};
use crate::error::{Error, Result};
use crate::gpu::cache::{self, GpuCache};
use crate::gpu::sources::Sources;
use crate::gpu::timing::{Span, Timer};
use crate::gpu::Inputs;
use crate::gpu::{buffers, GpuContext};
use crate::graph::exec::{Executor, Steps, STEP_ORIGIN};
use crate::io::Image;
use crate::methods::InputCx;
use crate::progress::{Progress, Verbosity};
use crate::render::Blueprint;
use crate::types::ObjectParams;

/// A rendered frame.
pub struct Frame {
    /// The linear HDR colour.
    pub image: Image,
    /// Per-pass GPU time (ms) from timestamp queries; empty without TIMESTAMP_QUERY.
    pub pass_times: Vec<(String, f64)>,
    /// The AOVs asked for, as EXR channels: (name, samples row-major from the top row).
    pub aovs: Vec<(String, Vec<f32>)>,
    /// The same passes on the adapter's clock (traces, `render --trace`).
    pub spans: Vec<Span>,
}

impl Frame {
    /// GPU time of the whole frame (the sum over its passes), when timestamps were taken.
    pub fn gpu_ms(&self) -> Option<f64> {
        (!self.pass_times.is_empty()).then(|| self.pass_times.iter().map(|p| p.1).sum())
    }
}

/// Parts of passes a frame rendered in steps times: WebGPU's 4096 queries a query set, two each.
const MAX_TIMED_PARTS: u64 = 2048;

/// GPU resources of a blueprint, ready to render frames.
pub struct Renderer {
    /// The plan it renders.
    pub blueprint: Blueprint,
    exec: Executor,
    frame: Inputs,
    objects: Vec<Inputs>,
    timer: Timer,
    /// The timer of the frame rendered in steps (sized for its parts by `begin_steps`).
    step_timer: Timer,
    readback: wgpu::Buffer,
    /// The passes of the last frame on the adapter's clock.
    spans: Vec<Span>,
    /// Time spent making the bakes the cache did not have, GPU work included (ms).
    pub(crate) bake_ms: f64,
}

impl Renderer {
    /// Creates the blueprint's GPU resources (bakes, buffers, pipelines) on `ctx`.
    pub fn new(ctx: &GpuContext, blueprint: Blueprint) -> Result<Self> {
        Self::with_cache(ctx, blueprint, &mut GpuCache::default())
    }

    /// Like [`Renderer::new`], taking shader modules, pipelines and bakes from `cache` where
    /// nothing that defines them changed (the preview's hot reload).
    pub fn with_cache(ctx: &GpuContext, blueprint: Blueprint, cache: &mut GpuCache) -> Result<Self> {
        blueprint.check_limits(&ctx.limits, "this adapter's limit")?;
        let started = std::time::Instant::now();
        let bakes_before = cache.stats.bakes;
        // The baker keeps its kernels' pipelines across the preview's rebuilds.
        let sources = Sources::project()?;
        let baker_key = cache::key(&sources.describe());
        let mut baker = cache.take::<Baker>(baker_key).unwrap_or_else(|| Baker::new(&sources));
        let bake_keys: Vec<u64> =
            blueprint.bakes.iter().map(|b| bake_key(&sources, &b.request)).collect::<Result<_>>()?;
        let baked: Vec<bake::Baked> = (blueprint.bakes.iter().zip(&bake_keys))
            .map(|(b, &key)| cache.bake(key, || baker.bake(ctx, &b.request)))
            .collect::<Result<_>>()?;
        cache.put(baker_key, baker);
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("volume_sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // Between the MIP levels of texel layers (`lod: Auto`); level 0 alone elsewhere.
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        // What plans bake for themselves (mesh grids, splat sets), per instance's plan.
        let prepare = |plan: &dyn crate::methods::MethodPlan, cache: &mut GpuCache| {
            plan.prepare(ctx, cache, &baked, &bake_keys)
        };
        let mut prepared = Vec::with_capacity(blueprint.instances.len());
        for i in &blueprint.instances {
            prepared.push(prepare(blueprint.plan_of(i), cache)?);
        }
        // Bakes made are waited for here, so that their time is told apart from the pipelines'.
        if cache.stats.bakes > bakes_before {
            ctx.wait()?;
        }
        let bake_ms = started.elapsed().as_secs_f64() * 1e3;
        let mut frame = Inputs::default();
        frame
            .buffers
            .insert("frame".into(), buffers::uniform(ctx, "frame", bytemuck::bytes_of(&blueprint.frame)));
        frame.buffers.insert(STEP_ORIGIN.into(), buffers::uniform(ctx, STEP_ORIGIN, &[0; 16]));
        frame.samplers.insert("volume_sampler".into(), sampler);
        frame.counts.insert(crate::gpu::bindings::counts::WIDTH.into(), blueprint.size.0);
        frame.counts.insert(crate::gpu::bindings::counts::HEIGHT.into(), blueprint.size.1);
        let objects = blueprint
            .instances
            .iter()
            .zip(&prepared)
            .map(|(i, prepared)| {
                let cx = InputCx {
                    ctx,
                    size: blueprint.size,
                    bakes: &blueprint.bakes,
                    baked: &baked,
                    prepared: prepared.as_deref(),
                };
                instance_inputs(&cx, &blueprint, i)
            })
            .collect();
        let exec = Executor::new(ctx, blueprint.graph.clone(), &blueprint.plan, blueprint.size, cache)?;
        let timer = Timer::new(ctx, blueprint.plan.passes.len() as u32);
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("image readback"),
            size: blueprint.readback_bytes(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let step_timer = Timer::new(ctx, 1);
        let mut r =
            Self { blueprint, exec, frame, objects, timer, step_timer, readback, spans: Vec::new(), bake_ms };
        // Pipelines now, so that a bad kernel fails before any frame.
        r.exec.prepare(ctx, &r.blueprint.plan, &r.frame, &r.objects, cache)?;
        ctx.wait()?;
        Ok(r)
    }

    /// Renders one frame and reads back the graph's first output as a linear HDR image.
    pub fn render(&mut self, ctx: &GpuContext) -> Result<Frame> {
        self.timer.reset();
        self.exec.run(ctx, &self.blueprint.plan, &self.frame, &self.objects, &mut self.timer)?;
        self.spans = self.timer.read_spans(ctx)?;
        self.read_frame(ctx)
    }

    /// Renders one frame as [`Renderer::render`] does, showing its progress on stderr where
    /// `talk` asks for it ([`Verbosity::frame_progress`]): the share of its units of work done (a
    /// compute pass's dispatches, a tile of a tiled pass, each other pass) and an ETA, labelled
    /// `what`. Such a frame is rendered in steps of about a quarter of a second: the same image,
    /// bit for bit, its split passes' times summed back per pass.
    pub fn render_showing(&mut self, ctx: &GpuContext, talk: Verbosity, what: &str) -> Result<Frame> {
        if !talk.frame_progress() {
            return self.render(ctx);
        }
        let mut steps = self.begin_steps(ctx);
        let total = steps.progress().1 as usize;
        let mut progress = Progress::new(total, talk);
        let mut batch = 1;
        while !self.step_for(ctx, &mut steps, 250.0, &mut batch)? {
            progress.reach(steps.progress().0 as usize, what);
        }
        progress.reach(total, what);
        progress.end();
        let mut frame = self.read_frame(ctx)?;
        frame.pass_times = merged_parts(&frame.pass_times);
        Ok(frame)
    }

    /// Starts a frame rendered in steps ([`Renderer::step`]) rather than in one submission.
    pub fn begin_steps(&mut self, ctx: &GpuContext) -> Steps {
        let steps = Executor::begin_steps(&self.blueprint.plan, &self.frame, &self.objects);
        // Every part of a split pass gets its timestamps, up to the 4096 queries a set may hold
        // (parts past it are not timed).
        let parts = steps.progress().1 + self.blueprint.plan.passes.len() as u64;
        self.step_timer = Timer::new(ctx, parts.min(MAX_TIMED_PARTS) as u32);
        steps
    }

    /// Submits the next `max_units` units of work of `steps` (a compute pass counts one per
    /// dispatch, so a Reference or RayMarch frame splits between its dispatches); returns
    /// whether the frame is finished. The finished frame is the one [`Renderer::render`] makes,
    /// bit for bit, read with [`Renderer::read_frame`]. A window renders a slow frame so and
    /// draws itself between the steps; a new frame may start at any step (the old one is left).
    pub fn step(&mut self, ctx: &GpuContext, steps: &mut Steps, max_units: u64) -> Result<bool> {
        let plan = &self.blueprint.plan;
        let finished =
            self.exec.step(ctx, plan, &self.frame, &self.objects, steps, max_units, &mut self.step_timer)?;
        if finished {
            self.spans = self.step_timer.read_spans(ctx)?;
        }
        Ok(finished)
    }

    /// Renders `steps`' frame on for about `budget_ms` (a window draws itself between calls, a
    /// command shows its progress): submissions of `batch` units each, waited for one by one
    /// (lavapipe's submit itself waits for the one before). The batch doubles while one takes
    /// under an eighth of the budget and halves past a quarter; it starts again from one unit at
    /// every tile of a tiled pass, whose units may cost a hundred times the last ones (a
    /// Reference tile over the object after one over the background), so a submission runs past
    /// the budget by about one unit at most. Returns whether the frame is finished.
    pub(crate) fn step_for(
        &mut self,
        ctx: &GpuContext,
        steps: &mut Steps,
        budget_ms: f64,
        batch: &mut u32,
    ) -> Result<bool> {
        let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
        let start = std::time::Instant::now();
        loop {
            if steps.starts_tile() {
                *batch = 1;
            }
            let t = std::time::Instant::now();
            let finished = self.step(ctx, steps, *batch as u64)?;
            if let Some(submission) = steps.last_submission() {
                ctx.wait_for(submission)?;
                let took = ms(t);
                *batch = if took < budget_ms / 8.0 {
                    (*batch * 2).min(256)
                } else if took > budget_ms / 4.0 {
                    (*batch / 2).max(1)
                } else {
                    *batch
                };
            }
            if finished {
                return Ok(true);
            }
            if ms(start) >= budget_ms {
                return Ok(false);
            }
        }
    }

    /// Reads back the last frame rendered: the graph's first output, the AOVs and the pass times
    /// (per part of a pass split by [`Renderer::step`]).
    pub fn read_frame(&mut self, ctx: &GpuContext) -> Result<Frame> {
        let pass_times = self.spans.iter().map(|s| (s.name.clone(), s.ms)).collect();
        let image = self.read_output(ctx)?.box_downsample(self.blueprint.supersample);
        let mut aovs = Vec::new();
        for aov in &self.blueprint.aovs {
            let images =
                aov.textures.iter().map(|(t, _)| self.read_texture(ctx, t)).collect::<Result<Vec<_>>>()?;
            aovs.extend(crate::render::aov::channels(aov, images, self.blueprint.supersample));
        }
        Ok(Frame { image, pass_times, aovs, spans: self.spans.clone() })
    }

    /// Renders without reading the image back (benchmarks); returns per-pass GPU times.
    pub fn render_timed(&mut self, ctx: &GpuContext) -> Result<Vec<(String, f64)>> {
        self.timer.reset();
        self.exec.run(ctx, &self.blueprint.plan, &self.frame, &self.objects, &mut self.timer)?;
        ctx.wait()?;
        self.spans = self.timer.read_spans(ctx)?;
        Ok(self.spans.iter().map(|s| (s.name.clone(), s.ms)).collect())
    }

    /// The passes of the last frame rendered, on the adapter's clock (empty without timestamps).
    pub(crate) fn spans(&self) -> &[Span] {
        &self.spans
    }

    fn read_output(&self, ctx: &GpuContext) -> Result<Image> {
        self.read_texture(ctx, &self.blueprint.graph.file.outputs[0])
    }

    /// The inputs of graph instance `i` (tests and benchmarks read kernel outputs from them).
    pub fn instance_inputs(&self, i: usize) -> &Inputs {
        &self.objects[i]
    }

    /// Reads back a buffer of graph instance `instance` (tests and tools: a layer, a table).
    pub fn read_instance_buffer(&self, ctx: &GpuContext, instance: usize, name: &str) -> Result<Vec<u8>> {
        let b = self
            .objects
            .get(instance)
            .and_then(|i| i.buffers.get(name))
            .ok_or_else(|| Error::Invalid(format!("graph instance {instance} has no buffer `{name}`")))?;
        ctx.read_buffer(b, 0, b.size())
    }

    /// Reads back a graph buffer (`Buffer` or `Parameter` in the graph file) as the last frame left it.
    pub fn read_buffer(&self, ctx: &GpuContext, name: &str) -> Result<Vec<u8>> {
        let b = self.exec.buffer(name).ok_or_else(|| {
            Error::Invalid(format!("`{name}` is not a graph buffer of this plan (undeclared or pruned)"))
        })?;
        ctx.read_buffer(b, 0, b.size())
    }

    /// The graph's first output (the linear image), as rendered by the last frame.
    pub(crate) fn output_texture(&self) -> Option<&wgpu::Texture> {
        self.exec.texture(&self.blueprint.graph.file.outputs[0])
    }

    /// Reads a graph texture back as a linear image: Rgba32Float as it is, R32Float as grey with
    /// alpha 1.
    pub fn read_texture(&self, ctx: &GpuContext, name: &str) -> Result<Image> {
        let texture = self.exec.texture(name).ok_or_else(|| {
            let msg = format!(
                "output `{name}` is not a graph texture of this frame: it cannot be read back as an image"
            );
            self.blueprint.graph.error_at_output(name, msg)
        })?;
        let grey = texture.format() == wgpu::TextureFormat::R32Float;
        if texture.format() != wgpu::TextureFormat::Rgba32Float && !grey {
            return Err(self
                .blueprint
                .graph
                .error_at(name, format!("output `{name}` must be Rgba32Float or R32Float to be read back")));
        }
        let (w, h) = self.blueprint.size;
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row(w)),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        ctx.queue.submit([enc.finish()]);
        let bytes = ctx.map_read(&self.readback)?;
        let mut pixels = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            if grey {
                let row = &bytes[y * padded_row(w) as usize..][..w as usize * 4];
                pixels
                    .extend(bytemuck::pod_collect_to_vec::<u8, f32>(row).into_iter().map(|v| [v, v, v, 1.0]));
            } else {
                let row = &bytes[y * padded_row(w) as usize..][..w as usize * 16];
                pixels.extend(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(row));
            }
        }
        Image::from_pixels(w, h, pixels)
    }
}

/// What a bake is kept under: its request and the source of every kernel it runs, so that an
/// edit of a bake kernel (or of a file it includes) bakes again.
pub fn bake_key(sources: &Sources, request: &bake::BakeRequest) -> Result<u64> {
    let kernels: Vec<u64> = (request.kernels().iter())
        .map(|k| crate::gpu::shader::source_hash(sources, k))
        .collect::<Result<_>>()?;
    Ok(cache::key(&(request, kernels)))
}

fn padded_row(w: u32) -> u32 {
    (w * 16).div_ceil(256) * 256
}

/// Buffers, views, counts and constants of one graph instance: the object's uniform, then
/// what its plan binds.
fn instance_inputs(cx: &InputCx, bp: &Blueprint, i: &crate::render::Instance) -> Inputs {
    let o = &bp.objects[i.object];
    let mut inputs = Inputs::default();
    inputs.constants.push(("per_pixel_lighting".into(), o.per_pixel as u32 as f64));
    let opacity_length = o.bake.map(|b| bp.bakes[b].opacity_length).unwrap_or(1.0);
    let c = o.object.base_color.unwrap_or([0.0; 3]);
    let params = ObjectParams {
        base_color: [c[0], c[1], c[2], 1.0],
        opacity_length,
        index: i.object as u32,
        _pad: [0.0; 2],
    };
    inputs.buffers.insert("object".into(), buffers::uniform(cx.ctx, "object", bytemuck::bytes_of(&params)));
    bp.plan_of(i).add_inputs(cx, o, i.part, &mut inputs);
    inputs
}

impl Renderer {
    /// EXR metadata: how the image was made (voltex version, scene, graph, camera, time, size,
    /// AOVs, each object's method and quality knobs, adapter, GPU time).
    pub fn metadata(&self, ctx: &GpuContext, frame: &Frame) -> Vec<(String, String)> {
        let bp = &self.blueprint;
        let v = &bp.view;
        let (w, h) = bp.size;
        let n = bp.supersample;
        let mut m = vec![
            ("voltex_version".to_string(), env!("CARGO_PKG_VERSION").to_string()),
            ("voltex_scene".to_string(), bp.scene_path.display().to_string()),
            ("voltex_graph".to_string(), bp.graph.path.display().to_string()),
            (
                "voltex_camera".to_string(),
                format!(
                    "eye ({}, {}, {}), forward ({:.6}, {:.6}, {:.6}), up ({}, {}, {}), fov_y {} degrees",
                    v.eye.x,
                    v.eye.y,
                    v.eye.z,
                    v.forward.x,
                    v.forward.y,
                    v.forward.z,
                    v.up.x,
                    v.up.y,
                    v.up.z,
                    v.fov_y
                ),
            ),
            ("voltex_time".to_string(), format!("{}", bp.time)),
            ("voltex_size".to_string(), format!("{}x{} (supersample {n})", w / n, h / n)),
            ("voltex_adapter".to_string(), ctx.adapter_line()),
        ];
        if !bp.aovs.is_empty() {
            let names: Vec<&str> = bp.aovs.iter().map(|a| a.name.as_str()).collect();
            m.push(("voltex_aovs".into(), names.join(",")));
        }
        if let Some(t) = frame.gpu_ms() {
            m.push(("voltex_gpu_ms".into(), format!("{t:.3}")));
        }
        for o in &bp.objects {
            let method = o.methods.last().map_or("None".into(), |m| m.metadata(o));
            m.push((format!("voltex_object_{}", o.object.name), method));
        }
        m
    }

    /// OpenEXR's standard camera attributes of the frame (world space, not camera-relative).
    pub fn camera_attributes(&self) -> crate::io::exr::CameraAttributes {
        let v = &self.blueprint.view;
        let c = v.camera();
        let right = c.right.normalize();
        let up = right.cross(v.forward);
        // Left-handed camera space: x right, y up, z forward.
        let rotation = glam::DMat4::from_cols(
            glam::DVec4::new(right.x, up.x, v.forward.x, 0.0),
            glam::DVec4::new(right.y, up.y, v.forward.y, 0.0),
            glam::DVec4::new(right.z, up.z, v.forward.z, 0.0),
            glam::DVec4::W,
        );
        let world_to_camera = rotation * glam::DMat4::from_translation(-v.eye);
        // NDC x = 0.5 + 0.5 x / (z tan_x), y = 0.5 - 0.5 y / (z tan_y), after the divide by w = z.
        let (kx, ky) = (0.5 / c.right.length(), 0.5 / c.up.length());
        let project = glam::DMat4::from_cols(
            glam::DVec4::new(kx, 0.0, 0.0, 0.0),
            glam::DVec4::new(0.0, -ky, 0.0, 0.0),
            glam::DVec4::new(0.5, 0.5, 1.0, 1.0),
            glam::DVec4::ZERO,
        );
        // Imath multiplies row vectors: its row-major array is glam's column-major one.
        crate::io::exr::CameraAttributes {
            world_to_camera: world_to_camera.as_mat4().to_cols_array(),
            world_to_ndc: (project * world_to_camera).as_mat4().to_cols_array(),
            near: v.near as f32,
            far: v.far as f32,
        }
    }
}

/// Per-pass times with the parts of a pass split by a stepped frame summed, in order (as one
/// submission times them).
fn merged_parts(times: &[(String, f64)]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for (pass, ms) in times {
        match out.last_mut() {
            Some(last) if &last.0 == pass => last.1 += ms,
            _ => out.push((pass.clone(), *ms)),
        }
    }
    out
}
