//! AxisSlices as a plug-in (see `methods::plugin`).

use super::knobs::AxisSlices;
use crate::error::Result;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::{options::RenderOptions, PlanCx};
use crate::scene::{Lighting, Method};
use crate::methods::sweep::{SweepPoint, SweepScene, SweepValues};


impl MethodPlugin for AxisSlices {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::plan(cx, object, self)
    }

    /// `--criteria`, `--occlusion-culling` and `--mipmaps` (baked colour only: no lighting).
    fn with_options(&self, o: &RenderOptions, _lighting: Lighting) -> Method {
        let (depth, pixels) = o.axis_criteria.unwrap_or((self.depth, self.pixels));
        let occlusion_culling = o.occlusion_culling.unwrap_or(self.occlusion_culling);
        let mipmaps = o.mipmaps.unwrap_or(self.mipmaps);
        Method::AxisSlices(AxisSlices { depth, pixels, occlusion_culling, mipmaps, ..*self })
    }

    /// Both criteria `d` times looser.
    fn coarser(&self, d: f64) -> Method {
        Method::AxisSlices(AxisSlices { depth: (self.depth * d).min(1024.0), pixels: self.pixels * d, ..*self })
    }

    /// Finer: see less deep inside contours (half the slice depth, so more slices).
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        let depth = (self.depth * scale).clamp(1.0 / 64.0, 1024.0);
        vec![KnobEdit { path: &["depth"], value: depth, integer: false }]
    }

    fn describe(&self) -> String {
        format!("AxisSlices(depth: {}, pixels: {}, {:?})", self.depth, self.pixels, self.directions)
    }

    /// Both criteria `d` (voxels) and `p` (pixels) set to each value; each object keeps its
    /// other knobs (directions, blend, culling), or the defaults when it used another method.
    fn sweep(&self, v: &SweepValues, _scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let mut criteria = v.criteria.clone();
        criteria.sort_by(f64::total_cmp);
        criteria.dedup();
        let kind = Method::AxisSlices(*self).kind();
        let point = |c: f64| SweepPoint {
            knobs: format!("d=p={c}"),
            tag: format!("{c}"),
            options: RenderOptions {
                size: Some(v.size),
                method: Some(kind),
                axis_criteria: Some((c, c)),
                ..Default::default()
            },
        };
        Ok(criteria.into_iter().map(point).collect())
    }

    fn kpixel_ms(&self) -> f64 {
        90.0
    }
}
