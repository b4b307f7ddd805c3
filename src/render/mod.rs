//! From a scene to an image: a [`Blueprint`] (CPU only: objects, shells, plane sweeps, bakes and
//! the pruned graph plan, enough for `voltex plan`), then a [`Renderer`] holding the GPU resources.

mod describe;
mod renderer;
mod texels;

pub use renderer::{Frame, Renderer};

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, DVec4};

use crate::bake::BakeRequest;
use crate::error::{Error, Result};
use crate::gpu::sources::Sources;
use crate::graph::plan::{self, ObjectInfo, Plan};
use crate::graph::{Graph, Vocabulary};
use crate::mesh::shell::{self, Shell};
use crate::methods::axis_slices::AxisPlan;
use crate::methods::ray_march::{self, RayMarchPlan};
use crate::methods::reference::{self, ReferenceSet};
use crate::methods::view_slices::{self, SliceChunk};
use crate::scene::{
    AxisSlices, Camera, Light, Lighting as LightingMode, Method, RayMarch, Reference, Scene, SceneObject,
    ViewSlices,
};
use crate::types::{BaseVertex, FrameParams, ReferenceParams, SliceParams, VertexFrame};

/// Overrides of what the scene file says, from the command line or tests.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    pub size: Option<(u32, u32)>,
    pub graph: Option<PathBuf>,
    pub planes: Option<u32>,
    pub trivial_reject: Option<bool>,
    /// Render every textured object with this method (keeping its lighting mode).
    pub method: Option<MethodKind>,
    /// Ray step for `Reference` and `RayMarch` objects (world units).
    pub step: Option<f64>,
    /// Segment strategy of every `RayMarch` object (the Pareto sweep).
    pub segments: Option<crate::scene::Segments>,
    /// RayMarch objects: an adaptive stride up to this step (world units; the Pareto sweep);
    /// `Some(None)` turns it off.
    pub max_step: Option<Option<f64>>,
    /// Methods replacing those of named objects (the preview's per-object switch), before
    /// `method` and the knob overrides apply.
    pub object_methods: Vec<(String, Method)>,
    /// A camera replacing the scene's (the preview's orbit).
    pub camera: Option<Camera>,
    /// Render at `n` times the width and height and average each `n x n` block: every pixel is
    /// then the mean over its area rather than a point sample (anti-aliasing; a reference for
    /// methods that filter by the pixel footprint).
    pub supersample: Option<u32>,
    /// AxisSlices criteria `(d, p)` for every AxisSlices object: slice depth in voxels and
    /// apparent slice distance in pixels (`--criteria`, the Pareto sweep).
    pub axis_criteria: Option<(f64, f64)>,
    /// Time of the frame in seconds (animated hypertextures; default: the scene's).
    pub time: Option<f64>,
    /// AxisSlices occlusion culling for every AxisSlices object (`--occlusion-culling`).
    pub occlusion_culling: Option<bool>,
}

/// A method without its knobs, to switch every object to it (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodKind {
    ViewSlices,
    Reference,
    AxisSlices,
}

/// Axis slicing's knobs when an object is switched to it from another method.
pub const DEFAULT_AXIS_SLICES: AxisSlices = AxisSlices {
    depth: 1.0,
    pixels: 1.0,
    max_angle: 80.0,
    directions: crate::scene::SliceDirections::Three,
    blend: crate::scene::SliceBlend::Binary,
    occlusion_culling: false,
    empty_culling: true,
    draw_order: crate::scene::DrawOrder::Texels,
};

/// Plane count when an object is switched to view slicing from a method without planes.
pub const DEFAULT_PLANES: u32 = 400;

impl RenderOptions {
    /// An object's method after the overrides: switched to `method` if given, knobs replaced.
    pub fn apply(&self, method: &Method) -> Method {
        if let Method::RayMarch(rm) = method {
            // Hypertextures have no texel for other methods: only the step changes.
            let adaptive = match self.max_step {
                Some(m) => m.map(|max_step| crate::scene::Adaptive { max_step }),
                None => rm.adaptive,
            };
            return Method::RayMarch(RayMarch {
                step: self.step.or(rm.step),
                segments: self.segments.unwrap_or(rm.segments),
                adaptive,
                ..*rm
            });
        }
        let lighting = method.lighting();
        let kind = self.method.unwrap_or(match method {
            Method::ViewSlices(_) => MethodKind::ViewSlices,
            Method::Reference(_) | Method::RayMarch(_) => MethodKind::Reference,
            Method::AxisSlices(_) => MethodKind::AxisSlices,
        });
        match (kind, method) {
            (MethodKind::ViewSlices, Method::ViewSlices(vs)) => Method::ViewSlices(ViewSlices {
                planes: self.planes.unwrap_or(vs.planes),
                trivial_reject: self.trivial_reject.unwrap_or(vs.trivial_reject),
                lighting,
            }),
            (MethodKind::ViewSlices, _) => Method::ViewSlices(ViewSlices {
                planes: self.planes.unwrap_or(DEFAULT_PLANES),
                trivial_reject: self.trivial_reject.unwrap_or(true),
                lighting,
            }),
            (MethodKind::Reference, Method::Reference(r)) => {
                Method::Reference(Reference { step: self.step.or(r.step), lighting })
            }
            (MethodKind::Reference, _) => Method::Reference(Reference { step: self.step, lighting }),
            (MethodKind::AxisSlices, m) => {
                let a = if let Method::AxisSlices(a) = m { *a } else { DEFAULT_AXIS_SLICES };
                let (depth, pixels) = self.axis_criteria.unwrap_or((a.depth, a.pixels));
                let occlusion_culling = self.occlusion_culling.unwrap_or(a.occlusion_culling);
                Method::AxisSlices(AxisSlices { depth, pixels, occlusion_culling, ..a })
            }
        }
    }
}

/// One object as the frame sees it.
pub struct ObjectPlan {
    pub object: SceneObject,
    pub shell: Shell,
    pub base: Option<Vec<BaseVertex>>,
    /// View slicing: the whole sweep, and its chunks (consecutive planes with their own buffers).
    pub sweep: Option<SliceParams>,
    pub chunks: Vec<SliceChunk>,
    pub trivial_reject: bool,
    pub per_pixel: bool,
    /// Per-vertex texel frames for per-pixel lighting (only when it is on).
    pub frames: Option<Vec<VertexFrame>>,
    /// Index into `Blueprint::bakes`.
    pub bake: Option<usize>,
    /// Reference method: the ray step (world units).
    pub reference_step: Option<f64>,
    /// Axis-aligned slicing (Meyer & Neyret).
    pub axis: Option<AxisPlan>,
    /// RayMarch method: the packed hypertexture and march settings.
    pub ray_march: Option<RayMarchPlan>,
}

pub struct BakePlan {
    pub texel: String,
    pub request: BakeRequest,
    pub opacity_length: f32,
}

/// What one graph instance draws: an object's base surface, or one chunk of its slices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Part {
    Base,
    Slices(usize),
    /// All Reference objects of the frame, traced in one dispatch.
    Reference,
    /// An object's axis-aligned slices.
    AxisSlices,
    /// A hypertexture object, ray-marched into its own layer.
    RayMarch,
}

pub struct Blueprint {
    pub scene_path: PathBuf,
    /// The size rendered at (the output size times `supersample`).
    pub size: (u32, u32),
    pub supersample: u32,
    pub eye: DVec3,
    pub frame: FrameParams,
    pub objects: Vec<ObjectPlan>,
    /// Graph instances: (object index, part), in the order of `plan`'s object indices.
    pub instances: Vec<(usize, Part)>,
    pub bakes: Vec<BakePlan>,
    /// The Reference objects' BVH, shells and atlas layout (if any object uses the method).
    pub reference: Option<ReferenceSet>,
    pub graph: Graph,
    pub plan: Plan,
}

/// The bake of `texel` with the scene's first light baked in (what `voltex bake` writes out).
pub fn baked_texel(scene: &Scene, texel: &str) -> Result<BakePlan> {
    let mut bakes = Vec::new();
    texels::bake_index(scene, texel, false, &Lighting::of(scene), scene.time, &mut bakes)?;
    Ok(bakes.remove(0))
}

/// The default graph's name under `graphs/`.
pub const DEFAULT_GRAPH: &str = "frame.ron";

/// Where a render's shaders are looked up: beside the graph file `graph` (`--graph`), or beside
/// the project's `graphs/frame.ron` when that is read from disk, then in the project's sources
/// (see [`Sources`]). Reads no graph (the preview's watch list needs it when the graph is broken).
pub fn shader_sources(graph: Option<&Path>) -> Result<Sources> {
    let project = Sources::project()?;
    Ok(match graph {
        Some(path) => project.beside(path),
        None => match project.graph(DEFAULT_GRAPH)? {
            Some(g) if g.on_disk => project.beside(&g.path),
            _ => project,
        },
    })
}

/// The graph a render uses, `graph` (`--graph`) or else the project's `graphs/frame.ron` (the
/// file when present, else the embedded copy), and where its shaders are looked up.
pub fn load_graph(graph: Option<&Path>) -> Result<(Graph, Sources)> {
    let sources = shader_sources(graph)?;
    let graph = match graph {
        Some(path) => Graph::load(path)?,
        None => {
            let g = Sources::project()?.graph(DEFAULT_GRAPH)?.ok_or_else(|| {
                Error::Invalid(format!("the default graph `graphs/{DEFAULT_GRAPH}` is missing"))
            })?;
            Graph::parse(&g.path, g.text)?
        }
    };
    Ok((graph, sources))
}

impl Blueprint {
    pub fn new(scene: &Scene, opts: &RenderOptions) -> Result<Self> {
        Self::with_objects(scene, scene.objects_at(opts.time.unwrap_or(scene.time))?, opts)
    }

    /// Like [`Blueprint::new`] with the scene's objects given (tests alter their surfaces).
    pub fn with_objects(scene: &Scene, objects: Vec<SceneObject>, opts: &RenderOptions) -> Result<Self> {
        let (w, h) = opts.size.unwrap_or((scene.output.width, scene.output.height));
        let n = opts.supersample.unwrap_or(1).max(1);
        let size = (w * n, h * n);
        let mut view = View::new(scene, opts.camera.as_ref().unwrap_or(&scene.camera), &objects)?;
        // Pixels per unit of tangent, for the slice-count criterion (at the rendered size).
        view.focal = 0.5 * size.1 as f64 / (0.5 * view.fov_y.to_radians()).tan();
        view.size = size;
        let light = Lighting::of(scene);
        let mut bakes: Vec<BakePlan> = Vec::new();
        let mut objects = objects
            .into_iter()
            .map(|o| ObjectPlan::new(scene, o, &view, &light, opts, &mut bakes))
            .collect::<Result<Vec<_>>>()?;
        let (graph, sources) = load_graph(opts.graph.as_deref())?;
        let reference = reference_set(&objects, &bakes, &view);
        let (instances, infos) = instances(&objects, reference.as_ref(), view.eye);
        let plan = plan::plan(&graph, &sources, &infos, size, &vocabulary())?;
        check_bindings(&graph, &plan)?;
        let samples_texels =
            plan.passes.iter().flat_map(|p| &p.bindings).any(|b| TEXEL_BINDINGS.contains(&b.name.as_str()));
        if !samples_texels {
            // A graph that samples no texel (the slicing debug graphs) bakes nothing.
            bakes.clear();
            objects.iter_mut().for_each(|o| o.bake = None);
        }
        let frame = view.frame_params(scene, size, &light);
        Ok(Self {
            scene_path: scene.path.clone(),
            size,
            supersample: n,
            eye: view.eye,
            frame,
            objects,
            instances,
            bakes,
            reference,
            graph,
            plan,
        })
    }
}

/// The BVH and tables of the frame's Reference objects.
fn reference_set(objects: &[ObjectPlan], bakes: &[BakePlan], view: &View) -> Option<ReferenceSet> {
    let members = reference_members(objects, bakes);
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
    Some(reference::build(&members, params))
}

/// The frame's Reference objects as the Reference method sees them.
fn reference_members<'a>(objects: &'a [ObjectPlan], bakes: &[BakePlan]) -> Vec<reference::Member<'a>> {
    let member = |(index, o): (usize, &'a ObjectPlan)| {
        let step = o.reference_step?;
        let bake = o.bake.unwrap_or(0);
        Some(reference::Member {
            index,
            surface: &o.object.surface,
            shell: &o.shell,
            frames: o.frames.as_deref().filter(|_| o.per_pixel),
            opaque: o.object.base_color.is_some(),
            step,
            bake,
            resolution: bakes[bake].request.resolution,
            opacity_length: bakes[bake].opacity_length,
        })
    };
    objects.iter().enumerate().filter_map(member).collect()
}

impl Blueprint {
    /// Inputs of the Reference method's f64 twin for this frame, from the atlases the kernel read.
    pub fn reference_twin_inputs(
        &self,
        texel_atlas: &[u8],
        normal_atlas: &[u8],
    ) -> (
        crate::methods::reference::trace_reference::TraceView,
        Vec<crate::methods::reference::trace_reference::TraceObject>,
    ) {
        let set = self.reference.as_ref().expect("a frame with Reference objects");
        let members = reference_members(&self.objects, &self.bakes);
        let frame = (&self.frame, self.size, self.eye);
        reference::twin_inputs(set, &members, frame, texel_atlas, normal_atlas)
    }
}

/// The camera, with the depth range of everything drawn for the projection's near and far planes.
struct View {
    eye: DVec3,
    forward: DVec3,
    up: DVec3,
    fov_y: f64,
    near: f64,
    far: f64,
    /// Focal length in pixels (half the image height over tan(fov_y / 2)).
    focal: f64,
    /// The rendered size (for the ray casters' camera).
    size: (u32, u32),
}

impl View {
    fn new(scene: &Scene, cam: &Camera, objects: &[SceneObject]) -> Result<Self> {
        let forward = (cam.target - cam.eye).normalize_or_zero();
        if forward == DVec3::ZERO || forward.cross(cam.up).length_squared() < 1e-12 {
            return Err(Error::Invalid(format!(
                "{}: the camera's eye and target coincide, or `up` is parallel to the view direction",
                scene.path.display()
            )));
        }
        let mut far: f64 = 1e-3;
        for o in objects {
            for (&p, &h) in o.surface.positions.iter().zip(&o.surface.heights) {
                far = far.max((p - cam.eye).dot(forward)).max((p + h - cam.eye).dot(forward));
            }
            let hyper = o.hypertexture.as_ref().and_then(|n| Some((n, scene.hypertextures.get(&n.name)?)));
            if let Some((node, h)) = hyper {
                for c in h.world_corners(&node.to_world) {
                    far = far.max((c - cam.eye).dot(forward));
                }
            }
        }
        far *= 1.01;
        let near = (far * 1e-4).max(1e-6);
        Ok(Self { eye: cam.eye, forward, up: cam.up, fov_y: cam.fov_y, near, far, focal: 1.0, size: (1, 1) })
    }

    /// The camera as ray casting kernels see it: a pixel's ray is `forward + sx right + sy up`.
    fn camera(&self) -> ray_march::Camera {
        let right_dir = self.forward.cross(self.up).normalize();
        let up_dir = right_dir.cross(self.forward);
        let half = (0.5 * self.fov_y.to_radians()).tan();
        let aspect = self.size.0 as f64 / self.size.1 as f64;
        ray_march::Camera {
            eye: self.eye,
            right: right_dir * half * aspect,
            up: up_dir * half,
            near: self.near,
            far: self.far,
        }
    }

    fn forward_f32(&self) -> [f32; 3] {
        self.forward.as_vec3().to_array()
    }

    fn frame_params(&self, scene: &Scene, size: (u32, u32), light: &Lighting) -> FrameParams {
        let view = view_matrix(self.forward, self.up);
        let proj = projection(self.fov_y.to_radians(), size.0 as f64 / size.1 as f64, self.near, self.far);
        let (f, l, c, b) = (self.forward_f32(), light.direction, light.color, scene.background);
        FrameParams {
            view_proj: (proj * view).as_mat4().to_cols_array_2d(),
            forward: [f[0], f[1], f[2], self.near as f32],
            light_dir: [l[0], l[1], l[2], scene.ambient],
            light_color: [c[0], c[1], c[2], 1.0],
            background: [b[0], b[1], b[2], 1.0],
            viewport: [size.0 as f32, size.1 as f32, 1.0 / size.0 as f32, 1.0 / size.1 as f32],
        }
    }
}

/// The scene's first light (towards the light, colour times intensity) and ambient term.
pub(crate) struct Lighting {
    pub(crate) direction: [f32; 3],
    color: [f32; 3],
    pub(crate) ambient: f32,
}

impl Lighting {
    fn of(scene: &Scene) -> Self {
        let (direction, color) = match scene.lights.first() {
            Some(Light::Directional { direction, color, intensity }) => {
                (-direction.normalize(), color.map(|c| c * intensity))
            }
            None => (DVec3::new(0.3, 0.4, 1.0).normalize(), [1.0; 3]),
        };
        Self { direction: direction.as_vec3().to_array(), color, ambient: scene.ambient }
    }
}

impl ObjectPlan {
    fn new(
        scene: &Scene,
        object: SceneObject,
        view: &View,
        light: &Lighting,
        opts: &RenderOptions,
        bakes: &mut Vec<BakePlan>,
    ) -> Result<Self> {
        let shell = Shell::new(&object.surface, view.eye);
        // Kernels take camera-relative f32 corners and square their distances.
        let limit = crate::mesh::prism::MAX_COORD as f32;
        let in_range = |c: &[f32; 4]| c[..3].iter().all(|x| x.abs() <= limit);
        if !shell.vertices.iter().all(|v| in_range(&v.bottom) && in_range(&v.top)) {
            return Err(Error::Invalid(format!(
                "{}: object `{}` lies beyond ±{:e} of the camera: move the camera closer",
                scene.path.display(),
                object.name,
                crate::mesh::prism::MAX_COORD
            )));
        }
        let base = object.base_color.map(|_| shell::base_vertices(&object.surface, view.eye));
        let mut plan = ObjectPlan {
            shell,
            base,
            sweep: None,
            chunks: Vec::new(),
            trivial_reject: true,
            per_pixel: false,
            frames: None,
            bake: None,
            reference_step: None,
            axis: None,
            ray_march: None,
            object,
        };
        let name = &plan.object.name;
        let chosen = opts.object_methods.iter().find(|(n, _)| n == name).map(|(_, m)| m);
        let Some(method) = chosen.or(plan.object.method.as_ref()).map(|m| opts.apply(m)) else {
            return Ok(plan);
        };
        let time = opts.time.unwrap_or(scene.time);
        let texel = plan.object.texel.clone().unwrap_or_default();
        let vs = match method {
            Method::ViewSlices(vs) => vs,
            Method::RayMarch(rm) => {
                let node = plan.object.hypertexture.as_ref().ok_or_else(|| {
                    Error::Invalid(format!("object \"{}\": RayMarch needs a hypertexture", plan.object.name))
                })?;
                let h = scene.hypertextures.get(&node.name).ok_or_else(|| {
                    Error::Invalid(format!("{}: unknown hypertexture `{}`", scene.path.display(), node.name))
                })?;
                plan.ray_march =
                    Some(ray_march::plan(&plan.object.name, node, h, &rm, &view.camera(), time, view.size)?);
                return Ok(plan);
            }
            Method::AxisSlices(a) => {
                let bake = texels::bake_index_axis(scene, &texel, light, time, bakes)?;
                plan.bake = Some(bake);
                let res = bakes[bake].request.resolution;
                let name = &plan.object.name;
                let axis = AxisPlan::new(&plan.shell, &a, res, view.forward_f32(), view.focal, name)?;
                plan.axis = Some(axis);
                return Ok(plan);
            }
            Method::Reference(r) => {
                plan.per_pixel = r.lighting == LightingMode::PerPixel;
                plan.frames = plan.per_pixel.then(|| shell::vertex_frames(&plan.object.surface));
                let bake = texels::bake_index(scene, &texel, plan.per_pixel, light, time, bakes)?;
                plan.bake = Some(bake);
                let step = r.step.unwrap_or_else(|| {
                    reference::default_step(&plan.object.surface, bakes[bake].request.resolution)
                });
                plan.reference_step = Some(step);
                return Ok(plan);
            }
        };
        let planes = vs.planes;
        if planes == 0 || planes > crate::scene::MAX_PLANES {
            return Err(Error::Invalid(format!(
                "{planes} planes: expected a plane count in 1..={}",
                crate::scene::MAX_PLANES
            )));
        }
        plan.trivial_reject = vs.trivial_reject;
        plan.per_pixel = vs.lighting == LightingMode::PerPixel;
        let sweep = view_slices::sweep(&plan.shell, view.forward_f32(), planes, view.near);
        plan.chunks = view_slices::chunks(&plan.shell, &sweep);
        view_slices::check_budget(&plan.chunks, &plan.object.name, planes)?;
        plan.sweep = Some(sweep);
        plan.frames = plan.per_pixel.then(|| shell::vertex_frames(&plan.object.surface));
        plan.bake = Some(texels::bake_index(scene, &texel, plan.per_pixel, light, time, bakes)?);
        Ok(plan)
    }
}

/// Graph instances: each object's base surface and slice chunks, with what the planner needs to
/// know of them (filters; back to front by object, chunks in sweep order).
fn instances(
    objects: &[ObjectPlan],
    reference: Option<&ReferenceSet>,
    eye: DVec3,
) -> (Vec<(usize, Part)>, Vec<ObjectInfo>) {
    let mut instances = Vec::new();
    let mut infos = Vec::new();
    if let Some(set) = reference {
        let first = set.objects[0];
        instances.push((first, Part::Reference));
        let name = objects[first].object.name.clone();
        infos.push(ObjectInfo { name, filters: vec!["Reference"], distance: 0.0, order: 0 });
    }
    for (i, o) in objects.iter().enumerate() {
        let positions = &o.object.surface.positions;
        let centre = positions.iter().sum::<DVec3>() / positions.len().max(1) as f64;
        let distance = (centre - eye).length();
        let parts = o.base.iter().map(|_| Part::Base).chain((0..o.chunks.len()).map(Part::Slices));
        let axis = o.axis.iter().map(|_| Part::AxisSlices);
        let march = o.ray_march.as_ref().map(|m| (m.corners.iter().sum::<DVec3>() / 8.0 - eye).length());
        let distance = march.unwrap_or(distance);
        for part in parts.chain(axis).chain(march.map(|_| Part::RayMarch)) {
            let (filters, order) = match part {
                Part::Base => (vec!["BaseSurface"], 0),
                Part::Slices(c) => (vec!["ViewSlices"], c as u32),
                Part::AxisSlices => {
                    let (blended, grouped) =
                        o.axis.as_ref().map_or((false, false), |a| (a.blended, a.grouped));
                    let mut filters =
                        vec!["AxisSlices", if blended { "AxisSlicesBlended" } else { "AxisSlicesBinary" }];
                    if grouped {
                        filters.push("AxisSlicesBySlice");
                    }
                    (filters, 0)
                }
                Part::RayMarch if o.ray_march.as_ref().is_some_and(|m| m.peel.is_some()) => {
                    (vec!["RayMarch", "RayMarchPeeling"], 0)
                }
                Part::RayMarch if o.ray_march.as_ref().is_some_and(|m| m.splatting.is_some()) => {
                    (vec!["RayMarch", "RayMarchSplatting"], 0)
                }
                Part::RayMarch => (vec!["RayMarch"], 0),
                Part::Reference => unreachable!("reference instances are added once, above"),
            };
            instances.push((i, part));
            infos.push(ObjectInfo { name: o.object.name.clone(), filters, distance, order });
        }
    }
    (instances, infos)
}

/// Bindings that sample baked texels: a graph using none of them bakes nothing.
const TEXEL_BINDINGS: &[&str] =
    &["volume", "normals", "texel_atlas", "axis_slices_s", "axis_slices_t", "axis_slices_w"];

/// Resources the renderer itself binds by name: per frame, and per instance of any method.
pub const FRAME_RESOURCES: &[&str] = &["frame", "volume_sampler"];
pub const OBJECT_RESOURCES: &[&str] = &["object"];

/// Every name the runtime offers graph files: the renderer's own and those the registered
/// methods declare (`methods::REGISTRY`), each once.
pub fn vocabulary() -> Vocabulary {
    let mut v = Vocabulary {
        filters: Vec::new(),
        counts: plan::FRAME_COUNTS.to_vec(),
        resources: [FRAME_RESOURCES, OBJECT_RESOURCES].concat(),
    };
    for c in crate::methods::REGISTRY {
        v.filters.extend(c.filters);
        v.counts.extend(c.counts);
        v.resources.extend(c.resources);
    }
    for list in [&mut v.filters, &mut v.counts, &mut v.resources] {
        let mut seen = std::collections::HashSet::new();
        list.retain(|n| seen.insert(*n));
    }
    v
}

/// Every WGSL global a kept pass uses must name a graph texture or a runtime resource, so that
/// `voltex plan` reports what `render` would.
fn check_bindings(graph: &Graph, plan: &Plan) -> Result<()> {
    for p in &plan.passes {
        for b in &p.bindings {
            let known = plan.declares(&b.name) || plan.vocabulary.resources.contains(&b.name.as_str());
            if !known {
                return Err(plan::unknown_resource(graph, p.decl.name(), &b.name));
            }
        }
    }
    Ok(())
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

/// Values of the WGSL `override` constants an object's kernels are specialised with.
fn object_constants(o: &ObjectPlan) -> Vec<(String, f64)> {
    let mut c = vec![
        ("trivial_reject".into(), o.trivial_reject as u32 as f64),
        ("per_pixel_lighting".into(), o.per_pixel as u32 as f64),
    ];
    c.extend(o.ray_march.iter().flat_map(|m| m.constants()));
    c
}
