//! ViewSlices as a plug-in (see `methods::plugin`).

use super::knobs::{Lod, ViewSlices, MAX_PLANES};
use crate::error::Result;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::{options::RenderOptions, PlanCx};
use crate::scene::{Lighting, Method};
use crate::methods::sweep::{unique, SweepPoint, SweepScene, SweepValues};


impl MethodPlugin for ViewSlices {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::plan(cx, object, self)
    }

    /// `--planes`, `--trivial-reject`, `--compositor` and `--lod`.
    fn with_options(&self, o: &RenderOptions, lighting: Lighting) -> Method {
        Method::ViewSlices(ViewSlices {
            planes: o.planes.unwrap_or(self.planes),
            trivial_reject: o.trivial_reject.unwrap_or(self.trivial_reject),
            lighting,
            compositor: o.compositor.unwrap_or(self.compositor),
            lod: o.lod.unwrap_or(self.lod),
        })
    }

    /// A `d`-th of the planes.
    fn coarser(&self, d: f64) -> Method {
        Method::ViewSlices(ViewSlices { planes: ((self.planes as f64 / d).round() as u32).max(1), ..*self })
    }

    /// Twice or half the planes.
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let p = self.planes;
        let planes = if finer { (p * 2).min(MAX_PLANES) } else { (p / 2).max(1) };
        vec![KnobEdit { path: &["planes"], value: planes as f64, integer: true }]
    }

    fn describe(&self) -> String {
        format!("ViewSlices(planes: {}, lighting: {:?})", self.planes, self.lighting)
    }

    /// Each plane count with the trivial reject on and off (a speed knob only), at full
    /// detail; with `lod`, also `lod: Auto` under each count.
    fn sweep(&self, v: &SweepValues, _scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        let point = |planes: u32, reject: bool, lod: Lod, knobs: String, tag: String| SweepPoint {
            knobs,
            tag,
            options: RenderOptions {
                size: Some(v.size),
                method: Some(Method::ViewSlices(*self).kind()),
                planes: Some(planes),
                trivial_reject: Some(reject),
                lod: Some(lod),
                ..Default::default()
            },
        };
        let mut out = Vec::new();
        for planes in unique(v.planes.iter().copied()) {
            for reject in [true, false] {
                let knobs = format!("planes={planes} reject={}", if reject { "on" } else { "off" });
                let tag = if reject { planes.to_string() } else { format!("{planes} no-reject") };
                out.push(point(planes, reject, Lod::Off, knobs, tag));
            }
            if v.lod {
                let knobs = format!("planes={planes} reject=on lod=auto");
                out.push(point(planes, true, Lod::Auto, knobs, format!("{planes} lod")));
            }
        }
        Ok(out)
    }

    /// `view-slices:PLANES`: a converged slicing (trivial reject on, no LOD).
    fn truth(&self, arg: Option<&str>, size: (u32, u32)) -> std::result::Result<(RenderOptions, String), String> {
        let n = arg.ok_or("expected a plane count: view-slices:PLANES")?;
        match n.parse::<u32>() {
            Ok(n) if (1..=MAX_PLANES).contains(&n) => Ok((
                RenderOptions {
                    size: Some(size),
                    method: Some(Method::ViewSlices(*self).kind()),
                    planes: Some(n),
                    trivial_reject: Some(true),
                    lod: Some(Lod::Off),
                    ..Default::default()
                },
                format!("ViewSlices, {n} planes"),
            )),
            _ => Err(format!("`{n}`: expected a plane count in 1..={MAX_PLANES}")),
        }
    }

    fn truth_form(&self) -> Option<&'static str> {
        Some("view-slices:PLANES")
    }

    fn swept_by_default(&self) -> bool {
        true
    }

    fn required_knobs(&self) -> &'static [&'static str] {
        &["planes"]
    }

    fn kpixel_ms(&self) -> f64 {
        45.0
    }
}
