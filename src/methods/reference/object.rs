//! Reference objects of a frame as the renderer sees them: each object's step, and the one
//! graph instance that traces them all ([`ReferenceSet`]).

use super::{build, default_step, twin_inputs, Member, ReferenceSet};
use crate::error::Result;
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::Inputs;
use crate::methods::reference::trace_reference::{TraceObject, TraceView};
use crate::methods::view::View;
use crate::methods::{texels, BakePlan, InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::{Lighting, Method, Reference};
use crate::types::{FrameParams, ReferenceParams};

/// One Reference object: its ray step; it is drawn by the frame's [`ReferenceSet`].
pub struct ReferencePlan {
    /// Ray step (world units).
    pub(crate) step: f64,
    /// Dispatches per frame of the set that traces it.
    pub(crate) dispatches: u32,
}

/// Plans `object`'s bake, lighting and step.
pub fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, m: &Reference) -> Result<()> {
    object.per_pixel = m.lighting == Lighting::PerPixel;
    let surface = &object.object.surface;
    let frames = object.object.prepared().frames(surface);
    object.frames = object.per_pixel.then(|| frames.to_vec());
    let texel = object.object.texel.clone().unwrap_or_default();
    let bake = texels::bake_index(cx.scene, &texel, object.per_pixel, cx.light, cx.time, cx.bakes)?;
    object.bake = Some(bake);
    let step = m.step.unwrap_or_else(|| default_step(surface, frames, cx.bakes[bake].request.resolution));
    object.methods.push(Box::new(ReferencePlan { step, dispatches: 0 }));
    Ok(())
}

/// The frame's Reference objects as the set sees them.
fn members<'a>(objects: &'a [ObjectPlan], bakes: &[BakePlan]) -> Vec<Member<'a>> {
    let member = |(index, o): (usize, &'a ObjectPlan)| {
        let step = o.method::<ReferencePlan>()?.step;
        let bake = o.bake.unwrap_or(0);
        Some(Member {
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

/// The BVH and tables of the frame's Reference objects (see `Contribution::gather`).
pub(super) fn gather(
    objects: &mut [ObjectPlan],
    bakes: &[BakePlan],
    view: &View,
) -> Option<Box<dyn MethodPlan>> {
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
    let set = build(&members, params, true);
    for o in objects.iter_mut().filter_map(|o| o.method_mut::<ReferencePlan>()) {
        o.dispatches = set.dispatches;
    }
    Some(Box::new(set))
}

/// Inputs of the f64 twin for a frame, from its objects, bakes and set and the atlases the kernel
/// read (see `twin_inputs`).
pub fn frame_twin_inputs(
    objects: &[ObjectPlan],
    bakes: &[BakePlan],
    set: &ReferenceSet,
    frame: (&FrameParams, (u32, u32), glam::DVec3),
    texel_atlas: &[u8],
    normal_atlas: &[u8],
) -> (TraceView, Vec<TraceObject>) {
    twin_inputs(set, &members(objects, bakes), frame, texel_atlas, normal_atlas)
}

fn lighting(object: &ObjectPlan) -> Lighting {
    if object.per_pixel {
        Lighting::PerPixel
    } else {
        Lighting::Baked
    }
}

impl MethodPlan for ReferencePlan {
    fn ray_step(&self) -> Option<f64> {
        Some(self.step)
    }

    fn parts(&self) -> Vec<PartDecl> {
        Vec::new()
    }

    fn add_inputs(&self, _cx: &InputCx, _object: &ObjectPlan, _part: usize, _inputs: &mut Inputs) {}

    fn summary(&self, object: &ObjectPlan) -> String {
        format!(
            "Reference step {:.6} lighting {:?}, {} dispatch(es) per frame",
            self.step,
            lighting(object),
            self.dispatches
        )
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        format!("Reference(step: {:.6}, lighting: {:?})", self.step, lighting(object))
    }

    fn memory(&self, _object: &ObjectPlan, _size: (u32, u32)) -> Vec<(String, u64)> {
        Vec::new()
    }

    fn scene_method(&self, object: &ObjectPlan) -> Option<Method> {
        Some(Method::Reference(Reference {
            step: Some(self.step),
            lighting: lighting(object),
            volume_shading: None,
        }))
    }

    crate::any_plan!();
}

impl MethodPlan for ReferenceSet {
    fn parts(&self) -> Vec<PartDecl> {
        vec![PartDecl { filters: vec!["Reference"], order: 0 }]
    }

    fn distance(&self, _eye: glam::DVec3) -> Option<f64> {
        Some(0.0)
    }

    fn members(&self) -> &[usize] {
        &self.objects
    }

    fn check_limits(&self, _object: &ObjectPlan, limits: &wgpu::Limits) -> Result<()> {
        ReferenceSet::check_limits(self, limits.max_storage_buffer_binding_size)
    }

    fn add_inputs(&self, cx: &InputCx, _object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        ReferenceSet::add_inputs(self, cx.ctx, inputs, cx.size);
        self.copy_volumes(cx.ctx, inputs, cx.baked);
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        format!(
            "Reference set of {} object(s), {} dispatch(es) per frame",
            self.objects.len(),
            self.dispatches
        )
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        self.summary(object)
    }

    fn allocations(&self, _object: &ObjectPlan, size: (u32, u32)) -> Vec<Allocation> {
        vec![Allocation {
            what: format!("the Reference per-pixel state at {}x{}", size.0, size.1),
            bytes: size.0 as u64 * size.1 as u64 * std::mem::size_of::<crate::types::ReferenceState>() as u64,
            shape: AllocationKind::Buffer { storage: true },
            driver: Driver::Output,
        }]
    }

    fn memory(&self, _object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        vec![(
            format!(
                "reference: BVH ({} nodes), {} prisms, shells, texel atlas{}, per-pixel state",
                self.nodes.len(),
                self.prisms.len(),
                if self.normal_words > 1 { " + normal atlas" } else { "" }
            ),
            (self.nodes.len() * 32
                + self.prisms.len() * 48
                + self.vertices.len() * 32
                + self.frames.len() * 32) as u64
                + (self.atlas_words + self.normal_words) * 4
                + size.0 as u64 * size.1 as u64 * 32,
        )]
    }

    crate::any_plan!();
}
