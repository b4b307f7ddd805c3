//! ShellMarch's scene-file knobs: types, defaults and ranges. Compiled in the scene layer
//! (`scene::methods`): it imports nothing above it, although it lives in the method's folder.

use crate::scene::values::{adapter, checked_f64};
use crate::scene::Lighting;
use serde::{Deserialize, Serialize};

checked_f64!(Step, |v| v > 0.0 && v <= 16.0, "a step in (0, 16] voxels");
checked_f64!(Tolerance, |v| v > 0.0 && v <= 4.0, "a tolerance in (0, 4] voxels");
checked_f64!(Cutoff, |v| v > 0.0 && v <= 0.5, "a transmittance in (0, 0.5]");
adapter!(step, f64, Step, |v| v.0);
adapter!(tolerance, f64, Tolerance, |v| v.0);
adapter!(cutoff, f64, Cutoff, |v| v.0);

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
    #[serde(default)]
    pub(crate) lighting: Lighting,
}

impl crate::scene::methods::MethodKnobs for ShellMarch {
    fn lighting(&self) -> Lighting {
        self.lighting
    }
}

impl Default for ShellMarch {
    /// One-voxel steps, a quarter-voxel tolerance, rays stopped at 0.001, skipping on.
    fn default() -> Self {
        ShellMarch { step: 1.0, tolerance: 0.25, min_transmittance: 1e-3, skip_empty: true, lighting: Lighting::Baked }
    }
}
