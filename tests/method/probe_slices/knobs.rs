//! ProbeSlices' scene-file knobs (scene layer, see `scene::methods`).

use serde::{Deserialize, Serialize};

/// View slicing under another name, with one knob.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSlices {
    /// Slicing planes across the object's depth range.
    #[serde(deserialize_with = "crate::scene::methods::view_slices::planes")]
    pub planes: u32,
}

impl Default for ProbeSlices {
    fn default() -> Self {
        ProbeSlices { planes: 16 }
    }
}

impl crate::scene::methods::MethodKnobs for ProbeSlices {}
