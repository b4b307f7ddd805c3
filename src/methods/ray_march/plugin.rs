//! RayMarch's answers about its scene-file knobs (see `methods::plugin`).

use crate::methods::plugin::{KnobEdit, MethodPlugin, Next};
use crate::scene::{Method, Shading};

pub(crate) struct Plugin;
pub(crate) static PLUGIN: Plugin = Plugin;

fn knobs(m: &Method) -> &crate::scene::RayMarch {
    match m {
        Method::RayMarch(h) => h,
        _ => unreachable!("the RayMarch plug-in is asked about {m:?}"),
    }
}

impl MethodPlugin for Plugin {
    fn name(&self) -> &'static str {
        "RayMarch"
    }

    /// A ray step, shadow step and adaptive stride `d` times longer.
    fn coarser(&self, m: &Method, d: f64) -> Method {
        let mut h = *knobs(m);
        h.step = Some(h.step() * d);
        h.shadow_step = h.shadow_step.map(|s| s * d);
        if let Some(a) = &mut h.adaptive {
            a.max_step *= d;
        }
        Method::RayMarch(h)
    }

    /// Half or twice the step, and an adaptive stride's longest step with it (so the stride
    /// stays on).
    fn quality_step(&self, m: &Method, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        let h = knobs(m);
        let mut out = vec![KnobEdit { path: &["step"], value: h.step() * scale, integer: false }];
        if let Some(a) = h.adaptive {
            out.push(KnobEdit { path: &["adaptive", "max_step"], value: a.max_step * scale, integer: false });
        }
        out
    }

    /// The next shading: None, Phong, PhongShadows, HenyeyGreenstein.
    fn next(&self, m: &Method) -> Next {
        let shading = match knobs(m).shading {
            Shading::None => "Phong",
            Shading::Phong => "PhongShadows",
            Shading::PhongShadows => "HenyeyGreenstein(g: 0.5, shadows: true)",
            Shading::HenyeyGreenstein { .. } => "None",
        };
        Next::Knob(&["shading"], shading.into())
    }
}
