//! The Reference's answers about its scene-file knobs (see `methods::plugin`).

use crate::methods::plugin::{KnobEdit, MethodPlugin, Next};
use crate::scene::Method;

pub(crate) struct Plugin;
pub(crate) static PLUGIN: Plugin = Plugin;

fn knobs(m: &Method) -> &crate::scene::Reference {
    match m {
        Method::Reference(r) => r,
        _ => unreachable!("the Reference plug-in is asked about {m:?}"),
    }
}

impl MethodPlugin for Plugin {
    fn name(&self) -> &'static str {
        "Reference"
    }

    /// A step `d` times longer; at its default step it stays as it is.
    fn coarser(&self, m: &Method, d: f64) -> Method {
        let r = knobs(m);
        Method::Reference(crate::scene::Reference { step: r.step.map(|s| s * d), ..*r })
    }

    /// Half or twice the step; nothing to step at the default step.
    fn quality_step(&self, m: &Method, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        knobs(m)
            .step
            .map(|s| KnobEdit { path: &["step"], value: s * scale, integer: false })
            .into_iter()
            .collect()
    }

    /// ViewSlices with the planes a switch gives, keeping the lighting.
    fn next(&self, m: &Method) -> Next {
        let planes = crate::methods::options::SWITCHED_PLANES;
        Next::Method(format!("ViewSlices(planes: {planes}, lighting: {:?})", knobs(m).lighting))
    }
}
