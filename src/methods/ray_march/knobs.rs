//! RayMarch's scene-file knobs: types, defaults and ranges (scene layer, see `scene::methods`).

use crate::scene::values::{adapter, checked_u32};
use crate::scene::methods::Draws;
use crate::scene::Shading;
use serde::{Deserialize, Serialize};

/// Ray marching of a hypertexture (Gilet & Dischler 2009), front to back with the shared
/// step-corrected opacity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RayMarch {
    /// The paper's presets: HQ (step 0.002) or IE (step 0.015, the default).
    #[serde(default)]
    pub quality: Quality,
    /// Ray step in world units (replaces the preset's).
    #[serde(default, deserialize_with = "crate::scene::values::opt_positive")]
    pub step: Option<f64>,
    /// How each sample is lit (default `None`: the transfer function's colour as is).
    #[serde(default)]
    pub shading: Shading,
    /// Step of shadow rays (world units; default twice the ray step).
    #[serde(default, deserialize_with = "crate::scene::values::opt_positive")]
    pub shadow_step: Option<f64>,
    /// Which stretches of each ray are marched (Gilet & Dischler 2009, section 5).
    #[serde(default)]
    pub segments: Segments,
    /// An adaptive stride (the paper's future work, section 7): longer strides in empty space,
    /// the fine `step` where there is matter (default: off, every step sampled).
    #[serde(default)]
    pub adaptive: Option<Adaptive>,
    /// How `PhongShadows` finds the light reaching a sample: exact shadow rays (the default) or
    /// a transmittance grid marched once per light.
    #[serde(default)]
    pub shadows: Shadows,
}

/// Shadows of `RayMarch(shading: PhongShadows)`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Shadows {
    /// A shadow ray from every shaded sample to the bounds' exit, step `shadow_step`: exact.
    #[default]
    Rays,
    /// A light volume: transmittance towards the light on a grid over the object's bounds
    /// (`resolution` samples along its longest axis, in the light's frame), marched once per
    /// light and density by `bake_light_volume.wgsl` and read trilinearly by the shading.
    LightVolume {
        /// Samples along the grid's longest axis, 4..=256 (default 64).
        #[serde(default = "default_light_resolution", deserialize_with = "light_resolution")]
        resolution: u32,
    },
}

/// `LightVolume`'s default and largest resolution (samples along the longest axis).
pub(crate) const DEFAULT_LIGHT_RESOLUTION: u32 = 64;
pub(crate) const MAX_LIGHT_RESOLUTION: u32 = 256;

fn default_light_resolution() -> u32 {
    DEFAULT_LIGHT_RESOLUTION
}

/// `RayMarch(adaptive: (max_step: ..))`: on the lattice of `step`, strides of 1, 2, 4, ... steps
/// while the density is 0, at most `max_step` (world units, at least `step`) long; a strided
/// sample that finds matter goes back to the sample before it and continues step by step.
/// Features thinner than a stride between two empty samples are missed.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Adaptive {
    #[serde(deserialize_with = "crate::scene::values::positive")]
    pub(crate) max_step: f64,
}

/// Longest adaptive stride, in steps.
pub(crate) const MAX_STRIDE: u32 = 1 << 12;
/// Most depth-peeling passes (segments per ray).
pub(crate) const MAX_PEEL_PASSES: u32 = 8;
/// Most depth slabs per pixel of EWA-style splatting.
pub(crate) const MAX_SPLAT_SLABS: u32 = 64;
/// Largest splat lattice (cells along the bounds' longest axis).
pub(crate) const MAX_SPLAT_GRID: u32 = 96;

/// The segments of a ray that `RayMarch` marches.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Segments {
    /// From the entry to the exit of the object's enlarged bounds.
    #[default]
    Bounds,
    /// Up to `passes` exact entry/exit intervals of the ray with the object's surface splats
    /// (disks on the boundary enlarged by the largest shift), found by depth peeling; concave
    /// objects give several per ray. `splat_grid`: lattice cells along the bounds' longest axis
    /// from which the splats are made (their spacing).
    DepthPeeling {
        /// Segments per ray, 1..=8 (default 4).
        #[serde(default = "default_passes", deserialize_with = "peel_passes")]
        passes: u32,
        /// Lattice cells along the bounds' longest axis the splats are made from, 4..=96 (default 32).
        #[serde(default = "default_splat_grid", deserialize_with = "splat_grid")]
        splat_grid: u32,
    },
    /// EWA-style splatting (section 5.1): every interior splat (a sphere) marches the stretch of
    /// each pixel ray of its footprint inside it, weighted by a Gaussian of the ray's distance to
    /// its centre; contributions are summed per depth slab (`slabs` along each ray's span in the
    /// bounds) and the slabs composited front to back.
    Splatting {
        /// Depth slabs along each ray's span in the bounds, 1..=64 (default 16).
        #[serde(default = "default_slabs", deserialize_with = "splat_slabs")]
        slabs: u32,
        /// Lattice cells along the bounds' longest axis the splats are made from, 4..=96 (default 32).
        #[serde(default = "default_splat_grid", deserialize_with = "splat_grid")]
        splat_grid: u32,
    },
}

/// `Splatting`'s default depth slabs.
pub const DEFAULT_SPLAT_SLABS: u32 = 16;

fn default_slabs() -> u32 {
    DEFAULT_SPLAT_SLABS
}

/// `DepthPeeling`'s default passes (segments per ray).
pub const DEFAULT_PEEL_PASSES: u32 = 4;
/// `DepthPeeling`'s default splat lattice cells along the bounds' longest axis.
pub const DEFAULT_SPLAT_GRID: u32 = 32;

fn default_passes() -> u32 {
    DEFAULT_PEEL_PASSES
}

fn default_splat_grid() -> u32 {
    DEFAULT_SPLAT_GRID
}

impl RayMarch {
    /// The ray step in world units: `step` if given, else the quality preset's.
    pub fn step(&self) -> f64 {
        self.step.unwrap_or(self.quality.step())
    }

    /// The longest stride in fine steps (1: the adaptive stride is off); `max_step` below the
    /// step is refused by validation.
    pub(crate) fn max_stride(&self) -> u32 {
        self.adaptive.map_or(1, |a| (a.max_step / self.step()).floor().clamp(1.0, MAX_STRIDE as f64) as u32)
    }
}

/// The quality settings of the paper's Figure 11.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Quality {
    /// High quality: step 0.002.
    #[serde(rename = "HQ")]
    High,
    /// Interactive exploration: step 0.015.
    #[default]
    #[serde(rename = "IE")]
    Interactive,
}

impl Quality {
    pub(crate) fn step(self) -> f64 {
        match self {
            Quality::High => 0.002,
            Quality::Interactive => 0.015,
        }
    }
}

checked_u32!(PeelPasses, 1, MAX_PEEL_PASSES, "a depth-peeling pass count");
checked_u32!(SplatGrid, 4, MAX_SPLAT_GRID, "a splat lattice size (cells along the longest axis)");
checked_u32!(
    LightResolution,
    4,
    MAX_LIGHT_RESOLUTION,
    "a light volume resolution (samples along the longest axis)"
);
checked_u32!(SplatSlabs, 1, MAX_SPLAT_SLABS, "a depth slab count");
adapter!(peel_passes, u32, PeelPasses, |v| v.0);
adapter!(splat_grid, u32, SplatGrid, |v| v.0);
adapter!(light_resolution, u32, LightResolution, |v| v.0);
adapter!(splat_slabs, u32, SplatSlabs, |v| v.0);

impl crate::scene::methods::MethodKnobs for RayMarch {
    fn draws(&self) -> Draws {
        Draws::Densities
    }

    fn imported(&self) -> Option<&'static str> {
        Some("RayMarch(shading: PhongShadows)")
    }

    fn volumes(&self) -> Option<Result<(), String>> {
        Some(if self.segments != Segments::Bounds || self.adaptive.is_some() {
            Err("a volume node's RayMarch takes `step`, `quality`, `shading` and `shadow_step`: its brick \
                 table skips empty space (no `segments` or `adaptive`)"
                .into())
        } else {
            Ok(())
        })
    }

    fn density_step(&self) -> Option<f64> {
        Some(self.step())
    }

    fn check(&self) -> Result<(), String> {
        if let Some(a) = self.adaptive.filter(|a| a.max_step < self.step()) {
            return Err(format!(
                "RayMarch(adaptive: (max_step: {})) is below the step {}: expected a max_step of at least the step",
                a.max_step,
                self.step()
            ));
        }
        if self.shadows != Shadows::Rays && self.shading != Shading::PhongShadows {
            return Err(format!(
                "RayMarch(shadows: LightVolume(..)) with shading: {:?}: expected shading: PhongShadows (the \
                 light volume replaces its shadow rays)",
                self.shading
            ));
        }
        Ok(())
    }
}

/// Parses `--shadows` values: `none` (Phong without shadows), `rays` (shadow rays) or
/// `volume:N` (a light volume of resolution N).
pub fn parse_shadows(s: &str) -> std::result::Result<Option<Shadows>, String> {
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
