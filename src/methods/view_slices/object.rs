//! One ViewSlices object of a frame: its plane sweep in chunks, and what the renderer asks of it.

use super::{add_inputs, check_budget, check_capacity, chunks, sweep, SliceChunk};
use crate::error::{Error, Result};
use crate::gpu::{buffers, Inputs};
use crate::methods::{texels, InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::{Lighting, Method, ViewSlices, MAX_PLANES};
use crate::types::{SliceParams, SliceVertex, VertexFrame};

pub struct ViewSlicesPlan {
    /// The whole sweep, and its chunks (consecutive planes with their own buffers).
    pub sweep: SliceParams,
    pub chunks: Vec<SliceChunk>,
    pub trivial_reject: bool,
}

/// Plans `object`'s sweep, its texel bake and its lighting.
pub fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, m: &ViewSlices) -> Result<()> {
    let planes = m.planes;
    if planes == 0 || planes > MAX_PLANES {
        return Err(Error::Invalid(format!("{planes} planes: expected a plane count in 1..={MAX_PLANES}")));
    }
    object.per_pixel = m.lighting == Lighting::PerPixel;
    let sweep = sweep(&object.shell, cx.view.forward_f32(), planes, cx.view.near);
    let chunks = chunks(&object.shell, &sweep);
    check_budget(&chunks, &object.object.name, planes)?;
    object.frames = object.per_pixel.then(|| crate::mesh::shell::vertex_frames(&object.object.surface));
    let texel = object.object.texel.clone().unwrap_or_default();
    object.bake = Some(texels::bake_index(cx.scene, &texel, object.per_pixel, cx.light, cx.time, cx.bakes)?);
    object.methods.push(Box::new(ViewSlicesPlan { sweep, chunks, trivial_reject: m.trivial_reject }));
    Ok(())
}

fn lighting(object: &ObjectPlan) -> &'static str {
    if object.per_pixel {
        "PerPixel"
    } else {
        "Baked"
    }
}

impl MethodPlan for ViewSlicesPlan {
    fn parts(&self) -> Vec<PartDecl> {
        (0..self.chunks.len()).map(|c| PartDecl { filters: vec!["ViewSlices"], order: c as u32 }).collect()
    }

    fn constants(&self) -> Vec<(String, f64)> {
        vec![("trivial_reject".into(), self.trivial_reject as u32 as f64)]
    }

    fn check_limits(&self, object: &ObjectPlan, limits: &wgpu::Limits) -> Result<()> {
        let max = limits.max_storage_buffer_binding_size;
        for c in &self.chunks {
            check_capacity(c.capacity, max, &object.object.name, c.params.plane_count)?;
        }
        Ok(())
    }

    fn add_inputs(&self, cx: &InputCx, object: &ObjectPlan, part: usize, inputs: &mut Inputs) {
        let c = &self.chunks[part];
        add_inputs(cx.ctx, inputs, &object.shell, &c.params, c.capacity, self.trivial_reject);
        // Bound even when unlit per pixel (the binding exists in the kernel): one entry then.
        let frames = object.frames.as_deref().unwrap_or(&[VertexFrame { ds: [0.0; 4], dt: [0.0; 4] }]);
        let frames = buffers::storage(cx.ctx, "vertex_frames", bytemuck::cast_slice(frames));
        inputs.buffers.insert("vertex_frames".into(), frames);
        if let Some(b) = object.bake {
            inputs.views.insert("volume".into(), cx.baked[b].volume.create_view(&Default::default()));
            inputs.views.insert("normals".into(), cx.baked[b].normals.create_view(&Default::default()));
        }
    }

    fn summary(&self, object: &ObjectPlan) -> String {
        format!(
            "ViewSlices planes {} spacing {:.4} trivial_reject {} lighting {}, {} chunk(s)",
            self.sweep.plane_count,
            self.sweep.spacing,
            self.trivial_reject,
            lighting(object),
            self.chunks.len()
        )
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        format!(
            "ViewSlices(planes: {}, trivial_reject: {}, lighting: {})",
            self.sweep.plane_count,
            self.trivial_reject,
            lighting(object)
        )
    }

    fn memory(&self, object: &ObjectPlan, _size: (u32, u32)) -> Vec<(String, u64)> {
        let name = &object.object.name;
        let shell = &object.shell;
        let cap: u64 = self.chunks.iter().map(|c| c.capacity).sum();
        vec![
            (
                format!("object {name}: shell ({} prisms)", shell.prisms.len()),
                (shell.vertices.len() * 32 + shell.prisms.len() * 64) as u64,
            ),
            (
                format!(
                    "object {name}: slice vertices (capacity {cap} in {} chunk(s)) + {} plane cursors",
                    self.chunks.len(),
                    self.sweep.plane_count
                ),
                cap * std::mem::size_of::<SliceVertex>() as u64
                    + self.sweep.plane_count as u64 * 4
                    + self.chunks.len() as u64 * (16 + 48),
            ),
        ]
    }

    fn scene_method(&self, object: &ObjectPlan) -> Option<Method> {
        let lighting = if object.per_pixel { Lighting::PerPixel } else { Lighting::Baked };
        Some(Method::ViewSlices(ViewSlices {
            planes: self.sweep.plane_count,
            trivial_reject: self.trivial_reject,
            lighting,
        }))
    }

    crate::any_plan!();
}
