//! ShellMarch as a plug-in (see `methods::plugin`).

use super::knobs::{Filter, ShellMarch};
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
/// MIP biases swept with `filter: Footprint` at the knobs' own step: the `mip_bias` knob carries
/// them (and turns the filter on).
pub(crate) const SWEEP_MIP_BIASES: [f64; 3] = [-1.0, 0.0, 1.0];

impl MethodPlugin for ShellMarch {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::object::plan(cx, object, self)
    }

    /// `step_scale` (`--step-scale`, the sweep) sets the step in voxels; the `tolerance` knob the
    /// tolerance; the `mip_bias` knob the bias, with the footprint filter on.
    fn with_options(&self, o: &RenderOptions, lighting: Lighting) -> Method {
        let bias = o.knob("mip_bias");
        Method::ShellMarch(ShellMarch {
            step: o.step_scale.unwrap_or(self.step).clamp(1e-3, 16.0),
            tolerance: o.knob("tolerance").unwrap_or(self.tolerance).clamp(1e-3, 64.0),
            filter: if bias.is_some() { Filter::Footprint } else { self.filter },
            mip_bias: bias.unwrap_or(self.mip_bias).clamp(-4.0, 4.0),
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
            "ShellMarch(step: {}, tolerance: {}, min_transmittance: {}, skip_empty: {}, filter: {:?}, mip_bias: {}, \
             lighting: {:?})",
            self.step,
            self.tolerance,
            self.min_transmittance,
            self.skip_empty,
            self.filter,
            self.mip_bias,
            self.lighting
        )
    }

    /// The step in voxels over [`SWEEP_STEPS`] at the knob's tolerance, then the tolerance over
    /// [`SWEEP_TOLERANCES`] at the knob's step, then the footprint filter over
    /// [`SWEEP_MIP_BIASES`] at both; the other knobs as they are.
    fn sweep(&self, v: &SweepValues, _scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let kind = Method::ShellMarch(*self).kind();
        let point = |(step, tolerance, bias): (f64, f64, Option<f64>)| {
            let (mut knobs, mut tag) = (format!("step={step} tolerance={tolerance}"), format!("{step}"));
            if tolerance != self.tolerance {
                tag += &format!(" tol {tolerance}");
            }
            let mut named = vec![("tolerance", tolerance)];
            if let Some(b) = bias {
                knobs += &format!(" filter=footprint mip_bias={b}");
                tag += &format!(" fp {b}");
                named.push(("mip_bias", b));
            }
            let options = RenderOptions {
                size: Some(v.size),
                method: Some(kind),
                step_scale: Some(step),
                knobs: named,
                ..Default::default()
            };
            SweepPoint { knobs, tag, options }
        };
        let (step, tolerance) = (self.step, self.tolerance);
        let steps = SWEEP_STEPS.iter().map(|&s| (s, tolerance, None));
        let tolerances = SWEEP_TOLERANCES.iter().map(|&t| (step, t, None));
        let biases = SWEEP_MIP_BIASES.iter().map(|&b| (step, tolerance, Some(b)));
        Ok(unique(steps.chain(tolerances).chain(biases)).into_iter().map(point).collect())
    }

    fn kpixel_ms(&self) -> f64 {
        4.0
    }
}
