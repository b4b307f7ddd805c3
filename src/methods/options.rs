//! Overrides of what a scene file says (the command line, the preview, sweeps), and how they
//! resolve an object's method.

use std::path::PathBuf;

use super::plugin::MethodKind;
use crate::scene::{Camera, Method};

/// Overrides of what the scene file says, from the command line or tests.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    /// Render size in pixels (width, height), instead of the scene's `output`.
    pub size: Option<(u32, u32)>,
    /// The graph file to render with, instead of `graphs/frame.ron`.
    pub graph: Option<PathBuf>,
    /// ViewSlices: plane count of every ViewSlices object.
    pub planes: Option<u32>,
    /// ViewSlices: whether prisms outside a plane's slab are skipped.
    pub trivial_reject: Option<bool>,
    /// Render every textured object with this method (keeping its lighting mode).
    pub method: Option<MethodKind>,
    /// Ray step for `Reference` and `RayMarch` objects (world units).
    pub step: Option<f64>,
    /// Segment strategy of every `RayMarch` object (the Pareto sweep).
    pub segments: Option<crate::scene::Segments>,
    /// RayMarch objects: an adaptive stride up to this step (world units; the Pareto sweep);
    /// `Some(None)` turns it off.
    pub max_step: Option<Option<f64>>,
    /// Methods replacing those of named objects (the preview's per-object switch), before
    /// `method` and the knob overrides apply.
    pub object_methods: Vec<(String, Method)>,
    /// A camera replacing the scene's (the preview's orbit).
    pub camera: Option<Camera>,
    /// Render at `n` times the width and height and average each `n x n` block: every pixel is
    /// then the mean over its area rather than a point sample (anti-aliasing; a reference for
    /// methods that filter by the pixel footprint).
    pub supersample: Option<u32>,
    /// AxisSlices criteria `(d, p)` for every AxisSlices object: slice depth in voxels and
    /// apparent slice distance in pixels (`--criteria`, the Pareto sweep).
    pub axis_criteria: Option<(f64, f64)>,
    /// Time of the frame in seconds (animated hypertextures; default: the scene's).
    pub time: Option<f64>,
    /// AxisSlices occlusion culling for every AxisSlices object (`--occlusion-culling`).
    pub occlusion_culling: Option<bool>,
    /// MIP-mapped slice images for every AxisSlices object (`--mipmaps`, the Pareto sweep).
    pub mipmaps: Option<bool>,
    /// RayMarch objects' step times this (after `step`; a converged truth).
    pub step_scale: Option<f64>,
    /// AOVs to write beside the colour (`--aov`), replacing the scene's `aovs`.
    pub aovs: Option<Vec<String>>,
    /// GPU memory the frame may allocate (`--budget`; default `gpu::budget::DEFAULT_BUDGET`).
    pub budget: Option<u64>,
    /// Compositor of every ViewSlices object (`--compositor`, the sweeps).
    pub compositor: Option<crate::scene::Compositor>,
    /// Level of detail of every ViewSlices object (`--lod`, the sweeps).
    pub lod: Option<crate::scene::Lod>,
    /// Entries of a `Tiles` compositor's tile lists (default: sized from the sweep and the
    /// output; tests make it small to exercise the overflow path).
    pub tile_entries: Option<u32>,
    /// Shadows of every RayMarch object (`--shadows`, the Pareto sweep): `Some(None)` is Phong
    /// without shadows, `Some(Some(s))` `PhongShadows` with `s`.
    pub shadows: Option<Option<crate::scene::Shadows>>,
    /// Knobs by name for every object of the switched-to (or own) method whose plug-in knows
    /// the name, e.g. `("tolerance", 1.0)` (a sweep's point); unknown names are ignored.
    pub knobs: Vec<(&'static str, f64)>,
}

impl RenderOptions {
    /// The value given for knob `name` (see `knobs`).
    pub(crate) fn knob(&self, name: &str) -> Option<f64> {
        self.knobs.iter().rev().find(|(k, _)| *k == name).map(|(_, v)| *v)
    }

    /// A volume object's method after the overrides: a switch (`--method`) to a method that
    /// takes volumes from the object's (the Reference: the truth of a RayMarch volume is that
    /// look, integrated exactly) makes that; otherwise as [`apply`](Self::apply).
    pub(crate) fn apply_volume(&self, method: &Method) -> Method {
        let switched = self.method.and_then(|k| k.defaults().plugin().volume_from(method, self));
        switched.unwrap_or_else(|| self.apply(method))
    }

    /// An object's method after the overrides: switched to `method` if given (between methods
    /// that draw texels; a new method starts from its defaults), then its plug-in applies the
    /// knob overrides.
    pub(crate) fn apply(&self, method: &Method) -> Method {
        let lighting = method.lighting();
        let switch = self.method.filter(|k| {
            *k != method.kind()
                && k.switchable()
                && method.knobs().draws() == crate::scene::methods::Draws::Texels
        });
        match switch {
            Some(k) => k.defaults().plugin().with_options(self, lighting),
            None => method.plugin().with_options(self, lighting),
        }
    }
}
