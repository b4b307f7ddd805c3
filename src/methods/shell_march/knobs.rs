//! ShellMarch's scene-file knobs: types, defaults and ranges. Compiled in the scene layer
//! (`scene::methods`): it imports nothing above it, although it lives in the method's folder.

use crate::scene::values::{adapter, checked_f64};
use crate::scene::Lighting;
use serde::{Deserialize, Serialize};

checked_f64!(Step, |v| v > 0.0 && v <= 16.0, "a step in (0, 16] voxels");
checked_f64!(Tolerance, |v| v > 0.0 && v <= 4.0, "a tolerance in (0, 4] voxels");
checked_f64!(Cutoff, |v| v > 0.0 && v <= 0.5, "a transmittance in (0, 0.5]");
checked_f64!(MipBias, |v| (-4.0..=4.0).contains(&v), "a MIP bias in [-4, 4] levels");
adapter!(step, f64, Step, |v| v.0);
adapter!(tolerance, f64, Tolerance, |v| v.0);
adapter!(cutoff, f64, Cutoff, |v| v.0);
adapter!(mip_bias, f64, MipBias, |v| v.0);

fn one() -> f64 {
    1.0
}

fn quarter() -> f64 {
    0.25
}

fn thousandth() -> f64 {
    1e-3
}

fn yes() -> bool {
    true
}

/// A per-pixel compute ray caster through the shell, made for speed at a measured error.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShellMarch {
    /// Sample spacing along the ray, in voxels of the texel (the largest of the s, t and w
    /// distances, in voxels, between samples); never more than one voxel along w. Default 1.
    #[serde(default = "one", deserialize_with = "step")]
    pub step: f64,
    /// How far, in voxels, the texture coordinates interpolated between a prism's entry and
    /// exit may stray from the exact inverse map (checked at two interior points of each
    /// interpolated piece); pieces that miss it are split, or mapped exactly. Default 0.25.
    #[serde(default = "quarter", deserialize_with = "tolerance")]
    pub tolerance: f64,
    /// The ray stops once its transmittance falls below this. Default 0.001.
    #[serde(default = "thousandth", deserialize_with = "cutoff")]
    pub min_transmittance: f64,
    /// Empty-space skipping: samples in bricks of the texel that hold no opacity are jumped
    /// over in whole steps (the image is the same either way). Default true.
    #[serde(default = "yes")]
    pub skip_empty: bool,
    /// How a sample filters the texel: at full resolution, or over the pixel's footprint in s
    /// and t. Default `Off`.
    #[serde(default)]
    pub filter: Filter,
    /// Levels added to the footprint's MIP level (`filter: Footprint`): below 0 sharper, above
    /// 0 smoother. Default 0.
    #[serde(default, deserialize_with = "mip_bias")]
    pub mip_bias: f64,
    #[serde(default)]
    pub(crate) lighting: Lighting,
}

/// How ShellMarch's samples filter the texel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Filter {
    /// Trilinear at full resolution: sharp, and aliased where a pixel covers many voxels.
    #[default]
    Off,
    /// s and t filtered over the ray's footprint (the pixel's cone against the voxel's size), from
    /// MIP levels of the texel that halve s and t only (w, the height profile, stays sharp); the
    /// step in s and t grows with the level.
    Footprint,
}

impl crate::scene::methods::MethodKnobs for ShellMarch {
    fn lighting(&self) -> Lighting {
        self.lighting
    }
}

impl Default for ShellMarch {
    /// One-voxel steps, a quarter-voxel tolerance, rays stopped at 0.001, skipping on, no
    /// filtering.
    fn default() -> Self {
        ShellMarch {
            step: 1.0,
            tolerance: 0.25,
            min_transmittance: 1e-3,
            skip_empty: true,
            filter: Filter::Off,
            mip_bias: 0.0,
            lighting: Lighting::Baked,
        }
    }
}
