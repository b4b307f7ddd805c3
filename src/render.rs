//! From a scene to an image: a [`Blueprint`] (CPU only: objects, shells, plane sweeps, bakes and
//! the pruned graph plan, enough for `voltex plan`), then a [`Renderer`] holding the GPU resources.

use std::path::PathBuf;

use glam::{DMat4, DVec3, DVec4};

use crate::bake::{self, BakeRequest, BakeSource, Baker};
use crate::cpu::bake::Shape as BakeShape;
use crate::error::{Error, Result};
use crate::gpu::timing::Timer;
use crate::gpu::GpuContext;
use crate::graph::exec::{Executor, Inputs};
use crate::graph::plan::{self, ObjectInfo, Plan};
use crate::graph::{Graph, ResourceDecl, TextureSize};
use crate::io::Image;
use crate::methods::shell::{self, Shell};
use crate::methods::view_slices;
use crate::scene::{Light, Lighting, Method, Scene, SceneObject, Shape, TexelSource};
use crate::types::{BaseVertex, FrameParams, ObjectParams, SliceParams, SliceVertex};

/// Overrides of what the scene file says, from the command line or tests.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    pub size: Option<(u32, u32)>,
    pub graph: Option<PathBuf>,
    pub planes: Option<u32>,
    pub trivial_reject: Option<bool>,
}

/// One object as the frame sees it.
pub struct ObjectPlan {
    pub object: SceneObject,
    pub shell: Shell,
    pub base: Option<Vec<BaseVertex>>,
    /// View slicing: the sweep and its vertex-buffer capacity.
    pub slicing: Option<(SliceParams, u64)>,
    pub trivial_reject: bool,
    pub per_pixel: bool,
    /// Index into `Blueprint::bakes`.
    pub bake: Option<usize>,
}

pub struct BakePlan {
    pub texel: String,
    pub request: BakeRequest,
    pub opacity_length: f32,
}

pub struct Blueprint {
    pub scene_path: PathBuf,
    pub size: (u32, u32),
    pub eye: DVec3,
    pub frame: FrameParams,
    pub objects: Vec<ObjectPlan>,
    pub bakes: Vec<BakePlan>,
    pub graph: Graph,
    pub plan: Plan,
}

pub fn default_graph() -> PathBuf {
    crate::project_root().join("graphs/frame.ron")
}

pub fn wgsl_root() -> PathBuf {
    crate::project_root().join("wgsl")
}

impl Blueprint {
    pub fn new(scene: &Scene, opts: &RenderOptions) -> Result<Self> {
        Self::with_objects(scene, scene.objects()?, opts)
    }

    /// Like [`Blueprint::new`] with the scene's objects given (tests alter their surfaces).
    pub fn with_objects(scene: &Scene, objects: Vec<SceneObject>, opts: &RenderOptions) -> Result<Self> {
        let size = opts.size.unwrap_or((scene.output.width, scene.output.height));
        let cam = &scene.camera;
        let eye = cam.eye;
        let forward = (cam.target - cam.eye).normalize_or_zero();
        if forward == DVec3::ZERO || forward.cross(cam.up).length_squared() < 1e-12 {
            return Err(Error::Invalid(format!(
                "{}: the camera's eye and target coincide, or `up` is parallel to the view direction",
                scene.path.display()
            )));
        }
        let f32v = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];

        // Depth range of everything drawn, for the projection's near and far planes.
        let mut far: f64 = 1e-3;
        for o in &objects {
            for (&p, &h) in o.surface.positions.iter().zip(&o.surface.heights) {
                for q in [p, p + h] {
                    far = far.max((q - eye).dot(forward));
                }
            }
        }
        far *= 1.01;
        let near = (far * 1e-4).max(1e-6);

        let mut bakes: Vec<BakePlan> = Vec::new();
        let mut plans = Vec::new();
        for object in objects {
            let shell = Shell::new(&object.surface, eye);
            let base = object.base_color.map(|_| shell::base_vertices(&object.surface, eye));
            let (mut slicing, mut trivial_reject, mut per_pixel, mut bake) = (None, true, false, None);
            if let Some(Method::ViewSlices(vs)) = &object.method {
                let planes = opts.planes.unwrap_or(vs.planes);
                if planes == 0 || planes > crate::scene::MAX_PLANES {
                    return Err(Error::Invalid(format!(
                        "{planes} planes: expected a plane count in 1..={}",
                        crate::scene::MAX_PLANES
                    )));
                }
                trivial_reject = opts.trivial_reject.unwrap_or(vs.trivial_reject);
                per_pixel = vs.lighting == Lighting::PerPixel;
                let mut params = view_slices::sweep(&shell, f32v(forward), planes, near);
                let capacity = view_slices::vertex_capacity(&shell, &params).max(3);
                params.vertex_capacity = capacity.min(u32::MAX as u64) as u32;
                slicing = Some((params, capacity));
                let texel_name = object.texel.clone().unwrap_or_default();
                bake = Some(bake_index(scene, &texel_name, per_pixel, &mut bakes)?);
            }
            plans.push(ObjectPlan { object, shell, base, slicing, trivial_reject, per_pixel, bake });
        }

        let graph = Graph::load(opts.graph.as_deref().unwrap_or(&default_graph()))?;
        let infos: Vec<ObjectInfo> = plans
            .iter()
            .map(|o| {
                let mut filters = Vec::new();
                if o.slicing.is_some() {
                    filters.push("ViewSlices");
                }
                if o.base.is_some() {
                    filters.push("BaseSurface");
                }
                let centre = o.object.surface.positions.iter().sum::<DVec3>()
                    / o.object.surface.positions.len().max(1) as f64;
                ObjectInfo { name: o.object.name.clone(), filters, distance: (centre - eye).length() }
            })
            .collect();
        let plan = plan::plan(&graph, &wgsl_root(), &infos)?;

        let view = view_matrix(forward, cam.up);
        let proj = projection(cam.fov_y.to_radians(), size.0 as f64 / size.1 as f64, near, far);
        let light = scene.lights.first();
        let (light_dir, light_color) = match light {
            Some(Light::Directional { direction, color, intensity }) => {
                (-direction.normalize(), color.map(|c| c * intensity))
            }
            None => (DVec3::new(0.3, 0.4, 1.0).normalize(), [1.0; 3]),
        };
        let frame = FrameParams {
            view_proj: (proj * view).as_mat4().to_cols_array_2d(),
            forward: [forward.x as f32, forward.y as f32, forward.z as f32, near as f32],
            light_dir: [light_dir.x as f32, light_dir.y as f32, light_dir.z as f32, scene.ambient],
            light_color: [light_color[0], light_color[1], light_color[2], 1.0],
            background: [scene.background[0], scene.background[1], scene.background[2], 1.0],
            viewport: [size.0 as f32, size.1 as f32, 1.0 / size.0 as f32, 1.0 / size.1 as f32],
        };
        for b in &mut bakes {
            // Baked shading treats the texel axes (s, t, w) as world (x, y, z): exact for a flat
            // z-up base surface; PerPixel lighting is right everywhere.
            b.request.light = [light_dir.x as f32, light_dir.y as f32, light_dir.z as f32];
            b.request.ambient = scene.ambient;
        }
        Ok(Self { scene_path: scene.path.clone(), size, eye, frame, objects: plans, bakes, graph, plan })
    }

    /// Bytes of GPU memory the frame allocates, by item.
    pub fn memory(&self) -> Vec<(String, u64)> {
        let mut out = Vec::new();
        for (name, decl) in &self.plan.textures {
            let ResourceDecl::Texture { format, size, .. } = decl;
            let (w, h) = match size {
                TextureSize::Output => self.size,
                TextureSize::Fixed(w, h) => (*w, *h),
            };
            out.push((
                format!("texture {name} {w}x{h} {format:?}"),
                w as u64 * h as u64 * format.bytes_per_pixel(),
            ));
        }
        for b in &self.bakes {
            let r = b.request.resolution;
            out.push((
                format!(
                    "texel {} {}x{}x{} rgba8 + mips{}",
                    b.texel,
                    r[0],
                    r[1],
                    r[2],
                    if b.request.per_pixel { " + normals" } else { "" }
                ),
                bake::bytes(r, b.request.per_pixel),
            ));
        }
        for o in &self.objects {
            let name = &o.object.name;
            let shell = (o.shell.vertices.len() * 32 + o.shell.prisms.len() * 64) as u64;
            if let Some((params, cap)) = &o.slicing {
                out.push((format!("object {name}: shell ({} prisms)", o.shell.prisms.len()), shell));
                out.push((
                    format!(
                        "object {name}: slice vertices (capacity {cap}) + {} plane cursors",
                        params.plane_count
                    ),
                    cap * std::mem::size_of::<SliceVertex>() as u64
                        + params.plane_count as u64 * 4
                        + 16
                        + 48
                        + 32,
                ));
            }
            if let Some(base) = &o.base {
                out.push((format!("object {name}: base triangles"), (base.len() * 32) as u64));
            }
        }
        out
    }

    /// The text of `voltex plan`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "scene {}\noutput {}x{}\n\nbakes:\n",
            self.scene_path.display(),
            self.size.0,
            self.size.1
        );
        if self.bakes.is_empty() {
            s += "  (none)\n";
        }
        for b in &self.bakes {
            let r = b.request.resolution;
            let kind = match b.request.source {
                BakeSource::Implicit(_) => "bake_implicit.wgsl",
                BakeSource::Heightfield(_) => "bake_heightfield.wgsl",
            };
            s += &format!(
                "  {:<16} {}x{}x{}  {kind} + downsample_volume.wgsl x{}  lighting {}\n",
                b.texel,
                r[0],
                r[1],
                r[2],
                bake::mip_count(r) - 1,
                if b.request.per_pixel { "per-pixel (albedo + normals)" } else { "baked" }
            );
        }
        s += "\nobjects:\n";
        for o in &self.objects {
            let method = match &o.slicing {
                Some((p, cap)) => format!(
                    "ViewSlices planes {} spacing {:.4} trivial_reject {} lighting {}, capacity {cap} vertices",
                    p.plane_count,
                    p.spacing,
                    o.trivial_reject,
                    if o.per_pixel { "PerPixel" } else { "Baked" }
                ),
                None => "base surface only".into(),
            };
            s += &format!("  {:<16} {} triangles  {method}\n", o.object.name, o.shell.prisms.len());
            for w in &o.object.report.warnings {
                s += &format!("    warning: {w}\n");
            }
        }
        s += "\npasses (in order):\n";
        for p in &self.plan.passes {
            let inst = match &p.instances {
                None => "frame".to_string(),
                Some(ids) => format!("{} object(s)", ids.len()),
            };
            let pipelines = self.pipeline_variants(p);
            s += &format!(
                "  {:<20} {:<26} {:<12} pipelines: {}\n",
                p.decl.name(),
                p.decl.shader(),
                inst,
                pipelines.join(", ")
            );
        }
        s += &format!(
            "\nkernels compiled: {}\n",
            self.plan.kernels().into_iter().collect::<Vec<_>>().join(", ")
        );
        if !self.plan.pruned.is_empty() {
            s += "\npruned:\n";
            for p in &self.plan.pruned {
                s += &format!("  {p}\n");
            }
        }
        s += "\nGPU memory:\n";
        let mem = self.memory();
        for (what, bytes) in &mem {
            s += &format!("  {:>10.2} MiB  {what}\n", *bytes as f64 / 1048576.0);
        }
        s += &format!("  {:>10.2} MiB  total\n", mem.iter().map(|m| m.1).sum::<u64>() as f64 / 1048576.0);
        s
    }

    fn pipeline_variants(&self, p: &plan::PlannedPass) -> Vec<String> {
        let names: Vec<String> = crate::gpu::reflect::overrides(&p.kernel).into_iter().map(|o| o.0).collect();
        let mut variants: Vec<String> = match &p.instances {
            None => vec![String::new()],
            Some(ids) => ids.iter().map(|&i| self.constants(&self.objects[i], &names)).collect(),
        };
        variants.sort();
        variants.dedup();
        variants.into_iter().map(|v| if v.is_empty() { "default".into() } else { v }).collect()
    }

    fn constants(&self, o: &ObjectPlan, names: &[String]) -> String {
        object_constants(o)
            .into_iter()
            .filter(|(n, _)| names.contains(n))
            .map(|(n, v)| format!("{n}={}", v != 0.0))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Right-handed view rotation (the camera at the origin looks down -z in view space).
fn view_matrix(forward: DVec3, up: DVec3) -> DMat4 {
    let s = forward.cross(up).normalize();
    let u = s.cross(forward);
    DMat4::from_cols(
        DVec4::new(s.x, u.x, -forward.x, 0.0),
        DVec4::new(s.y, u.y, -forward.y, 0.0),
        DVec4::new(s.z, u.z, -forward.z, 0.0),
        DVec4::W,
    )
}

/// Perspective projection to wgpu clip space (depth 0 at `near`, 1 at `far`).
fn projection(fov_y: f64, aspect: f64, near: f64, far: f64) -> DMat4 {
    let h = 1.0 / (0.5 * fov_y).tan();
    let r = far / (near - far);
    DMat4::from_cols(
        DVec4::new(h / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, h, 0.0, 0.0),
        DVec4::new(0.0, 0.0, r, -1.0),
        DVec4::new(0.0, 0.0, r * near, 0.0),
    )
}

fn object_constants(o: &ObjectPlan) -> Vec<(String, f64)> {
    vec![
        ("trivial_reject".into(), o.trivial_reject as u32 as f64),
        ("per_pixel_lighting".into(), o.per_pixel as u32 as f64),
    ]
}

fn bake_index(scene: &Scene, texel: &str, per_pixel: bool, bakes: &mut Vec<BakePlan>) -> Result<usize> {
    if let Some(i) = bakes.iter().position(|b| b.texel == texel && b.request.per_pixel == per_pixel) {
        return Ok(i);
    }
    let t = scene
        .texels
        .get(texel)
        .ok_or_else(|| Error::Invalid(format!("{}: unknown texel `{texel}`", scene.path.display())))?;
    let source = match &t.source {
        TexelSource::Implicit { shapes } => BakeSource::Implicit(crate::cpu::bake::pack_shapes(
            &shapes.iter().map(bake_shape).collect::<Vec<_>>(),
        )),
        TexelSource::PerlinHeight {
            frequency,
            octaves,
            amplitude,
            base,
            seed,
            color_low,
            color_high,
            opacity,
        } => {
            let c = |v: &[f32; 3]| [v[0], v[1], v[2], 0.0];
            BakeSource::Heightfield(crate::types::HeightfieldParams {
                frequency: *frequency,
                octaves: *octaves,
                seed: *seed,
                amplitude: *amplitude,
                base: *base,
                opacity: *opacity,
                color_low: c(color_low),
                color_high: c(color_high),
                ..Default::default()
            })
        }
        TexelSource::Constant { color, opacity } => {
            BakeSource::Implicit(crate::cpu::bake::pack_shapes(&[(BakeShape::Constant, *color, *opacity)]))
        }
    };
    bakes.push(BakePlan {
        texel: texel.to_string(),
        request: BakeRequest {
            resolution: t.resolution,
            source,
            per_pixel,
            light: [0.0, 0.0, 1.0],
            ambient: 0.2,
        },
        opacity_length: t.opacity_length,
    });
    Ok(bakes.len() - 1)
}

/// A rendered frame.
pub struct Frame {
    pub image: Image,
    /// Per-pass GPU time (ms) from timestamp queries; empty without TIMESTAMP_QUERY.
    pub pass_times: Vec<(String, f64)>,
}

impl Frame {
    pub fn gpu_ms(&self) -> Option<f64> {
        (!self.pass_times.is_empty()).then(|| self.pass_times.iter().map(|p| p.1).sum())
    }
}

/// GPU resources of a blueprint, ready to render frames.
pub struct Renderer {
    pub blueprint: Blueprint,
    exec: Executor,
    frame: Inputs,
    objects: Vec<Inputs>,
    timer: Timer,
    readback: wgpu::Buffer,
}

impl Renderer {
    pub fn new(ctx: &GpuContext, blueprint: Blueprint) -> Result<Self> {
        for o in &blueprint.objects {
            if let Some((p, cap)) = &o.slicing {
                view_slices::check_capacity(
                    *cap,
                    ctx.limits.max_storage_buffer_binding_size,
                    &o.object.name,
                    p.plane_count,
                )?;
            }
        }
        let mut baker = Baker::new(&wgsl_root());
        let baked: Vec<bake::Baked> =
            blueprint.bakes.iter().map(|b| baker.bake(ctx, &b.request)).collect::<Result<_>>()?;
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("volume_sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let mut frame = Inputs::default();
        frame
            .buffers
            .insert("frame".into(), bake::uniform(ctx, "frame", bytemuck::bytes_of(&blueprint.frame)));
        frame.samplers.insert("volume_sampler".into(), sampler);
        frame.counts.insert("width".into(), blueprint.size.0);
        frame.counts.insert("height".into(), blueprint.size.1);
        let objects = blueprint.objects.iter().map(|o| object_inputs(ctx, &blueprint, o, &baked)).collect();
        let exec = Executor::new(ctx, blueprint.graph.clone(), &blueprint.plan, blueprint.size)?;
        let timer = Timer::new(ctx, blueprint.plan.passes.len() as u32);
        let (w, h) = blueprint.size;
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("image readback"),
            size: padded_row(w) as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut r = Self { blueprint, exec, frame, objects, timer, readback };
        // Pipelines now, so that a bad kernel fails before any frame.
        r.exec.prepare(ctx, &r.blueprint.plan, &r.frame, &r.objects)?;
        ctx.wait()?;
        Ok(r)
    }

    /// Renders one frame and reads back the graph's first output as a linear HDR image.
    pub fn render(&mut self, ctx: &GpuContext) -> Result<Frame> {
        self.timer.reset();
        self.exec.run(ctx, &self.blueprint.plan, &self.frame, &self.objects, &mut self.timer)?;
        let pass_times = self.timer.read(ctx)?;
        let image = self.read_output(ctx)?;
        Ok(Frame { image, pass_times })
    }

    /// Renders without reading the image back (benchmarks); returns per-pass GPU times.
    pub fn render_timed(&mut self, ctx: &GpuContext) -> Result<Vec<(String, f64)>> {
        self.timer.reset();
        self.exec.run(ctx, &self.blueprint.plan, &self.frame, &self.objects, &mut self.timer)?;
        ctx.wait()?;
        self.timer.read(ctx)
    }

    fn read_output(&self, ctx: &GpuContext) -> Result<Image> {
        let name = &self.blueprint.graph.file.outputs[0];
        let texture =
            self.exec.texture(name).ok_or_else(|| Error::Invalid(format!("output `{name}` was pruned")))?;
        if texture.format() != wgpu::TextureFormat::Rgba32Float {
            return Err(self
                .blueprint
                .graph
                .error_at(name, format!("output `{name}` must be Rgba32Float to be read back")));
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
            let row = &bytes[y * padded_row(w) as usize..][..w as usize * 16];
            pixels.extend(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(row));
        }
        Image::from_pixels(w, h, pixels)
    }

    /// Slice polygons (triangle-list vertices per plane) of one object after the last frame.
    pub fn read_slices(&self, ctx: &GpuContext, object: usize) -> Result<Vec<Vec<SliceVertex>>> {
        let (params, _) = self.blueprint.objects[object]
            .slicing
            .ok_or_else(|| Error::Invalid("object is not sliced".into()))?;
        view_slices::read_back(ctx, &self.objects[object], params.plane_count)
    }
}

fn padded_row(w: u32) -> u32 {
    (w * 16).div_ceil(256) * 256
}

fn object_inputs(ctx: &GpuContext, bp: &Blueprint, o: &ObjectPlan, baked: &[bake::Baked]) -> Inputs {
    let mut inputs = Inputs::default();
    inputs.constants.push(("per_pixel_lighting".into(), o.per_pixel as u32 as f64));
    let opacity_length = o.bake.map(|b| bp.bakes[b].opacity_length).unwrap_or(1.0);
    let c = o.object.base_color.unwrap_or([0.0; 3]);
    let params = ObjectParams { base_color: [c[0], c[1], c[2], 1.0], opacity_length, _pad: [0.0; 3] };
    inputs.buffers.insert("object".into(), bake::uniform(ctx, "object", bytemuck::bytes_of(&params)));
    inputs.counts.insert("prisms".into(), o.shell.prisms.len() as u32);
    if let Some(base) = &o.base {
        inputs
            .buffers
            .insert("base_vertices".into(), bake::storage(ctx, "base_vertices", bytemuck::cast_slice(base)));
        inputs.counts.insert("base_vertices".into(), base.len() as u32);
    }
    if let Some((params, capacity)) = &o.slicing {
        view_slices::add_inputs(ctx, &mut inputs, &o.shell, params, *capacity, o.trivial_reject);
        if let Some(b) = o.bake {
            inputs.views.insert("volume".into(), baked[b].volume.create_view(&Default::default()));
            inputs.views.insert("normals".into(), baked[b].normals.create_view(&Default::default()));
        }
    }
    inputs
}

impl Renderer {
    /// EXR metadata: scene, methods and their quality knobs, adapter, GPU time.
    pub fn metadata(&self, ctx: &GpuContext, frame: &Frame) -> Vec<(String, String)> {
        let mut m = vec![
            ("voltex_scene".to_string(), self.blueprint.scene_path.display().to_string()),
            ("voltex_adapter".to_string(), ctx.adapter_line()),
        ];
        if let Some(t) = frame.gpu_ms() {
            m.push(("voltex_gpu_ms".into(), format!("{t:.3}")));
        }
        for o in &self.blueprint.objects {
            let method = match &o.slicing {
                Some((p, _)) => format!(
                    "ViewSlices(planes: {}, trivial_reject: {}, lighting: {})",
                    p.plane_count,
                    o.trivial_reject,
                    if o.per_pixel { "PerPixel" } else { "Baked" }
                ),
                None => "BaseSurface".into(),
            };
            m.push((format!("voltex_object_{}", o.object.name), method));
        }
        m
    }
}

/// A scene shape as the bake kernels take it: (shape, albedo, opacity).
fn bake_shape(s: &Shape) -> (BakeShape, [f32; 3], f32) {
    match s {
        Shape::Sphere { center, radius, color, opacity } => {
            (BakeShape::Sphere { center: *center, radius: *radius }, *color, *opacity)
        }
        Shape::Torus { center, major, minor, color, opacity } => {
            (BakeShape::Torus { center: *center, major: *major, minor: *minor }, *color, *opacity)
        }
        Shape::Ellipsoid { center, radii, color, opacity } => {
            (BakeShape::Ellipsoid { center: *center, radii: *radii }, *color, *opacity)
        }
        Shape::Metaballs { balls, threshold, color, opacity } => (
            BakeShape::Metaballs {
                balls: balls.iter().map(|b| (b.center, b.radius)).collect(),
                threshold: *threshold,
            },
            *color,
            *opacity,
        ),
    }
}
