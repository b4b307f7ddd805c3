//! AxisSlices' answers about its scene-file knobs (see `methods::plugin`).

use crate::methods::plugin::{KnobEdit, MethodPlugin, Next};
use crate::scene::Method;

pub(crate) struct Plugin;
pub(crate) static PLUGIN: Plugin = Plugin;

fn knobs(m: &Method) -> &crate::scene::AxisSlices {
    match m {
        Method::AxisSlices(a) => a,
        _ => unreachable!("the AxisSlices plug-in is asked about {m:?}"),
    }
}

impl MethodPlugin for Plugin {
    fn name(&self) -> &'static str {
        "AxisSlices"
    }

    /// Both criteria `d` times looser.
    fn coarser(&self, m: &Method, d: f64) -> Method {
        let a = knobs(m);
        Method::AxisSlices(crate::scene::AxisSlices {
            depth: (a.depth * d).min(1024.0),
            pixels: a.pixels * d,
            ..*a
        })
    }

    /// Finer: see less deep inside contours (half the slice depth, so more slices).
    fn quality_step(&self, m: &Method, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        let depth = (knobs(m).depth * scale).clamp(1.0 / 64.0, 1024.0);
        vec![KnobEdit { path: &["depth"], value: depth, integer: false }]
    }

    /// The Reference at its default step.
    fn next(&self, _m: &Method) -> Next {
        Next::Method("Reference()".into())
    }
}
