//! ViewSlices' answers about its scene-file knobs (see `methods::plugin`).

use crate::methods::plugin::{KnobEdit, MethodPlugin, Next};
use crate::scene::{Method, MAX_PLANES};

pub(crate) struct Plugin;
pub(crate) static PLUGIN: Plugin = Plugin;

fn knobs(m: &Method) -> &crate::scene::ViewSlices {
    match m {
        Method::ViewSlices(v) => v,
        _ => unreachable!("the ViewSlices plug-in is asked about {m:?}"),
    }
}

impl MethodPlugin for Plugin {
    fn name(&self) -> &'static str {
        "ViewSlices"
    }

    /// A `d`-th of the planes.
    fn coarser(&self, m: &Method, d: f64) -> Method {
        let v = knobs(m);
        Method::ViewSlices(crate::scene::ViewSlices {
            planes: ((v.planes as f64 / d).round() as u32).max(1),
            ..*v
        })
    }

    /// Twice or half the planes.
    fn quality_step(&self, m: &Method, finer: bool) -> Vec<KnobEdit> {
        let p = knobs(m).planes;
        let planes = if finer { (p * 2).min(MAX_PLANES) } else { (p / 2).max(1) };
        vec![KnobEdit { path: &["planes"], value: planes as f64, integer: true }]
    }

    /// AxisSlices at its defaults.
    fn next(&self, _m: &Method) -> Next {
        Next::Method("AxisSlices()".into())
    }
}
