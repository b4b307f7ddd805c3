//! One volume object of a frame as the renderer sees it.

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::volume as B;
use std::any::Any;

use super::{plan_volume, VolumePlan};
use crate::bake::volume::{atlas_size, slots, upload, Uploaded};
use crate::error::{Error, Result};
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::cache::GpuCache;
use crate::gpu::{GpuContext, Inputs};
use crate::methods::{InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::Method;

/// Plans the march through `object`'s volume with `method`.
pub fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, method: &Method) -> Result<()> {
    let name = &object.object.name;
    let node = object
        .object
        .volume
        .as_ref()
        .ok_or_else(|| Error::Invalid(format!("object \"{name}\" has no volume")))?;
    let volume = cx.scene.volumes.get(&node.name).ok_or_else(|| {
        Error::Invalid(format!("{}: unknown volume `{}`", cx.scene.path.display(), node.name))
    })?;
    let plan = plan_volume(name, node, volume, method, &cx.view.camera())?;
    object.methods.push(Box::new(plan));
    Ok(())
}

impl MethodPlan for VolumePlan {
    /// The exact cells need no step; their shadow rays do (a quarter voxel).
    fn ray_step(&self) -> Option<f64> {
        self.exact.then_some(self.step)
    }

    fn parts(&self) -> Vec<PartDecl> {
        vec![PartDecl { filters: vec!["Volume"], order: 0 }]
    }

    fn distance(&self, eye: glam::DVec3) -> Option<f64> {
        Some((self.corners.iter().sum::<glam::DVec3>() / 8.0 - eye).length())
    }

    fn constants(&self) -> Vec<(String, f64)> {
        VolumePlan::constants(self)
    }

    /// The brick table and atlases, uploaded once per grid while the cache holds them.
    fn prepare(
        &self,
        ctx: &GpuContext,
        cache: &mut GpuCache,
        _baked: &[crate::bake::Baked],
        _bake_keys: &[u64],
    ) -> Result<Option<Box<dyn Any + Send>>> {
        let uploaded = cache.bake(self.upload_key(), || Ok(upload(ctx, &self.grid)))?;
        Ok(Some(Box::new(uploaded)))
    }

    fn add_inputs(&self, cx: &InputCx, _object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        use crate::gpu::buffers::{uniform, work_buffer};
        let uploaded = cx.prepared.and_then(|p| p.downcast_ref::<Uploaded>()).cloned();
        uploaded.unwrap_or_else(|| upload(cx.ctx, &self.grid)).bind(inputs);
        inputs.buffers.insert(
            "volume_params".into(),
            uniform(cx.ctx, "volume_params", bytemuck::bytes_of(&self.params)),
        );
        let state = work_buffer(
            cx.ctx,
            "volume_state",
            VolumePlan::state_bytes(cx.size),
            wgpu::BufferUsages::empty(),
        );
        inputs.buffers.insert(B::VOLUME_STATE.into(), state);
        inputs.counts.insert(C::VOLUME_DISPATCHES.into(), self.dispatches);
        inputs.constants.extend(self.constants());
    }

    fn bake_lines(&self, object: &ObjectPlan) -> Vec<String> {
        let g = &self.grid;
        let [x, y, z] = atlas_size(slots(&self.grid));
        vec![format!(
            "{:<16} {x}x{y}x{z}  upload  volume \"{}\": {} bricks of 9^3 for {} leaves, table of {} top cells{}",
            object.object.name,
            self.volume,
            g.bricks(),
            g.leaves,
            g.top.x * g.top.y * g.top.z,
            if g.color.is_some() { ", colour atlas" } else { "" }
        )]
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        format!(
            "{} of volume \"{}\", {} dispatch(es) per frame",
            self.describe(),
            self.volume,
            self.dispatches
        )
    }

    fn metadata(&self, _object: &ObjectPlan) -> String {
        self.describe()
    }

    fn allocations(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<Allocation> {
        let name = &object.object.name;
        let driver = Driver::Object(name.clone());
        let atlas = atlas_size(slots(&self.grid));
        let texels = atlas.iter().map(|&s| s as u64).product::<u64>();
        let mut out = vec![
            Allocation {
                what: format!("the brick table of volume \"{}\"", self.volume),
                bytes: self.grid.table.len() as u64 * 4,
                shape: AllocationKind::Buffer { storage: true },
                driver: driver.clone(),
            },
            Allocation {
                what: format!(
                    "the density atlas of volume \"{}\" ({} bricks)",
                    self.volume,
                    self.grid.bricks()
                ),
                bytes: texels * 4,
                shape: AllocationKind::Texture3d { size: atlas },
                driver: driver.clone(),
            },
            Allocation {
                what: format!("the volume march state at {}x{}", size.0, size.1),
                bytes: VolumePlan::state_bytes(size),
                shape: AllocationKind::Buffer { storage: true },
                driver: Driver::Output,
            },
        ];
        if self.grid.color.is_some() {
            out.push(Allocation {
                what: format!("the colour atlas of volume \"{}\"", self.volume),
                bytes: texels * 8,
                shape: AllocationKind::Texture3d { size: atlas },
                driver,
            });
        }
        out
    }

    fn memory(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        let bytes: u64 = self.allocations(object, size).iter().map(|a| a.bytes).sum();
        vec![(
            format!(
                "object {}: volume \"{}\": brick table, density atlas{}, per-pixel march state",
                object.object.name,
                self.volume,
                if self.grid.color.is_some() { ", colour atlas" } else { "" }
            ),
            bytes + std::mem::size_of::<crate::types::VolumeParams>() as u64,
        )]
    }

    fn scene_method(&self, _object: &ObjectPlan) -> Option<Method> {
        Some(self.method.clone())
    }

    crate::any_plan!();
}
