//! ProbeSlices' plan: view slicing's, reported under its own name.

use super::knobs::ProbeSlices;
use crate::error::Result;
use crate::gpu::cache::GpuCache;
use crate::gpu::{GpuContext, Inputs};
use crate::gpu::budget::Allocation;
use crate::methods::plan::{InputCx, MethodPlan, ObjectPlan, PartDecl};
use crate::scene::methods::view_slices::ViewSlices;
use crate::methods::PlanCx;
use crate::scene::Method;

/// View slicing's plan of the object, with the knobs it was asked for.
struct ProbePlan {
    knobs: ProbeSlices,
    inner: Box<dyn MethodPlan>,
}

/// Plans the object as view slicing with `planes` planes, then wraps that plan.
pub(super) fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, knobs: &ProbeSlices) -> Result<()> {
    let slices = ViewSlices { planes: knobs.planes, ..Default::default() };
    crate::methods::view_slices::plan(cx, object, &slices)?;
    let inner = object.methods.pop().expect("view slicing added its plan");
    object.methods.push(Box::new(ProbePlan { knobs: *knobs, inner }));
    Ok(())
}

impl MethodPlan for ProbePlan {
    fn parts(&self) -> Vec<PartDecl> {
        self.inner.parts()
    }
    fn distance(&self, eye: glam::DVec3) -> Option<f64> {
        self.inner.distance(eye)
    }
    fn ray_step(&self) -> Option<f64> {
        self.inner.ray_step()
    }
    fn choices(&self, object: &ObjectPlan) -> Option<String> {
        self.inner.choices(object)
    }
    fn constants(&self) -> Vec<(String, f64)> {
        self.inner.constants()
    }
    fn check_limits(&self, object: &ObjectPlan, limits: &wgpu::Limits) -> Result<()> {
        self.inner.check_limits(object, limits)
    }
    fn prepare(
        &self,
        ctx: &GpuContext,
        cache: &mut GpuCache,
        baked: &[crate::bake::Baked],
        bake_keys: &[u64],
    ) -> Result<Option<Box<dyn std::any::Any + Send>>> {
        self.inner.prepare(ctx, cache, baked, bake_keys)
    }
    fn kernels(&self) -> Vec<&'static str> {
        self.inner.kernels()
    }
    fn add_inputs(&self, cx: &InputCx, object: &ObjectPlan, part: usize, inputs: &mut Inputs) {
        self.inner.add_inputs(cx, object, part, inputs)
    }
    fn bake_lines(&self, object: &ObjectPlan) -> Vec<String> {
        self.inner.bake_lines(object)
    }
    fn summary(&self, object: &ObjectPlan) -> String {
        format!("ProbeSlices ({})", self.inner.summary(object))
    }
    fn metadata(&self, _object: &ObjectPlan) -> String {
        Method::ProbeSlices(self.knobs).text()
    }
    fn memory(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        self.inner.memory(object, size)
    }
    fn allocations(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<Allocation> {
        self.inner.allocations(object, size)
    }
    fn scene_method(&self, _object: &ObjectPlan) -> Option<Method> {
        Some(Method::ProbeSlices(self.knobs))
    }
    /// View slicing's plan, so what looks for it finds it.
    fn as_any(&self) -> &dyn std::any::Any {
        self.inner.as_any()
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self.inner.as_any_mut()
    }
}
