//! From a scene to an image: a [`Blueprint`] (CPU only: objects, shells, plane sweeps, bakes and
//! the pruned graph plan, enough for `voltex plan`), then a [`Renderer`] holding the GPU resources.

mod describe;
mod renderer;
mod texels;

pub use renderer::{Frame, Renderer};

use std::path::PathBuf;

use glam::{DMat4, DVec3, DVec4};

use crate::bake::BakeRequest;
use crate::error::{Error, Result};
use crate::graph::plan::{self, ObjectInfo, Plan};
use crate::graph::Graph;
use crate::methods::shell::{self, Shell};
use crate::methods::view_slices::{self, SliceChunk};
use crate::scene::{Light, Lighting, Method, Scene, SceneObject};
use crate::types::{BaseVertex, FrameParams, SliceParams, VertexFrame};

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
    /// View slicing: the whole sweep, and its chunks (consecutive planes with their own buffers).
    pub sweep: Option<SliceParams>,
    pub chunks: Vec<SliceChunk>,
    pub trivial_reject: bool,
    pub per_pixel: bool,
    /// Per-vertex texel frames for per-pixel lighting (only when it is on).
    pub frames: Option<Vec<VertexFrame>>,
    /// Index into `Blueprint::bakes`.
    pub bake: Option<usize>,
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
}

pub struct Blueprint {
    pub scene_path: PathBuf,
    pub size: (u32, u32),
    pub eye: DVec3,
    pub frame: FrameParams,
    pub objects: Vec<ObjectPlan>,
    /// Graph instances: (object index, part), in the order of `plan`'s object indices.
    pub instances: Vec<(usize, Part)>,
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
            let (mut sweep, mut chunks, mut trivial_reject, mut per_pixel, mut bake) =
                (None, Vec::new(), true, false, None);
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
                let params = view_slices::sweep(&shell, f32v(forward), planes, near);
                chunks = view_slices::chunks(&shell, &params);
                view_slices::check_budget(&chunks, &object.name, planes)?;
                sweep = Some(params);
                let texel_name = object.texel.clone().unwrap_or_default();
                bake = Some(texels::bake_index(scene, &texel_name, per_pixel, &mut bakes)?);
            }
            let frames = per_pixel.then(|| shell::vertex_frames(&object.surface));
            plans.push(ObjectPlan {
                object,
                shell,
                base,
                sweep,
                chunks,
                trivial_reject,
                per_pixel,
                frames,
                bake,
            });
        }

        let graph = Graph::load(opts.graph.as_deref().unwrap_or(&default_graph()))?;
        // Instances: base surfaces and slice chunks; back to front by object, chunks in order.
        let mut instances = Vec::new();
        let mut infos = Vec::new();
        for (i, o) in plans.iter().enumerate() {
            let positions = &o.object.surface.positions;
            let centre = positions.iter().sum::<DVec3>() / positions.len().max(1) as f64;
            let distance = (centre - eye).length();
            let parts = o.base.iter().map(|_| Part::Base).chain((0..o.chunks.len()).map(Part::Slices));
            for part in parts {
                let filter = if part == Part::Base { "BaseSurface" } else { "ViewSlices" };
                let order = match part {
                    Part::Base => 0,
                    Part::Slices(c) => c as u32,
                };
                instances.push((i, part));
                infos.push(ObjectInfo {
                    name: o.object.name.clone(),
                    filters: vec![filter],
                    distance,
                    order,
                });
            }
        }
        let plan = plan::plan(&graph, &wgsl_root(), &infos)?;
        check_bindings(&graph, &plan)?;

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
        Ok(Self {
            scene_path: scene.path.clone(),
            size,
            eye,
            frame,
            objects: plans,
            instances,
            bakes,
            graph,
            plan,
        })
    }
}

/// Resources the runtime binds by name: per frame, and per instance (an object's base surface or
/// one chunk of its slices).
pub const FRAME_RESOURCES: &[&str] = &["frame", "volume_sampler"];
pub const INSTANCE_RESOURCES: &[&str] = &[
    "object",
    "base_vertices",
    "slice_params",
    "shell_vertices",
    "prisms",
    "plane_cursors",
    "draw_args",
    "slice_vertices",
    "volume",
    "normals",
    "vertex_frames",
];

/// Every WGSL global a kept pass uses must name a graph texture or a runtime resource, so that
/// `voltex plan` reports what `render` would.
fn check_bindings(graph: &Graph, plan: &Plan) -> Result<()> {
    for p in &plan.passes {
        for b in &p.bindings {
            let known = plan.textures.contains_key(&b.name)
                || FRAME_RESOURCES.contains(&b.name.as_str())
                || INSTANCE_RESOURCES.contains(&b.name.as_str());
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
    vec![
        ("trivial_reject".into(), o.trivial_reject as u32 as f64),
        ("per_pixel_lighting".into(), o.per_pixel as u32 as f64),
    ]
}
