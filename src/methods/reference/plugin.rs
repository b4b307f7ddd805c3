//! The Reference as a plug-in (see `methods::plugin`).

use super::knobs::Reference;
use crate::error::Result;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::{options::RenderOptions, PlanCx};
use crate::scene::{Lighting, Method, Shading};
use crate::methods::sweep::{unique, SweepPoint, SweepScene, SweepValues};


impl MethodPlugin for Reference {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::plan(cx, object, self)
    }

    fn is_truth(&self) -> bool {
        true
    }

    /// `--step`.
    fn with_options(&self, o: &RenderOptions, lighting: Lighting) -> Method {
        Method::Reference(Reference { step: o.step.or(self.step), lighting, ..*self })
    }

    /// A RayMarch volume switched to the Reference (its truth) keeps its look: its shading,
    /// integrated exactly with `--step` for the shadow rays.
    fn volume_from(&self, from: &Method, o: &RenderOptions) -> Option<Method> {
        let Method::RayMarch(rm) = from else { return None };
        let lighting = if rm.shading == Shading::None { Lighting::Baked } else { Lighting::PerPixel };
        Some(Method::Reference(Reference { step: o.step, lighting, volume_shading: Some(rm.shading) }))
    }

    /// A step `d` times longer; at its default step it stays as it is.
    fn coarser(&self, d: f64) -> Method {
        Method::Reference(Reference { step: self.step.map(|s| s * d), ..*self })
    }

    /// Half or twice the step; nothing to step at the default step.
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        self.step.map(|s| KnobEdit { path: &["step"], value: s * scale, integer: false }).into_iter().collect()
    }

    fn describe(&self) -> String {
        let step = self.step.map_or("default".into(), |s| format!("{s:.5}"));
        format!("Reference(step: {step}, lighting: {:?})", self.lighting)
    }

    /// The ray step as multiples of the scene's default step (one step for all objects).
    fn sweep(&self, v: &SweepValues, scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let default_step = match &scene.truth_step {
            Ok(Some(step)) => *step,
            Ok(None) => return Err("no textured object".into()),
            Err(e) => return Err(e.clone()),
        };
        let kind = Method::Reference(*self).kind();
        let point = |f: f64| SweepPoint {
            knobs: format!("step={f}x"),
            tag: format!("{f}x"),
            options: RenderOptions {
                size: Some(v.size),
                method: Some(kind),
                step: Some(f * default_step),
                ..Default::default()
            },
        };
        Ok(unique(v.steps.iter().copied()).into_iter().map(point).collect())
    }

    /// `reference`: every object at its default step.
    fn truth(&self, arg: Option<&str>, size: (u32, u32)) -> std::result::Result<(RenderOptions, String), String> {
        if let Some(a) = arg {
            return Err(format!("`{a}`: the Reference takes no argument (its default step)"));
        }
        let options = RenderOptions { size: Some(size), method: Some(Method::Reference(*self).kind()), ..Default::default() };
        Ok((options, "Reference, default step".into()))
    }

    fn truth_form(&self) -> Option<&'static str> {
        Some("reference")
    }

    fn swept_by_default(&self) -> bool {
        true
    }

    /// The default step is half the object's smallest voxel; `0.01` is a starting point.
    fn unset_knobs(&self) -> Vec<(&'static str, String)> {
        vec![("step", "0.01".into())]
    }

    fn kpixel_ms(&self) -> f64 {
        15.0
    }
}
