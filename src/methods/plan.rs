//! What every method plans against: an object of the frame ([`ObjectPlan`]), the texel bakes the
//! frame shares ([`BakePlan`]), and the [`MethodPlan`] trait through which the renderer lays out,
//! binds, checks and describes a method's graph instances without naming the method.

use std::any::Any;

use crate::bake::{BakeRequest, Baked};
use crate::error::Result;
use crate::gpu::budget::Allocation;
use crate::gpu::cache::GpuCache;
use crate::gpu::{GpuContext, Inputs};
use crate::mesh::shell::Shell;
use crate::scene::{Method, SceneObject};
use crate::types::VertexFrame;

/// One object as the frame sees it: its shell, the texel bake and lighting its method chose,
/// and what it draws (the base surface first, then its method).
pub struct ObjectPlan {
    /// The scene object: its name, base surface (world space), texel and method.
    pub object: SceneObject,
    /// Its prisms, camera-relative.
    pub shell: Shell,
    /// Per-pixel lighting: the texel is baked as albedo + normals and lit in the kernels.
    pub(crate) per_pixel: bool,
    /// Per-vertex texel frames for per-pixel lighting (only when it is on).
    pub(crate) frames: Option<Vec<VertexFrame>>,
    /// Index into the frame's bakes.
    pub(crate) bake: Option<usize>,
    /// What the object draws, in draw order.
    pub methods: Vec<Box<dyn MethodPlan>>,
}

impl ObjectPlan {
    /// The object's plan of type `T` (a method's own type), if it has one.
    pub fn method<T: MethodPlan>(&self) -> Option<&T> {
        self.methods.iter().find_map(|m| m.as_any().downcast_ref())
    }

    /// The object's plan of type `T` to change (the preview's knobs, tests), if it has one.
    pub fn method_mut<T: MethodPlan>(&mut self) -> Option<&mut T> {
        self.methods.iter_mut().find_map(|m| m.as_any_mut().downcast_mut())
    }

    /// The scene method it is drawn with, knobs resolved (`None`: base surface only).
    pub fn scene_method(&self) -> Option<Method> {
        self.methods.iter().find_map(|m| m.scene_method(self))
    }

    /// Values of the WGSL `override` constants the object's kernels are specialised with.
    pub(crate) fn constants(&self) -> Vec<(String, f64)> {
        let mut c: Vec<(String, f64)> =
            vec![("trivial_reject".into(), 1.0), ("per_pixel_lighting".into(), self.per_pixel as u32 as f64)];
        for (name, value) in self.methods.iter().flat_map(|m| m.constants()) {
            match c.iter_mut().find(|(n, _)| *n == name) {
                Some(entry) => entry.1 = value,
                None => c.push((name, value)),
            }
        }
        c
    }
}

/// One texel bake of the frame, shared by the objects that sample it.
pub struct BakePlan {
    /// The texel's name in the scene.
    pub texel: String,
    /// What to bake.
    pub request: BakeRequest,
    /// World length over which a voxel's stored opacity is reached.
    pub opacity_length: f32,
}

/// One graph instance a method adds: the object filters it matches and its order among the
/// object's instances (passes run instances back to front by object, then by this order).
#[derive(Debug, Clone)]
pub struct PartDecl {
    pub(crate) filters: Vec<&'static str>,
    pub(crate) order: u32,
}

/// What binding a method's inputs may read: the GPU, the frame's size and bakes.
pub struct InputCx<'a> {
    pub(crate) ctx: &'a GpuContext,
    pub(crate) size: (u32, u32),
    /// The frame's texel bakes (objects find theirs by index).
    pub bakes: &'a [BakePlan],
    pub(crate) baked: &'a [Baked],
    /// What [`MethodPlan::prepare`] returned for this plan.
    pub(crate) prepared: Option<&'a (dyn Any + Send)>,
}

/// A method's plan for one object (or, for a method that draws several objects in one instance,
/// for the frame: see [`Contribution::gather`](super::Contribution)). Everything the renderer
/// does with a method goes through here.
pub trait MethodPlan: Any + Send {
    /// The graph instances this plan adds.
    fn parts(&self) -> Vec<PartDecl>;

    /// Distance from the eye by which the object is sorted, if not its surface's centre.
    fn distance(&self, _eye: glam::DVec3) -> Option<f64> {
        None
    }

    /// The ray step this plan marches, where a truth's sweep scales it (`pareto`).
    fn ray_step(&self) -> Option<f64> {
        None
    }

    /// Density evaluations of the frame just drawn (what an adaptive stride saves, whatever the
    /// machine's load), from its instance's buffers (`read` reads one by name); `None` where the
    /// method does not count them.
    fn evaluations(&self, _read: &mut dyn FnMut(&str) -> Result<Vec<u8>>) -> Result<Option<f64>> {
        Ok(None)
    }

    /// The objects a frame-wide plan draws (see `Contribution::gather`); its instance is the
    /// first one's.
    fn members(&self) -> &[usize] {
        &[]
    }

    /// Override constants of the object's kernels (replacing the defaults of the same name).
    fn constants(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// Checks against the adapter's limits before anything is allocated.
    fn check_limits(&self, _object: &ObjectPlan, _limits: &wgpu::Limits) -> Result<()> {
        Ok(())
    }

    /// GPU work done once per renderer (bakes the plan owns, what it derives from the frame's
    /// texel bakes `baked`, whose cache keys are `bake_keys`), kept in `cache` across reloads.
    fn prepare(
        &self,
        _ctx: &GpuContext,
        _cache: &mut GpuCache,
        _baked: &[crate::bake::Baked],
        _bake_keys: &[u64],
    ) -> Result<Option<Box<dyn Any + Send>>> {
        Ok(None)
    }

    /// The kernels (under `wgsl/`) that `prepare` runs outside the graph, checked by `plan`.
    fn kernels(&self) -> Vec<&'static str> {
        Vec::new()
    }

    /// Adds the buffers, views, samplers, counts and constants of instance `part` to `inputs`.
    fn add_inputs(&self, cx: &InputCx, object: &ObjectPlan, part: usize, inputs: &mut Inputs);

    /// Lines of `voltex plan`'s bakes section for what `prepare` bakes.
    fn bake_lines(&self, _object: &ObjectPlan) -> Vec<String> {
        Vec::new()
    }

    /// The object's line in `voltex plan` (the method and its knobs, resolved).
    fn summary(&self, object: &ObjectPlan) -> String;

    /// The method and knobs written into EXR metadata.
    fn metadata(&self, object: &ObjectPlan) -> String;

    /// What the plan chose from the view (a level of detail), for the render log.
    fn choices(&self, _object: &ObjectPlan) -> Option<String> {
        None
    }

    /// GPU memory the plan allocates, by item.
    fn memory(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)>;

    /// Its buffers that grow with the scene's values (per-pixel state, atlases), one by one, for
    /// the checks against the adapter's limits (`memory` is what counts against the budget).
    fn allocations(&self, _object: &ObjectPlan, _size: (u32, u32)) -> Vec<Allocation> {
        Vec::new()
    }

    /// The scene method this plan draws, knobs resolved (the preview's method switch).
    fn scene_method(&self, _object: &ObjectPlan) -> Option<Method> {
        None
    }

    /// The plan as `Any`, to downcast to its own type (see [`ObjectPlan::method`]).
    fn as_any(&self) -> &dyn Any;
    /// The plan as mutable `Any` (see [`ObjectPlan::method_mut`]).
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// Implements [`MethodPlan::as_any`] and `as_any_mut`.
#[macro_export]
macro_rules! any_plan {
    () => {
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
        fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
            self
        }
    };
}
