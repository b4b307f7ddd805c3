//! The registration of every scene method, and the scene-file enum made from it.
//!
//! A method's knobs are scene-file types: each `src/methods/<method>/knobs.rs` is compiled here,
//! as `scene::methods::<method>` (a `#[path]` made from the list), so the scene layer never
//! imports the methods layer, although each method's knobs live in its folder (they import
//! nothing above the scene layer; `tests/checks/layers.rs` keeps it so). Everything else a
//! method does is its plug-in (`methods::plugin`), dispatched from the same list.

use crate::scene::Lighting;
use serde::{Deserialize, Serialize};

/// The registration: each method's scene-file name, its folder (`src/methods/<folder>/`,
/// `wgsl/<folder>/`) and its knobs file (relative to `src/scene/`), optionally under a `cfg`
/// (`in "path"`: a method folder elsewhere, relative to `src/methods/`). The scene-file enum
/// [`Method`], its dispatch to knobs and plug-ins, the method modules and their graph
/// contributions are all made from this list (`$then!` receives it), so a new method is a
/// folder and a line here.
macro_rules! for_each_method {
    ($then:ident) => {
        $then! {
            /// View-aligned prism slicing (2002).
            ViewSlices view_slices "../methods/view_slices/knobs.rs",
            /// Axis-aligned slice stacks (Meyer & Neyret 1998).
            AxisSlices axis_slices "../methods/axis_slices/knobs.rs",
            /// Exact ray casting through the prisms: the ground truth.
            Reference reference "../methods/reference/knobs.rs",
            /// Ray marching of a hypertexture or volume (Gilet & Dischler 2009).
            RayMarch ray_march "../methods/ray_march/knobs.rs",
            /// Per-pixel ray casting through the shell, made for speed at a measured error.
            ShellMarch shell_march "../methods/shell_march/knobs.rs",
            /// A method registered by the tests alone (the worked example of adding one).
            #[cfg(feature = "test-method")]
            ProbeSlices probe_slices "../../tests/method/probe_slices/knobs.rs" in "../../tests/method/probe_slices/mod.rs",
        }
    };
}
pub(crate) use for_each_method;

/// What the scene layer asks of a method's knobs (each `<method>/knobs.rs` answers).
pub(crate) trait MethodKnobs {
    /// Where the object's shading comes from.
    fn lighting(&self) -> Lighting {
        Lighting::Baked
    }

    /// What the method draws: a surface's texel, or a hypertexture (density) node.
    fn draws(&self) -> Draws {
        Draws::Texels
    }

    /// Whether the method draws volume nodes: `Some(Err(why))` where these knobs cannot.
    fn volumes(&self) -> Option<Result<(), String>> {
        None
    }

    /// The ray step a density node is marched with (checked against the node's bounds).
    fn density_step(&self) -> Option<f64> {
        None
    }

    /// Checks of the knobs together: `Err` is the message, placed at the method.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }

    /// The method as `voltex import` writes it into a new scene (scene-file text) for what it
    /// draws: a texel on an imported mesh, or an imported volume ([`MethodKnobs::volumes`]).
    /// The first registered method that answers is written.
    fn imported(&self) -> Option<&'static str> {
        None
    }
}

/// What a method draws (see [`MethodKnobs::draws`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Draws {
    /// A surface's texel: the node has a `surface` and a `texel`.
    Texels,
    /// A hypertexture: the node has a `hypertexture` (or is a volume).
    Densities,
}

macro_rules! scene_enum {
    ($($(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $name:ident $folder:ident $knobs:literal $(in $path:literal)?,)*) => {
        $($(#[cfg($cfg)])? #[path = $knobs] pub(crate) mod $folder;)*
        // Each method's knob types are the scene's (`scene::ViewSlices`, ...).
        $($(#[cfg($cfg)])? pub use $folder::*;)*

        /// How a node's texel is rendered: one variant per registered method, each with its knobs.
        #[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
        #[serde(deny_unknown_fields)]
        pub enum Method {
            $($(#[doc = $doc])* $(#[cfg($cfg)])? $name($folder::$name),)*
        }

        impl Method {
            /// The method's knobs as the scene layer sees them.
            pub(crate) fn knobs(&self) -> &dyn MethodKnobs {
                match self {
                    $($(#[cfg($cfg)])? Method::$name(k) => k,)*
                }
            }

            /// The method's scene-file name.
            pub(crate) fn name(&self) -> &'static str {
                match self {
                    $($(#[cfg($cfg)])? Method::$name(_) => stringify!($name),)*
                }
            }

            /// Every method at its defaults, in registration order.
            #[allow(clippy::vec_init_then_push)] // `vec![]` takes no `cfg` on its items.
            pub(crate) fn every_default() -> Vec<Method> {
                let mut all = Vec::new();
                $($(#[cfg($cfg)])? all.push(Method::$name(Default::default()));)*
                all
            }
        }

        /// Every method's scene-file name, in registration order.
        pub const METHOD_NAMES: &[&str] = &[$($(#[cfg($cfg)])? stringify!($name),)*];
    };
}
for_each_method!(scene_enum);

impl Method {
    /// Where the object's shading comes from.
    pub(crate) fn lighting(&self) -> Lighting {
        self.knobs().lighting()
    }

    /// What a hypertexture or volume node without a `method` is drawn with: the first method
    /// that draws densities, at its defaults.
    pub(crate) fn for_densities() -> Method {
        let mut all = Method::every_default().into_iter();
        all.find(|m| m.knobs().draws() == Draws::Densities).expect("a registered method draws densities")
    }

    /// What `voltex import` writes for an imported mesh's texel (`volume: false`) or an imported
    /// volume (see [`MethodKnobs::imported`]).
    pub(crate) fn imported(volume: bool) -> &'static str {
        let draws = |m: &Method| match volume {
            true => m.knobs().volumes().is_some(),
            false => m.knobs().draws() == Draws::Texels,
        };
        let mut all = Method::every_default().into_iter().filter(draws);
        all.find_map(|m| m.knobs().imported()).expect("a registered method is imported")
    }

    /// The methods that draw volume nodes, as a user would write them (`RayMarch(...)`).
    pub(crate) fn volume_methods() -> String {
        let names: Vec<String> = Method::every_default()
            .iter()
            .filter(|m| m.knobs().volumes().is_some())
            .map(|m| format!("{}(...)", m.name()))
            .collect();
        names.join(" or ")
    }

    /// The method and all its knobs as scene-file text (`ViewSlices(planes: 400, ...)`).
    pub fn text(&self) -> String {
        let compact = crate::scene::options().to_string(self).expect("knobs are plain values");
        // Knobs hold no strings: every `,` and `:` separates.
        compact.replace(',', ", ").replace(':', ": ")
    }
}
