//! Volume objects: a node drawing a grid of an OpenVDB file in its own box, with `RayMarch`
//! (samples at the middle of each step, empty leaves skipped) or `Reference` (the optical depth
//! of every voxel cell integrated exactly). Density times `density_scale` is the extinction
//! per world unit; the light scattered is `albedo` times the colour grid, shaded as
//! hypertextures are. Per object: the brick table and atlases (uploaded once, kept in the
//! cache), the camera and medium (`VolumeParams`), the per-pixel march state, and how many
//! dispatches of `march_volume.wgsl` finish every ray.

pub mod march_volume;
mod object;

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::volume as B;
use std::sync::Arc;

use glam::{DMat4, DVec3};

use crate::error::{Error, Result};
use crate::methods::view::RayCamera;
use crate::scene::{Method, Volume, VolumeNode};
use crate::types::{MarchState, VolumeParams};
use crate::vdb::SparseVolume as Grid;

pub(crate) use object::plan;

/// What volume objects bring to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "Volume",
    filters: &["Volume"],
    resources: &[B::VOLUME_PARAMS, B::VOLUME_TABLE, B::VOLUME_DENSITY, B::VOLUME_COLOR, B::VOLUME_STATE],
    counts: &[C::VOLUME_DISPATCHES],
    texel_resources: &[],
    gather: None,
};

/// Loop iterations one invocation may run per dispatch (lavapipe ends an invocation's loops
/// after 65535 iterations in all).
pub(crate) const LOOP_BUDGET: u32 = 48_000;
/// Most samples of one shadow ray (its step grows when the box is longer).
pub(crate) const MAX_SHADOW_SAMPLES: u32 = 256;
/// More dispatches than this means a step far finer than the volume needs.
pub(crate) const MAX_DISPATCHES: u32 = 20_000;

/// One volume object of a frame.
#[derive(Debug, Clone)]
pub struct VolumePlan {
    pub(crate) volume: String,
    pub(crate) grid: Arc<Grid>,
    /// The object's parameters (uniform `volume_params`).
    pub params: VolumeParams,
    /// Reference: exact optical depth per voxel cell; else RayMarch's midpoint samples.
    pub(crate) exact: bool,
    pub(crate) phong: bool,
    pub(crate) shadows: bool,
    pub(crate) step: f64,
    pub(crate) shadow_step: f64,
    pub(crate) dispatches: u32,
    /// World corners of the box outside which the density is 0.
    pub(crate) corners: [DVec3; 8],
    /// The method as resolved (the preview's switch, metadata).
    pub(crate) method: Method,
}

/// The length in world units of the shortest voxel edge of `node`'s grid.
pub(crate) fn voxel_length(node: &VolumeNode) -> f64 {
    crate::vdb::voxel_size(&(node.to_world * node.grid.index_to_world))
}

/// Whether a volume drawn with `shading` is Phong-shaded, and whether it casts shadows.
fn lit(shading: crate::scene::Shading) -> (bool, bool) {
    use crate::scene::Shading;
    (shading != Shading::None, shading == Shading::PhongShadows)
}

/// Plans the march of `node` drawn with `method` (RayMarch or Reference) from `camera`.
pub(crate) fn plan_volume(
    object: &str,
    node: &VolumeNode,
    volume: &Volume,
    method: &Method,
    camera: &RayCamera,
) -> Result<VolumePlan> {
    use crate::scene::{Lighting, Quality};
    let voxel = voxel_length(node);
    let (exact, step, shadow_step, phong, shadows) = match method {
        Method::RayMarch(rm) => {
            // A voxel a step (a quarter for HQ), unless the step is given.
            let preset = if rm.quality == Quality::High { 0.25 } else { 1.0 };
            let step = rm.step.unwrap_or(preset * voxel);
            let shadow_step = rm.shadow_step.unwrap_or(2.0 * step);
            let (phong, shadows) = lit(rm.shading);
            (false, step, shadow_step, phong, shadows)
        }
        Method::Reference(r) => {
            let step = r.step.unwrap_or(0.25 * voxel);
            let (phong, shadows) = match r.volume_shading {
                Some(shading) => lit(shading),
                None if r.lighting == Lighting::PerPixel => (true, true),
                None => (false, false),
            };
            (true, step, step, phong, shadows)
        }
        _ => {
            return Err(Error::Invalid(format!(
                "object \"{object}\": a volume is drawn with RayMarch(...) or Reference(...)"
            )))
        }
    };
    let grid = &node.grid;
    let index_to_world = node.to_world * grid.index_to_world;
    let corners = grid.world_corners(&node.to_world);
    let (lo, hi) = grid.index_bounds();
    let diagonal = crate::scene::hypertexture::diagonal(&corners);
    let index_diagonal = (hi - lo).length();
    let shadow_samples = ((diagonal / shadow_step).ceil() as u32).clamp(1, MAX_SHADOW_SAMPLES);
    let worst = 1 + exact as u32 + shadow_samples * shadows as u32;
    // Loop iterations along the longest ray: samples, empty boxes skipped (at most one per
    // sample or cell), and for Reference the voxel cells crossed.
    let samples = (diagonal / step).ceil() + 1.0;
    let iterations = if exact { 2.0 * (3.0 * index_diagonal + 4.0) + samples } else { 2.0 * samples };
    let dispatches = (iterations * worst as f64 / LOOP_BUDGET as f64).ceil() + 1.0;
    if dispatches > MAX_DISPATCHES as f64 {
        return Err(Error::Invalid(format!(
            "object \"{object}\": a step of {step} needs {dispatches} dispatches per frame across volume \"{}\" \
             (at most {MAX_DISPATCHES}): use a larger `step`",
            node.name
        )));
    }
    let to_index = (index_to_world.inverse() * DMat4::from_translation(camera.eye)).as_mat4();
    let v3 = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
    let mut params = VolumeParams {
        to_index: to_index.to_cols_array_2d(),
        right: v3(camera.right, camera.near),
        up: v3(camera.up, camera.far),
        box_lo: v3(lo, step),
        box_hi: v3(hi, shadow_step),
        medium: [volume.albedo[0], volume.albedo[1], volume.albedo[2], volume.density_scale as f32],
        budget: [LOOP_BUDGET, shadow_samples, worst, 0],
        ..Default::default()
    };
    crate::bake::volume::grid_params(grid, &mut params);
    Ok(VolumePlan {
        volume: node.name.clone(),
        grid: grid.clone(),
        params,
        exact,
        phong,
        shadows,
        step,
        shadow_step,
        dispatches: dispatches as u32,
        corners,
        method: method.clone(),
    })
}

impl VolumePlan {
    /// Values of the kernel's override constants.
    pub(crate) fn constants(&self) -> Vec<(String, f64)> {
        vec![
            ("exact".into(), self.exact as u32 as f64),
            ("phong".into(), self.phong as u32 as f64),
            ("shadows".into(), self.shadows as u32 as f64),
        ]
    }

    /// The method as written in metadata and `voltex plan`.
    pub fn describe(&self) -> String {
        let shading = match (self.phong, self.shadows) {
            (false, _) => "None",
            (true, false) => "Phong",
            (true, true) => "PhongShadows",
        };
        if self.exact {
            format!("Reference(step: {:.6}, exact cells, shading: {shading})", self.step)
        } else {
            format!(
                "RayMarch(step: {:.6}, shading: {shading}, shadow_step: {:.6})",
                self.step, self.shadow_step
            )
        }
    }

    /// Bytes of the per-pixel march state.
    pub(crate) fn state_bytes(size: (u32, u32)) -> u64 {
        size.0 as u64 * size.1 as u64 * std::mem::size_of::<MarchState>() as u64
    }

    /// The brick table's and atlases' cache key: the grid's content.
    pub(crate) fn upload_key(&self) -> u64 {
        crate::gpu::cache::key(&("volume", self.grid.hash))
    }
}
