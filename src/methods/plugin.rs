//! A method as a plug-in: everything voltex does with a scene method, answered by the method's
//! own folder (`<method>/plugin.rs` implements [`MethodPlugin`] on its knobs struct) and found
//! through [`Method::plugin`], made from the one registration list (`scene::methods`).

use super::options::RenderOptions;
use super::plan::ObjectPlan;
use super::sweep::{SweepPoint, SweepScene, SweepValues};
use super::PlanCx;
use crate::error::Result;
use crate::scene::methods::Draws;
use crate::scene::{Lighting, Method, METHOD_NAMES};

/// What a method answers, on its knobs (`self`: the knobs an object is drawn with, or the
/// method's defaults where no object is at hand).
pub(crate) trait MethodPlugin: Sync {
    /// Plans `object` drawn with these knobs: adds its plan to `object.methods` and its bake,
    /// lighting and frames to the object.
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()>;

    /// Whether this is the ground truth every other method's error is measured against.
    fn is_truth(&self) -> bool {
        false
    }

    /// These knobs after the overrides of `opts` (command line, sweeps), drawing an object
    /// whose lighting is `lighting`.
    fn with_options(&self, opts: &RenderOptions, lighting: Lighting) -> Method;

    /// A volume drawn with `from` switched to this method (`--method`), if this method takes
    /// volumes from another; `None` keeps `from`.
    fn volume_from(&self, _from: &Method, _opts: &RenderOptions) -> Option<Method> {
        None
    }

    /// The knobs `d` times coarser (`d` >= 1): the preview's drafts while a drag goes on.
    fn coarser(&self, d: f64) -> Method;

    /// The preview's `+` (finer) and `-`: the knobs to write; empty where the method has no
    /// knob to step.
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit>;

    /// The preview's `M` within the method: a knob to cycle (its path under the method and its
    /// next value). `None`: `M` switches the object to the next method that draws texels.
    fn next_mode(&self) -> Option<(&'static [&'static str], String)> {
        None
    }

    /// The knobs in force, for the preview's status line (by default all, as scene-file text).
    fn describe(&self) -> String;

    /// Whether `voltex pareto` sweeps it when no `--methods` are given.
    fn swept_by_default(&self) -> bool {
        false
    }

    /// The points `voltex pareto` measures of this method (`Err`: why it measures none here).
    fn sweep(&self, values: &SweepValues, scene: &SweepScene)
        -> std::result::Result<Vec<SweepPoint>, String>;

    /// This method as what a pareto sweep's errors are measured against (`--truth NAME[:ARG]`,
    /// see [`truth_form`](Self::truth_form)): the options that render it and how it reads.
    /// `Err`: what `arg` should have been.
    fn truth(
        &self,
        _arg: Option<&str>,
        _size: (u32, u32),
    ) -> std::result::Result<(RenderOptions, String), String> {
        Err("not a truth".into())
    }

    /// How `--truth` names this method (`view-slices:PLANES`); `None`: it is no truth.
    fn truth_form(&self) -> Option<&'static str> {
        None
    }

    /// Knobs a scene file must write (the rest have defaults).
    fn required_knobs(&self) -> &'static [&'static str] {
        &[]
    }

    /// What leaving out each optional knob means, as scene-file text (the panel shows it).
    fn unset_knobs(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }

    /// Estimated milliseconds per 1000 pixels on software Vulkan (the farm's shard balance;
    /// see `regress::shards`).
    fn kpixel_ms(&self) -> f64;
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

macro_rules! plugin_dispatch {
    ($($(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $name:ident $folder:ident $knobs:literal $(in $path:literal)?,)*) => {
        impl Method {
            /// The method's plug-in: its knobs struct.
            pub(crate) fn plugin(&self) -> &dyn MethodPlugin {
                match self {
                    $($(#[cfg($cfg)])? Method::$name(k) => k,)*
                }
            }

            /// The registered method these knobs belong to.
            pub(crate) fn kind(&self) -> MethodKind {
                match self {
                    $($(#[cfg($cfg)])? Method::$name(_) => MethodKind(stringify!($name)),)*
                }
            }
        }

        impl MethodKind {
            /// The method at its defaults (what a switch to it starts from).
            pub(crate) fn defaults(self) -> Method {
                match self.0 {
                    $($(#[cfg($cfg)])? stringify!($name) => Method::$name(Default::default()),)*
                    other => unreachable!("`{other}` is not a registered method"),
                }
            }
        }
    };
}
crate::scene::methods::for_each_method!(plugin_dispatch);

/// A registered method without its knobs (`--method`, `pareto --methods`), by its scene-file
/// name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MethodKind(&'static str);

impl MethodKind {
    /// Every registered method, in registration order.
    pub fn all() -> impl Iterator<Item = MethodKind> {
        METHOD_NAMES.iter().map(|n| MethodKind(n))
    }

    /// The registered method with this scene-file name.
    pub fn named(name: &str) -> Option<MethodKind> {
        Self::all().find(|k| k.0 == name)
    }

    /// The ground truth (the method whose plug-in says so).
    pub(crate) fn truth() -> MethodKind {
        Self::all().find(|k| k.defaults().plugin().is_truth()).expect("a registered method is the truth")
    }

    /// The scene-file name (`ViewSlices`).
    pub(crate) fn name(self) -> &'static str {
        self.0
    }

    /// The command line's name: the scene-file name in kebab case (`view-slices`).
    pub fn cli_name(self) -> String {
        let mut out = String::new();
        for (i, c) in self.0.char_indices() {
            if c.is_ascii_uppercase() && i > 0 {
                out.push('-');
            }
            out.push(c.to_ascii_lowercase());
        }
        out
    }

    /// Parses a command-line name (`view-slices`).
    pub fn from_cli(s: &str) -> std::result::Result<MethodKind, String> {
        Self::all().find(|k| k.cli_name() == s).ok_or_else(|| {
            let names: Vec<String> = Self::all().map(|k| format!("`{}`", k.cli_name())).collect();
            format!("`{s}`: expected a method: {}", names.join(", "))
        })
    }

    /// Whether `voltex pareto` sweeps it when no `--methods` are given.
    pub fn swept_by_default(self) -> bool {
        self.defaults().plugin().swept_by_default()
    }

    /// Whether `--method` may switch objects to it (it draws texels).
    pub fn switchable(self) -> bool {
        self.defaults().knobs().draws() == Draws::Texels
    }
}

impl std::fmt::Display for MethodKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

/// The knobs of `m` as written by [`Method::text`]: `(name, value)` in order.
pub(crate) fn knob_fields(m: &Method) -> Vec<(String, String)> {
    let text = m.text();
    let inner = text.split_once('(').map_or("", |(_, rest)| rest.strip_suffix(')').unwrap_or(rest));
    let (mut out, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices().chain([(inner.len(), ',')]) {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            ',' if depth == 0 => {
                if let Some((k, v)) = inner[start..i].split_once(':') {
                    out.push((k.trim().to_string(), v.trim().to_string()));
                }
                start = i + 1;
            }
            _ => {}
        }
    }
    out
}

/// `m` as scene-file text with only the knobs a file must write and those off their defaults
/// (`AxisSlices()`, `ViewSlices(planes: 400, lighting: PerPixel)`).
pub(crate) fn short_text(m: &Method) -> String {
    let defaults = knob_fields(&m.kind().defaults());
    let required = m.plugin().required_knobs();
    let knobs: Vec<String> = knob_fields(m)
        .into_iter()
        .filter(|(n, v)| required.contains(&n.as_str()) || !defaults.contains(&(n.clone(), v.clone())))
        .map(|(n, v)| format!("{n}: {v}"))
        .collect();
    format!("{}({})", m.kind(), knobs.join(", "))
}

/// A registered method as the preview's panel shows it.
pub(crate) struct PanelKnobs {
    /// The scene-file name.
    pub(crate) name: &'static str,
    /// Knobs a file may leave out, with the value shown for each (an optional knob: what
    /// leaving it out means; one without such a value is not shown).
    pub(crate) defaults: Vec<(&'static str, &'static str)>,
    /// The text written when the method is chosen for an object (methods that draw texels).
    pub(crate) chosen: Option<&'static str>,
}

/// Every registered method's panel knobs, made once from its defaults and plug-in.
pub(crate) fn panel_knobs() -> &'static [PanelKnobs] {
    static KNOBS: std::sync::OnceLock<Vec<PanelKnobs>> = std::sync::OnceLock::new();
    let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
    KNOBS.get_or_init(|| {
        MethodKind::all()
            .map(|k| {
                let m = k.defaults();
                let plugin = m.plugin();
                let (required, unset) = (plugin.required_knobs(), plugin.unset_knobs());
                let fields = knob_fields(&m);
                let defaults = fields
                    .iter()
                    .filter(|(n, _)| !required.contains(&n.as_str()))
                    .filter_map(|(n, v)| {
                        let shown = match unset.iter().find(|(u, _)| u == n) {
                            Some((_, hint)) if v == "None" => hint.clone(),
                            _ if v == "None" => return None,
                            _ => v.clone(),
                        };
                        Some((leak(n.clone()), leak(shown)))
                    })
                    .collect();
                let written: Vec<String> = fields
                    .iter()
                    .filter(|(n, _)| required.contains(&n.as_str()))
                    .map(|(n, v)| format!("{n}: {v}"))
                    .collect();
                let chosen = k.switchable().then(|| leak(format!("{k}({})", written.join(", "))));
                PanelKnobs { name: k.name(), defaults, chosen }
            })
            .collect()
    })
}

/// The method after `M`: the next method that draws texels in registration order, keeping the
/// lighting (a method's own mode, such as RayMarch's shading, is its [`MethodPlugin::next_mode`]).
pub(crate) fn next_method(m: &Method) -> Method {
    let kinds: Vec<MethodKind> = MethodKind::all().filter(|k| k.switchable()).collect();
    let at = kinds.iter().position(|k| *k == m.kind()).map_or(0, |i| i + 1);
    let next = kinds[at % kinds.len()];
    next.defaults().plugin().with_options(&RenderOptions::default(), m.lighting())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each plug-in answers for its own variant: coarser settings stay that method, its text
    /// parses back to it, and the command line's name maps back to it.
    #[test]
    fn every_plugin_answers_for_its_variant() {
        for text in ["ViewSlices(planes: 8)", "AxisSlices()", "Reference(step: 0.01)", "RayMarch()"] {
            let parse = |t: &str| -> Method {
                ron::from_str(&format!("#![enable(implicit_some, unwrap_variant_newtypes)] {t}")).unwrap()
            };
            let m = parse(text);
            let kind = m.kind();
            assert!(text.starts_with(&format!("{}(", kind.name())), "{text}: {kind}");
            assert_eq!(MethodKind::from_cli(&kind.cli_name()), Ok(kind));
            let coarse = m.plugin().coarser(4.0);
            assert_eq!(coarse.kind(), kind, "{text}");
            assert_ne!(coarse, m, "{text}: 4 times coarser changes a knob");
            assert_eq!(parse(&m.text()), m, "{text}: its text");
        }
        assert_eq!(MethodKind::truth().name(), "Reference");
        // `M` goes to the next method at its defaults, keeping the lighting where it has one.
        let lit = crate::scene::ViewSlices { lighting: Lighting::PerPixel, ..Default::default() };
        assert_eq!(short_text(&Method::ViewSlices(lit)), "ViewSlices(planes: 400, lighting: PerPixel)");
        assert_eq!(short_text(&next_method(&Method::ViewSlices(lit))), "AxisSlices()");
        assert!(MethodKind::from_cli("no-such").unwrap_err().contains("`view-slices`"));
    }

    /// The panel shows every knob of every method (from the knobs themselves, so a new knob
    /// shows with no panel edit), and writes a method that parses when one is chosen.
    #[test]
    fn the_panel_shows_every_knob() {
        let knobs = panel_knobs();
        assert_eq!(knobs.len(), METHOD_NAMES.len());
        let shown = |name: &str| knobs.iter().find(|k| k.name == name).unwrap().defaults.clone();
        let names = |name: &str| shown(name).iter().map(|(n, _)| *n).collect::<Vec<_>>();
        assert_eq!(names("ViewSlices"), ["trivial_reject", "lighting", "compositor", "lod"]);
        assert!(names("AxisSlices").contains(&"mipmaps"), "{:?}", names("AxisSlices"));
        assert!(shown("RayMarch").contains(&("step", "0.015")), "{:?}", shown("RayMarch"));
        for k in knobs {
            let Some(chosen) = k.chosen else { continue };
            let m: Method = crate::scene::options().from_str(chosen).unwrap();
            assert_eq!(m.kind().name(), k.name, "{chosen}");
        }
    }
}
