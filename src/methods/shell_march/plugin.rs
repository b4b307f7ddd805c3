//! ShellMarch as a plug-in (see `methods::plugin`).

use super::knobs::ShellMarch;
use crate::error::Result;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::sweep::{unique, SweepPoint, SweepScene, SweepValues};
use crate::methods::{options::RenderOptions, PlanCx};
use crate::scene::{Lighting, Method};

/// Steps (voxels) of the `pareto` sweep: `step_scale` carries them.
pub(crate) const SWEEP_STEPS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];
/// Tolerances (voxels) swept at the knob's own step, beside its own tolerance: the `tolerance`
/// knob (`RenderOptions::knobs`) carries them.
pub(crate) const SWEEP_TOLERANCES: [f64; 3] = [0.25, 1.0, 4.0];

impl MethodPlugin for ShellMarch {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::object::plan(cx, object, self)
    }

    /// `step_scale` (`--step-scale`, the sweep) sets the step in voxels; the `tolerance` knob the
    /// tolerance.
    fn with_options(&self, o: &RenderOptions, lighting: Lighting) -> Method {
        Method::ShellMarch(ShellMarch {
            step: o.step_scale.unwrap_or(self.step).clamp(1e-3, 16.0),
            tolerance: o.knob("tolerance").unwrap_or(self.tolerance).clamp(1e-3, 64.0),
            lighting,
            ..*self
        })
    }

    /// A step `d` times longer (at most 16 voxels; along w it stays one voxel at most).
    fn coarser(&self, d: f64) -> Method {
        Method::ShellMarch(ShellMarch { step: (self.step * d).min(16.0), ..*self })
    }

    /// Half or twice the step.
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let step = if finer { self.step * 0.5 } else { (self.step * 2.0).min(16.0) };
        vec![KnobEdit { path: &["step"], value: step, integer: false }]
    }

    fn describe(&self) -> String {
        format!(
            "ShellMarch(step: {}, tolerance: {}, min_transmittance: {}, skip_empty: {}, lighting: {:?})",
            self.step, self.tolerance, self.min_transmittance, self.skip_empty, self.lighting
        )
    }

    /// The step in voxels over [`SWEEP_STEPS`] at the knob's tolerance, then the tolerance over
    /// [`SWEEP_TOLERANCES`] at the knob's step; the other knobs as they are.
    fn sweep(&self, v: &SweepValues, _scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let kind = Method::ShellMarch(*self).kind();
        let point = |(step, tolerance): (f64, f64)| SweepPoint {
            knobs: format!("step={step} tolerance={tolerance}"),
            tag: if tolerance == self.tolerance { format!("{step}") } else { format!("{step} tol {tolerance}") },
            options: RenderOptions {
                size: Some(v.size),
                method: Some(kind),
                step_scale: Some(step),
                knobs: vec![("tolerance", tolerance)],
                ..Default::default()
            },
        };
        let steps = SWEEP_STEPS.iter().map(|&s| (s, self.tolerance));
        let tolerances = SWEEP_TOLERANCES.iter().map(|&t| (self.step, t));
        Ok(unique(steps.chain(tolerances)).into_iter().map(point).collect())
    }

    fn kpixel_ms(&self) -> f64 {
        4.0
    }
}
