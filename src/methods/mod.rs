//! Host side of each method: view-aligned prism slicing, axis-aligned slices, the reference ray
//! caster, hypertexture ray marching, and the opaque base surface. Each lives in its own folder,
//! declares what it brings to the render graph ([`Contribution`]), plans objects into a
//! [`MethodPlan`], and is registered once, in [`REGISTRY`] and `plan_method`.

pub(crate) mod base_surface;
pub mod options;
pub mod plan;
pub(crate) mod plugin;
pub mod sweep;
pub(crate) mod texels;
pub mod view;
pub mod volume;

macro_rules! method_modules {
    ($($(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $name:ident $folder:ident $knobs:literal $(in $path:literal)?,)*) => {
        $($(#[cfg($cfg)])? $(#[path = $path])? pub mod $folder;)*

        /// Every method's graph contribution, the base surface's first and volumes' last.
        pub const REGISTRY: &[&Contribution] =
            &[&base_surface::CONTRIBUTION, $($(#[cfg($cfg)])? &$folder::CONTRIBUTION,)* &volume::CONTRIBUTION];
    };
}
crate::scene::methods::for_each_method!(method_modules);

pub use plan::{BakePlan, InputCx, MethodPlan, ObjectPlan, PartDecl};

use crate::error::Result;
use crate::scene::{Method, Scene};
use view::{FrameLight, View};

/// What a method brings to the render graph: the object filters its objects match (passes are
/// instanced over them), and the per-object resources and counts its inputs provide (graph files
/// bind and use them by name). The graph core checks graph files against the union of these.
pub struct Contribution {
    /// The method's name in scene files (`ViewSlices`, ...).
    pub method: &'static str,
    /// The filters passes may be instanced over for this method's objects.
    pub filters: &'static [&'static str],
    pub(crate) resources: &'static [&'static str],
    pub(crate) counts: &'static [&'static str],
    /// Resources that sample baked texels: a graph binding none of any method's bakes nothing.
    pub(crate) texel_resources: &'static [&'static str],
    /// For a method that draws all its objects in one graph instance: builds that instance's
    /// plan from the frame's objects (`None` when no object uses the method).
    pub(crate) gather: Option<Gather>,
}

/// Builds a frame-wide plan from the frame's objects, bakes and view (see [`Contribution::gather`]).
pub(crate) type Gather = fn(&mut [ObjectPlan], &[BakePlan], &View) -> Option<Box<dyn MethodPlan>>;

/// What planning an object may read, and the frame's bakes it adds to.
pub struct PlanCx<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) view: &'a View,
    pub(crate) light: &'a FrameLight,
    /// The frame's time (animated texels are baked at it).
    pub(crate) time: f64,
    pub(crate) bakes: &'a mut Vec<BakePlan>,
    /// Tile-list entries of `Tiles` compositors (`RenderOptions::tile_entries`).
    pub(crate) tile_entries: Option<u32>,
}

/// Plans `object` for the scene method `method` (knobs resolved): adds its plan to
/// `object.methods` and its bake, lighting and frames to the object.
pub(crate) fn plan_method(cx: &mut PlanCx, object: &mut ObjectPlan, method: &Method) -> Result<()> {
    if object.object.volume.is_some() {
        return volume::plan(cx, object, method);
    }
    method.plugin().plan(cx, object)
}

/// The frame-wide plans of methods that gather their objects (see [`Contribution::gather`]).
pub(crate) fn gather(
    objects: &mut [ObjectPlan],
    bakes: &[BakePlan],
    view: &View,
) -> Vec<Box<dyn MethodPlan>> {
    REGISTRY.iter().filter_map(|c| c.gather).filter_map(|g| g(objects, bakes, view)).collect()
}

/// Plans one object of the frame: its shell, its base surface if it has one, and its method
/// (`opts` may switch it or change its knobs).
pub(crate) fn plan_object(
    cx: &mut PlanCx,
    object: crate::scene::SceneObject,
    opts: &options::RenderOptions,
) -> Result<ObjectPlan> {
    let eye = cx.view.eye;
    let shell = crate::mesh::shell::Shell::prepared(&object.surface, object.prepared(), eye);
    // Kernels take camera-relative f32 corners and square their distances.
    if !shell.within(crate::mesh::prism::MAX_COORD as f32) {
        return Err(crate::error::Error::Invalid(format!(
            "{}: object `{}` lies beyond ±{:e} of the camera: move the camera closer",
            cx.scene.path.display(),
            object.name,
            crate::mesh::prism::MAX_COORD
        )));
    }
    let mut methods: Vec<Box<dyn MethodPlan>> = Vec::new();
    if object.base_color.is_some() {
        let vertices = crate::mesh::shell::base_vertices(&object.surface, eye);
        methods.push(Box::new(base_surface::BaseSurfacePlan { vertices }));
    }
    let chosen = opts.object_methods.iter().find(|(n, _)| *n == object.name).map(|(_, m)| m);
    let volume = object.volume.is_some();
    let method =
        chosen.or(object.method.as_ref()).map(|m| if volume { opts.apply_volume(m) } else { opts.apply(m) });
    let mut plan = ObjectPlan { object, shell, per_pixel: false, frames: None, bake: None, methods };
    if let Some(method) = method {
        plan_method(cx, &mut plan, &method)?;
    }
    Ok(plan)
}
