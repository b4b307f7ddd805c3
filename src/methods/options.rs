//! Overrides of what a scene file says (the command line, the preview, sweeps), and how they
//! resolve an object's method.

use std::path::PathBuf;

use crate::scene::{AxisSlices, Camera, Method, RayMarch, Reference, Shading, Shadows, ViewSlices};

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
}

/// A method without its knobs, to switch every object to it (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodKind {
    /// View-aligned prism slicing.
    ViewSlices,
    /// Exact ray casting (the ground truth).
    Reference,
    /// Axis-aligned slice stacks.
    AxisSlices,
}

/// Axis slicing's knobs when an object is switched to it from another method.
pub const DEFAULT_AXIS_SLICES: AxisSlices = AxisSlices {
    depth: 1.0,
    pixels: 1.0,
    max_angle: 80.0,
    directions: crate::scene::SliceDirections::Three,
    blend: crate::scene::SliceBlend::Binary,
    occlusion_culling: false,
    empty_culling: true,
    draw_order: crate::scene::DrawOrder::Texels,
    mipmaps: false,
};

/// Plane count when an object is switched to view slicing from a method without planes.
pub const SWITCHED_PLANES: u32 = 400;

impl RenderOptions {
    /// A volume object's method after the overrides. RayMarch and Reference both draw volumes:
    /// `--method reference` switches a RayMarch volume to the exact Reference with `--step`,
    /// keeping its shading (the truth of a look is that look, integrated exactly); otherwise as
    /// [`apply`](Self::apply).
    pub(crate) fn apply_volume(&self, method: &Method) -> Method {
        match (self.method, method) {
            (Some(MethodKind::Reference), Method::RayMarch(rm)) => Method::Reference(Reference {
                step: self.step,
                lighting: if rm.shading == Shading::None {
                    crate::scene::Lighting::Baked
                } else {
                    crate::scene::Lighting::PerPixel
                },
                volume_shading: Some(rm.shading),
            }),
            _ => self.apply(method),
        }
    }

    /// An object's method after the overrides: switched to `method` if given, knobs replaced.
    pub(crate) fn apply(&self, method: &Method) -> Method {
        if let Method::RayMarch(rm) = method {
            // Hypertextures have no texel for other methods: only the step changes.
            let adaptive = match self.max_step {
                Some(m) => m.map(|max_step| crate::scene::Adaptive { max_step }),
                None => rm.adaptive,
            };
            let step = self.step.or(rm.step);
            let step = self.step_scale.map_or(step, |k| Some(k * step.unwrap_or(rm.step())));
            let (shading, shadows) = match self.shadows {
                None => (rm.shading, rm.shadows),
                Some(None) => (Shading::Phong, Shadows::Rays),
                Some(Some(s)) => (Shading::PhongShadows, s),
            };
            return Method::RayMarch(RayMarch {
                step,
                segments: self.segments.unwrap_or(rm.segments),
                adaptive,
                shading,
                shadows,
                ..*rm
            });
        }
        let lighting = method.lighting();
        // A method the switch does not know keeps its knobs unless switched.
        let Some(kind) = self.method.or(match method {
            Method::ViewSlices(_) => Some(MethodKind::ViewSlices),
            Method::Reference(_) => Some(MethodKind::Reference),
            Method::AxisSlices(_) => Some(MethodKind::AxisSlices),
            _ => None,
        }) else {
            return method.clone();
        };
        match (kind, method) {
            (MethodKind::ViewSlices, Method::ViewSlices(vs)) => Method::ViewSlices(ViewSlices {
                planes: self.planes.unwrap_or(vs.planes),
                trivial_reject: self.trivial_reject.unwrap_or(vs.trivial_reject),
                lighting,
                compositor: self.compositor.unwrap_or(vs.compositor),
                lod: self.lod.unwrap_or(vs.lod),
            }),
            (MethodKind::ViewSlices, _) => Method::ViewSlices(ViewSlices {
                planes: self.planes.unwrap_or(SWITCHED_PLANES),
                trivial_reject: self.trivial_reject.unwrap_or(true),
                lighting,
                compositor: self.compositor.unwrap_or_default(),
                lod: self.lod.unwrap_or_default(),
            }),
            (MethodKind::Reference, Method::Reference(r)) => {
                Method::Reference(Reference { step: self.step.or(r.step), lighting, ..*r })
            }
            (MethodKind::Reference, _) => {
                Method::Reference(Reference { step: self.step, lighting, volume_shading: None })
            }
            (MethodKind::AxisSlices, m) => {
                let a = if let Method::AxisSlices(a) = m { *a } else { DEFAULT_AXIS_SLICES };
                let (depth, pixels) = self.axis_criteria.unwrap_or((a.depth, a.pixels));
                let occlusion_culling = self.occlusion_culling.unwrap_or(a.occlusion_culling);
                let mipmaps = self.mipmaps.unwrap_or(a.mipmaps);
                Method::AxisSlices(AxisSlices { depth, pixels, occlusion_culling, mipmaps, ..a })
            }
        }
    }
}

/// Parses `--shadows` values: `none` (Phong without shadows), `rays` (shadow rays) or
/// `volume:N` (a light volume of resolution N).
pub fn parse_shadows(s: &str) -> std::result::Result<Option<Shadows>, String> {
    use crate::scene::MAX_LIGHT_RESOLUTION;
    match s {
        "none" => Ok(None),
        "rays" => Ok(Some(Shadows::Rays)),
        _ => match s.strip_prefix("volume:").map(|n| n.parse::<u32>()) {
            Some(Ok(resolution)) if (4..=MAX_LIGHT_RESOLUTION).contains(&resolution) => {
                Ok(Some(Shadows::LightVolume { resolution }))
            }
            _ => Err(format!(
                "`{s}`: expected `none`, `rays` or `volume:N` with a resolution N in 4..={MAX_LIGHT_RESOLUTION}"
            )),
        },
    }
}

/// `--shadows` as written: `none`, `rays` or `volume:N`.
pub(crate) fn shadows_name(s: Option<Shadows>) -> String {
    match s {
        None => "none".into(),
        Some(Shadows::Rays) => "rays".into(),
        Some(Shadows::LightVolume { resolution }) => format!("volume:{resolution}"),
    }
}
