//! One AxisSlices object of a frame as the renderer sees it.

use super::slice_images::SliceImages;
use super::{add_inputs, AxisPlan};
use crate::error::Result;
use crate::gpu::Inputs;
use crate::methods::{texels, InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::{AxisSlices, Method};

/// Plans `object`'s slicing and its texel bake with slice images.
pub fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, m: &AxisSlices) -> Result<()> {
    let texel = object.object.texel.clone().unwrap_or_default();
    let bake = texels::bake_index(cx.scene, &texel, false, cx.light, cx.time, cx.bakes)?;
    // Objects drawing the same texel share its slice images, with MIP levels if any asks.
    let mipmaps = m.mipmaps;
    cx.bakes[bake].request.derive(|before: Option<&SliceImages>| SliceImages {
        mipmaps: mipmaps || before.is_some_and(|b| b.mipmaps),
    });
    object.bake = Some(bake);
    let res = cx.bakes[bake].request.resolution;
    let (forward, focal) = (cx.view.forward_f32(), cx.view.focal);
    let axis = AxisPlan::new(&object.shell, m, res, forward, focal, &object.object.name)?;
    object.methods.push(Box::new(axis));
    Ok(())
}

impl MethodPlan for AxisPlan {
    fn parts(&self) -> Vec<PartDecl> {
        let mut filters =
            vec!["AxisSlices", if self.blended { "AxisSlicesBlended" } else { "AxisSlicesBinary" }];
        if self.grouped {
            filters.push("AxisSlicesBySlice");
        }
        vec![PartDecl { filters, order: 0 }]
    }

    fn add_inputs(&self, cx: &InputCx, object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        let Some(b) = object.bake else { return };
        if let Some(axis) = cx.baked[b].derived.get::<super::slice_images::AxisBaked>() {
            add_inputs(cx.ctx, inputs, &object.shell, self, axis);
        }
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        format!("{:?}, vertex capacity {}", self.method, self.capacity)
    }

    fn metadata(&self, _object: &ObjectPlan) -> String {
        format!("{:?}", self.method)
    }

    fn memory(&self, object: &ObjectPlan, _size: (u32, u32)) -> Vec<(String, u64)> {
        let prism = std::mem::size_of::<crate::types::Prism>() as u64;
        let shell = object.shell.vertices.len() as u64 * 32 + object.shell.prisms.len() as u64 * prism;
        vec![(
            format!(
                "object {}: axis slice vertices (capacity {}) + choices",
                object.object.name, self.capacity
            ),
            self.capacity * 48 + self.prisms.len() as u64 * (32 + prism) + shell + 16,
        )]
    }

    fn scene_method(&self, _object: &ObjectPlan) -> Option<Method> {
        Some(Method::AxisSlices(self.method))
    }

    crate::any_plan!();
}
