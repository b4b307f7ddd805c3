//! A method as a plug-in: what voltex does with a scene method beyond planning it, answered by
//! the method's own folder (`<method>/plugin.rs`) and found through [`Method::plugin`], the one
//! place besides the scene-file enum that lists the methods. (Planning and the graph
//! contribution are registered in `methods::REGISTRY` and `plan_method`.)

use crate::scene::Method;

/// What a method answers about its scene-file knobs.
pub(crate) trait MethodPlugin: Sync {
    /// The method's name in scene files (`ViewSlices`, ...).
    fn name(&self) -> &'static str;

    /// The method `d` times coarser (`d` >= 1): the preview's drafts while a drag goes on.
    fn coarser(&self, m: &Method, d: f64) -> Method;

    /// The preview's `+` (finer) and `-`: the knobs to write; empty where the method has no
    /// knob to step.
    fn quality_step(&self, m: &Method, finer: bool) -> Vec<KnobEdit>;

    /// The preview's `M`: the method to switch to, as scene-file text, or the knobs to write to
    /// switch the method's own mode (a path under the method and a value).
    fn next(&self, m: &Method) -> Next;
}

/// A number knob of a method to write: its path under the method and its new value.
pub(crate) struct KnobEdit {
    /// Field names from the method's struct (`["adaptive", "max_step"]`).
    pub(crate) path: &'static [&'static str],
    /// The value.
    pub(crate) value: f64,
    /// Written as an integer (a count).
    pub(crate) integer: bool,
}

/// What `M` does to a node's method (see [`MethodPlugin::next`]).
pub(crate) enum Next {
    /// Replace the method by this text.
    Method(String),
    /// Write this knob of the method (a path under it) with this value.
    Knob(&'static [&'static str], String),
}

impl Method {
    /// The method's plug-in (the one registration of each method beside this enum).
    pub(crate) fn plugin(&self) -> &'static dyn MethodPlugin {
        match self {
            Method::ViewSlices(_) => &super::view_slices::plugin::PLUGIN,
            Method::AxisSlices(_) => &super::axis_slices::plugin::PLUGIN,
            Method::Reference(_) => &super::reference::plugin::PLUGIN,
            Method::RayMarch(_) => &super::ray_march::plugin::PLUGIN,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each plug-in answers for its own variant: its name is the scene file's, and coarser
    /// settings stay that method.
    #[test]
    fn every_plugin_answers_for_its_variant() {
        for text in ["ViewSlices(planes: 8)", "AxisSlices()", "Reference(step: 0.01)", "RayMarch()"] {
            let m: Method =
                ron::from_str(&format!("#![enable(implicit_some, unwrap_variant_newtypes)] {text}")).unwrap();
            let p = m.plugin();
            assert!(text.starts_with(&format!("{}(", p.name())), "{text}: {}", p.name());
            let coarse = p.coarser(&m, 4.0);
            assert_eq!(coarse.plugin().name(), p.name(), "{text}");
            assert_ne!(coarse, m, "{text}: 4 times coarser changes a knob");
        }
    }
}
