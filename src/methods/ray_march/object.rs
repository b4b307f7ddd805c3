//! One RayMarch object of a frame as the renderer sees it.

use std::any::Any;

use super::{plan, RayMarchPlan};
use crate::error::{Error, Result};
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::cache::GpuCache;
use crate::gpu::{GpuContext, Inputs};
use crate::hypertexture::mesh::MeshGrid;
use crate::hypertexture::splats::SplatSet;
use crate::methods::{InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::RayMarch;

/// Plans the march through `object`'s hypertexture.
pub(crate) fn plan_object(cx: &mut PlanCx, object: &mut ObjectPlan, m: &RayMarch) -> Result<()> {
    let name = &object.object.name;
    let node = object
        .object
        .hypertexture
        .as_ref()
        .ok_or_else(|| Error::Invalid(format!("object \"{name}\": RayMarch needs a hypertexture")))?;
    let h = cx.scene.hypertextures.get(&node.name).ok_or_else(|| {
        Error::Invalid(format!("{}: unknown hypertexture `{}`", cx.scene.path.display(), node.name))
    })?;
    let plan = plan(name, node, h, m, cx)?;
    object.methods.push(Box::new(plan));
    Ok(())
}

/// What `prepare` bakes: the mesh grid of a mesh object, the splat set of a segmented one, the
/// light volume of one with `shadows: LightVolume(..)`.
type Prepared = (Option<MeshGrid>, Option<SplatSet>, Option<wgpu::Buffer>);

impl MethodPlan for RayMarchPlan {
    /// Each pixel's `ray_march_state` counts the samples its ray evaluated.
    fn evaluations(&self, read: &mut dyn FnMut(&str) -> Result<Vec<u8>>) -> Result<Option<f64>> {
        let states: Vec<crate::types::MarchState> = bytemuck::pod_collect_to_vec(&read("ray_march_state")?);
        Ok(Some(states.iter().map(|s| s.resume[1] as f64).sum()))
    }

    fn parts(&self) -> Vec<PartDecl> {
        let filters = match (&self.peel, &self.splatting) {
            (Some(_), _) => vec!["RayMarch", "RayMarchPeeling"],
            (_, Some(_)) => vec!["RayMarch", "RayMarchSplatting"],
            _ => vec!["RayMarch"],
        };
        vec![PartDecl { filters, order: 0 }]
    }

    fn distance(&self, eye: glam::DVec3) -> Option<f64> {
        Some((self.corners.iter().sum::<glam::DVec3>() / 8.0 - eye).length())
    }

    fn constants(&self) -> Vec<(String, f64)> {
        RayMarchPlan::constants(self)
    }

    /// Mesh grids, splat sets and light volumes, baked once per mesh, grid, lattice, and light
    /// and density while the cache holds them.
    fn prepare(
        &self,
        ctx: &GpuContext,
        cache: &mut GpuCache,
        _baked: &[crate::bake::Baked],
        _bake_keys: &[u64],
    ) -> Result<Option<Box<dyn Any + Send>>> {
        let grid = match self.mesh_grid_key() {
            Some(key) => Some(cache.bake(key, || Ok(self.bake_mesh_grid(ctx)?.expect("a mesh object")))?),
            None => None,
        };
        let splats = match self.splat_key() {
            Some(key) => Some(cache.bake(key, || self.bake_splats(ctx, grid.as_ref()))?),
            None => None,
        };
        let light = match (self.light_key(), &self.light) {
            (Some(key), Some(l)) => {
                Some(cache.bake(key, || super::light_volume::bake(ctx, self, l, grid.as_ref()))?)
            }
            _ => None,
        };
        let prepared: Prepared = (grid, splats, light);
        Ok(Some(Box::new(prepared)))
    }

    fn kernels(&self) -> Vec<&'static str> {
        let grid = self.packed.grid_kernel();
        let splats = self.splat_key().map(|_| "ray_march/bake_splats.wgsl");
        grid.into_iter().chain(splats).collect()
    }

    fn add_inputs(&self, cx: &InputCx, _object: &ObjectPlan, _part: usize, inputs: &mut Inputs) {
        let prepared = cx.prepared.and_then(|p| p.downcast_ref::<Prepared>());
        let (grid, splats, light) =
            prepared.map_or((None, None, None), |(g, s, l)| (g.as_ref(), s.as_ref(), l.as_ref()));
        RayMarchPlan::add_inputs(self, cx.ctx, inputs, cx.size, grid, splats, light);
    }

    fn bake_lines(&self, object: &ObjectPlan) -> Vec<String> {
        let name = &object.object.name;
        let mut lines = Vec::new();
        if let Some((shape, spec)) = &self.packed.mesh {
            let [x, y, z] = spec.n;
            lines.push(format!(
                "{name:<16} {x}x{y}x{z}  bake_mesh_grid.wgsl  mesh grid of {} triangles in {} part(s)",
                shape.triangles.len(),
                shape.parts.len(),
            ));
        }
        if let Some(p) = &self.packed.point_set {
            let [x, y, z] = p.spec.n;
            lines.push(format!(
                "{name:<16} {x}x{y}x{z}  bake_point_grid.wgsl  point grid of {} kernels of radius {}",
                p.set.centres.len(),
                p.radius,
            ));
        }
        if let Some(l) = &self.light {
            let [x, y, z, m] = l.counts;
            lines.push(format!(
                "{name:<16} {x}x{y}x{z}  bake_light_volume.wgsl  transmittance towards the light, {m} sub-step(s) per layer"
            ));
        }
        if let Some(l) = self.lattice() {
            let [x, y, z] = l.counts;
            lines.push(format!(
                "{name:<16} {x}x{y}x{z}  bake_splats.wgsl  surface and interior splats, cell {:.4}, surface at \
                 support distance {:.4}",
                l.cell, l.level
            ));
        }
        lines
    }

    fn summary(&self, _object: &ObjectPlan) -> String {
        format!(
            "{} of hypertexture \"{}\", {} noise(s), {} dispatch(es) per frame",
            self.describe(),
            self.hypertexture,
            self.packed.noises.len(),
            self.dispatches
        )
    }

    fn metadata(&self, _object: &ObjectPlan) -> String {
        self.describe()
    }

    fn scene_method(&self, _object: &ObjectPlan) -> Option<crate::scene::Method> {
        Some(crate::scene::Method::RayMarch(self.method))
    }

    fn allocations(&self, _object: &ObjectPlan, size: (u32, u32)) -> Vec<Allocation> {
        self.per_pixel_buffers(size)
            .into_iter()
            .map(|(name, bytes)| Allocation {
                what: format!("RayMarch buffer `{name}` at {}x{}", size.0, size.1),
                bytes,
                shape: AllocationKind::Buffer { storage: true },
                driver: Driver::Output,
            })
            .collect()
    }

    fn memory(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        let what = format!(
            "object {}: hypertexture parameters, transfer tables, per-pixel march state{}",
            object.object.name,
            if self.packed.grid_key().is_some() { ", object grid" } else { "" }
        ) + if self.peel.is_some() { ", splat sets, per-pixel segment bounds" } else { "" }
            + if self.splatting.is_some() { ", splat sets, per-pixel depth slabs" } else { "" }
            + if self.light.is_some() { ", light volume" } else { "" };
        vec![(what, self.bytes(size))]
    }

    crate::any_plan!();
}
