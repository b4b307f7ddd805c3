//! The opaque base surface under every textured object, drawn by `base_surface/draw_base.wgsl`.

use super::{InputCx, MethodPlan, ObjectPlan, PartDecl};
use crate::gpu::bindings::counts as C;
use crate::gpu::buffers;
use crate::gpu::Inputs;
use crate::types::BaseVertex;

pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "base surface",
    filters: &["BaseSurface"],
    resources: &["base_vertices"],
    counts: &[C::BASE_VERTICES],
    texel_resources: &[],
    gather: None,
};

/// The object's base triangles, camera-relative.
pub(crate) struct BaseSurfacePlan {
    pub(crate) vertices: Vec<BaseVertex>,
}

impl MethodPlan for BaseSurfacePlan {
    fn parts(&self) -> Vec<PartDecl> {
        vec![PartDecl { filters: vec!["BaseSurface"], order: 0 }]
    }

    fn add_inputs(&self, cx: &InputCx, _object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        let bytes = bytemuck::cast_slice(&self.vertices);
        inputs.buffers.insert("base_vertices".into(), buffers::storage(cx.ctx, "base_vertices", bytes));
        inputs.counts.insert(C::BASE_VERTICES.into(), self.vertices.len() as u32);
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        "base surface only".into()
    }

    fn metadata(&self, _object: &ObjectPlan) -> String {
        "BaseSurface".into()
    }

    fn memory(&self, object: &ObjectPlan, _size: (u32, u32)) -> Vec<(String, u64)> {
        let name = &object.object.name;
        vec![(format!("object {name}: base triangles"), (self.vertices.len() * 32) as u64)]
    }

    crate::any_plan!();
}
