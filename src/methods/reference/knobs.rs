//! The Reference's scene-file knobs (scene layer, see `scene::methods`).

use crate::scene::{Lighting, Shading};
use serde::{Deserialize, Serialize};

/// Exact ray casting through the prisms with a fine fixed step: the ground truth.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Ray step in world units (default: half the object's smallest voxel extent).
    #[serde(default, deserialize_with = "crate::scene::values::opt_positive")]
    pub step: Option<f64>,
    #[serde(default)]
    pub(crate) lighting: Lighting,
    /// A `RayMarch` volume switched to the Reference (its truth, `--method reference`) keeps
    /// its look: that object's shading. Not in scene files (`None`: `lighting` decides).
    #[serde(skip)]
    pub(crate) volume_shading: Option<Shading>,
}

impl crate::scene::methods::MethodKnobs for Reference {
    fn lighting(&self) -> Lighting {
        self.lighting
    }

    /// Volumes are integrated exactly, cell by cell.
    fn volumes(&self) -> Option<Result<(), String>> {
        Some(Ok(()))
    }
}

impl Default for Reference {
    /// The default step (half the smallest voxel extent), the texel's baked colour.
    fn default() -> Self {
        Reference { step: None, lighting: Lighting::Baked, volume_shading: None }
    }
}
