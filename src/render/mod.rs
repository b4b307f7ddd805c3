//! From a scene to an image: a [`Blueprint`] (CPU only: objects, shells, plane sweeps, bakes and
//! the pruned graph plan, enough for `voltex plan`), then a [`Renderer`] holding the GPU resources.

pub(crate) mod aov;
mod budget;
mod describe;
pub mod export;
mod renderer;
pub mod trace;

pub(crate) use budget::Positions;

pub use crate::methods::options::RenderOptions;
pub use crate::methods::plugin::MethodKind;
pub use crate::methods::{BakePlan, ObjectPlan};
pub use renderer::{bake_key, Frame, Renderer};

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::error::{Error, Result};
use crate::gpu::sources::Sources;
use crate::graph::exec::STEP_ORIGIN;
use crate::graph::plan::{self, ObjectInfo, Plan};
use crate::graph::{Graph, Vocabulary};
use crate::methods::view::{FrameLight, View};
use crate::methods::{MethodPlan, PlanCx, REGISTRY};
use crate::scene::{Scene, SceneObject};
use crate::types::FrameParams;

/// One graph instance: part `part` of a plan (an object's, or a frame-wide one), with the
/// object it is bound as (its `object` uniform) and the filters it matches.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// Index of the object in `objects`, bound as its `object` uniform.
    pub object: usize,
    pub(crate) owner: Owner,
    pub(crate) part: usize,
    /// The filters it matches (which per-object passes run for it).
    pub filters: Vec<&'static str>,
}

/// Whose plan an instance draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    /// `objects[instance.object].methods[i]`.
    Object(usize),
    /// `groups[i]`, a method drawing several objects at once.
    Group(usize),
}

/// A scene planned for rendering, before any GPU resource: its objects, bakes and graph plan.
pub struct Blueprint {
    pub(crate) scene_path: PathBuf,
    /// The size rendered at (the output size times `supersample`).
    pub size: (u32, u32),
    pub(crate) supersample: u32,
    /// The camera's position, world space; positions reach the kernels relative to it.
    pub eye: DVec3,
    /// The per-frame uniform `frame`.
    pub frame: FrameParams,
    /// The scene's objects, each with its method plans.
    pub objects: Vec<ObjectPlan>,
    /// Frame-wide plans of methods that draw several objects in one instance.
    pub(crate) groups: Vec<Box<dyn MethodPlan>>,
    /// Graph instances, in the order of `plan`'s object indices.
    pub instances: Vec<Instance>,
    /// The texel bakes the objects share.
    pub bakes: Vec<BakePlan>,
    pub(crate) graph: Graph,
    /// The graph planned for this scene.
    pub plan: Plan,
    /// GPU memory the frame may allocate (`RenderOptions::budget` or the default).
    pub(crate) budget: u64,
    /// Where the values that size the allocations are written, for the limit checks' errors.
    pub(crate) positions: Positions,
    /// The AOVs this render writes beside the colour (`--aov`, the scene's `aovs`).
    pub aovs: Vec<aov::PlannedAov>,
    /// The camera rendered through, and the frame's time (seconds): the EXR says so.
    pub(crate) view: View,
    pub(crate) time: f64,
}

/// The bake of `texel` with the scene's first light baked in (what `voltex bake` writes out).
pub fn baked_texel(scene: &Scene, texel: &str) -> Result<BakePlan> {
    let mut bakes = Vec::new();
    crate::methods::texels::bake_index(scene, texel, false, &FrameLight::of(scene), scene.time, &mut bakes)?;
    Ok(bakes.remove(0))
}

/// The default graph's name under `graphs/`.
pub(crate) const DEFAULT_GRAPH: &str = "frame.ron";

/// Where a render's shaders are looked up: beside the graph file `graph` (`--graph`), or beside
/// the project's `graphs/frame.ron` when that is read from disk, then in the project's sources
/// (see [`Sources`]). Reads no graph (the preview's watch list needs it when the graph is broken).
pub(crate) fn shader_sources(graph: Option<&Path>) -> Result<Sources> {
    let project = Sources::project()?;
    Ok(match graph {
        Some(path) => project.beside(path),
        None => match project.graph_path(DEFAULT_GRAPH) {
            Some(path) => project.beside(&path),
            None => project,
        },
    })
}

/// The graph a render uses, `graph` (`--graph`) or else the project's `graphs/frame.ron` (the
/// file when present, else the embedded copy), and where its shaders are looked up. Loaded once
/// per process while the graph file keeps its modification time and length (a `stat`, no read):
/// planning an unchanged scene again opens no graph file.
pub(crate) fn load_graph(graph: Option<&Path>) -> Result<(Graph, Sources)> {
    type Stamp = Option<(std::time::SystemTime, u64)>;
    type Loaded = (Option<PathBuf>, Stamp, Graph, Sources);
    static GRAPHS: std::sync::Mutex<Vec<Loaded>> = std::sync::Mutex::new(Vec::new());
    let file = match graph {
        Some(path) => Some(path.to_path_buf()),
        None => Sources::project()?.graph_path(DEFAULT_GRAPH),
    };
    let stamp = |f: &Option<PathBuf>| -> Stamp {
        let m = std::fs::symlink_metadata(f.as_ref()?).ok()?;
        Some((m.modified().unwrap_or(std::time::UNIX_EPOCH), m.len()))
    };
    let key = graph.map(Path::to_path_buf);
    let now = stamp(&file);
    let mut cache = GRAPHS.lock().unwrap();
    if let Some((_, _, g, s)) = cache.iter().find(|(k, st, ..)| *k == key && *st == now && now.is_some()) {
        return Ok((g.clone(), s.clone()));
    }
    let sources = shader_sources(graph)?;
    let loaded = match graph {
        Some(path) => Graph::load(path)?,
        None => {
            let g = Sources::project()?.graph(DEFAULT_GRAPH)?.ok_or_else(|| {
                Error::Invalid(format!("the default graph `graphs/{DEFAULT_GRAPH}` is missing"))
            })?;
            Graph::parse(&g.path, g.text)?
        }
    };
    cache.retain(|(k, ..)| *k != key);
    cache.push((key, now, loaded.clone(), sources.clone()));
    Ok((loaded, sources))
}

impl Blueprint {
    /// Plans `scene` with the overrides `opts` at the scene's time (or `opts.time`).
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
        let light = FrameLight::of(scene);
        let mut bakes: Vec<BakePlan> = Vec::new();
        let time = opts.time.unwrap_or(scene.time);
        let mut cx = PlanCx {
            scene,
            view: &view,
            light: &light,
            time,
            bakes: &mut bakes,
            tile_entries: opts.tile_entries,
        };
        let positions = Positions::of(scene, opts.size.is_some());
        let mut objects = objects
            .into_iter()
            .map(|o| {
                let name = o.name.clone();
                crate::methods::plan_object(&mut cx, o, opts).map_err(|e| positions.at_object(&name, e))
            })
            .collect::<Result<Vec<_>>>()?;
        let (mut graph, sources) = load_graph(opts.graph.as_deref())?;
        let names: Vec<&str> = objects.iter().map(|o| o.object.name.as_str()).collect();
        let requested = match &opts.aovs {
            Some(names) => aov::Requested { names, at: None },
            None => aov::Requested { names: &scene.aovs, at: scene.locations.aovs.clone() },
        };
        let aovs = aov::plan(&mut graph, requested, &names)?;
        let groups = crate::methods::gather(&mut objects, &bakes, &view);
        aov::check_groups(&aovs, &graph, &groups, &objects)?;
        let (instances, infos) = instances(&objects, &groups, view.eye);
        let plan = plan::plan(&graph, &sources, &infos, size, &vocabulary())?;
        plan::check_image_output(&graph, size)?;
        check_bindings(&graph, &plan)?;
        let texel_resources: Vec<&str> = REGISTRY.iter().flat_map(|c| c.texel_resources).copied().collect();
        let samples_texels =
            plan.passes.iter().flat_map(|p| &p.bindings).any(|b| texel_resources.contains(&b.name.as_str()));
        if !samples_texels {
            // A graph that samples no texel (the slicing debug graphs) bakes nothing.
            bakes.clear();
            objects.iter_mut().for_each(|o| o.bake = None);
        }
        check_kernels(&bakes, &objects, &groups)?;
        let frame = view.frame_params(scene, size, &light);
        Ok(Self {
            scene_path: scene.path.clone(),
            size,
            supersample: n,
            eye: view.eye,
            frame,
            objects,
            groups,
            instances,
            bakes,
            graph,
            plan,
            budget: opts.budget.unwrap_or(crate::gpu::budget::DEFAULT_BUDGET),
            positions,
            aovs,
            view,
            time,
        })
    }
}

impl Blueprint {
    /// The plan instance `i` draws.
    pub(crate) fn plan_of(&self, i: &Instance) -> &dyn MethodPlan {
        match i.owner {
            Owner::Object(m) => self.objects[i.object].methods[m].as_ref(),
            Owner::Group(g) => self.groups[g].as_ref(),
        }
    }

    /// The first graph instance matching object filter `filter`.
    pub fn find_instance(&self, filter: &str) -> Option<usize> {
        self.instances.iter().position(|i| i.filters.contains(&filter))
    }

    /// The frame-wide plan of type `T` (a method's own), if the frame has one.
    pub fn group<T: MethodPlan>(&self) -> Option<&T> {
        self.groups.iter().find_map(|g| g.as_any().downcast_ref())
    }
}

/// Graph instances: the frame-wide plans', then each object's plans' parts, with what the
/// planner needs to know of them (back to front by object, then by each part's order).
fn instances(
    objects: &[ObjectPlan],
    groups: &[Box<dyn MethodPlan>],
    eye: DVec3,
) -> (Vec<Instance>, Vec<ObjectInfo>) {
    let mut instances = Vec::new();
    let mut infos = Vec::new();
    let mut add = |object: usize, owner: Owner, plan: &dyn MethodPlan, distance: f64| {
        for (part, decl) in plan.parts().into_iter().enumerate() {
            let name = objects[object].object.name.clone();
            infos.push(ObjectInfo { name, filters: decl.filters.clone(), distance, order: decl.order });
            instances.push(Instance { object, owner, part, filters: decl.filters });
        }
    };
    for (g, plan) in groups.iter().enumerate() {
        let Some(&first) = plan.members().first() else { continue };
        add(first, Owner::Group(g), plan.as_ref(), plan.distance(eye).unwrap_or(0.0));
    }
    for (i, o) in objects.iter().enumerate() {
        let positions = &o.object.surface.positions;
        let centre = positions.iter().sum::<DVec3>() / positions.len().max(1) as f64;
        let distance = o.methods.iter().find_map(|m| m.distance(eye)).unwrap_or((centre - eye).length());
        for (m, plan) in o.methods.iter().enumerate() {
            add(i, Owner::Object(m), plan.as_ref(), distance);
        }
    }
    (instances, infos)
}

/// Loads and validates the kernels the frame runs outside its graph (bakes, and what methods
/// prepare), so that a broken or unreadable one (a FIFO `#include`d, say) is a `plan` error at
/// its line rather than a failure after other GPU work.
fn check_kernels(bakes: &[BakePlan], objects: &[ObjectPlan], groups: &[Box<dyn MethodPlan>]) -> Result<()> {
    let mut kernels: Vec<&str> = bakes.iter().flat_map(|b| b.request.kernels()).collect();
    let plans = objects.iter().flat_map(|o| o.methods.iter()).chain(groups);
    kernels.extend(plans.flat_map(|p| p.kernels()));
    kernels.sort_unstable();
    kernels.dedup();
    let sources = Sources::project()?;
    for k in kernels {
        crate::gpu::shader::load_shared(&sources, k)?;
    }
    Ok(())
}

/// Resources the renderer itself binds by name: per frame, and per instance of any method.
pub(crate) const FRAME_RESOURCES: &[&str] = &["frame", "volume_sampler", STEP_ORIGIN];
pub(crate) const OBJECT_RESOURCES: &[&str] = &["object"];

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
