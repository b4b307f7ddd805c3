//! ProbeSlices as a plug-in (see `methods::plugin`).

use super::knobs::ProbeSlices;
use crate::error::Result;
use crate::methods::options::RenderOptions;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::sweep::{SweepPoint, SweepScene, SweepValues};
use crate::methods::PlanCx;
use crate::scene::{Lighting, Method};

impl MethodPlugin for ProbeSlices {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::plan::plan(cx, object, self)
    }

    /// `--planes`.
    fn with_options(&self, o: &RenderOptions, _lighting: Lighting) -> Method {
        Method::ProbeSlices(ProbeSlices { planes: o.planes.unwrap_or(self.planes) })
    }

    fn coarser(&self, d: f64) -> Method {
        Method::ProbeSlices(ProbeSlices { planes: ((self.planes as f64 / d).round() as u32).max(1) })
    }

    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let planes = if finer { self.planes * 2 } else { (self.planes / 2).max(1) };
        vec![KnobEdit { path: &["planes"], value: planes as f64, integer: true }]
    }

    fn describe(&self) -> String {
        Method::ProbeSlices(*self).text()
    }

    fn required_knobs(&self) -> &'static [&'static str] {
        &["planes"]
    }

    fn swept_by_default(&self) -> bool {
        false
    }

    /// Each plane count of `--planes`.
    fn sweep(&self, v: &SweepValues, _scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let kind = Method::ProbeSlices(*self).kind();
        let point = |planes: u32| SweepPoint {
            knobs: format!("planes={planes}"),
            tag: planes.to_string(),
            options: RenderOptions { size: Some(v.size), method: Some(kind), planes: Some(planes), ..Default::default() },
        };
        Ok(v.planes.iter().copied().map(point).collect())
    }

    fn kpixel_ms(&self) -> f64 {
        30.0
    }
}
