//! ViewSlices' scene-file knobs: types, defaults and ranges. Compiled in the scene layer
//! (`scene::methods`): it imports nothing above it, although it lives in the method's folder.

use crate::scene::Lighting;
use crate::scene::values::{adapter, checked_u32};
use serde::{Deserialize, Serialize};

/// Most planes one ViewSlices object may use (the scan kernel and the dispatch height allow it).
pub const MAX_PLANES: u32 = 16384;

/// Plane count when an object is switched to view slicing from a method without planes.
pub const SWITCHED_PLANES: u32 = 400;

checked_u32!(PlaneCount, 1, MAX_PLANES, "a plane count");
adapter!(planes, u32, PlaneCount, |v| v.0);

fn yes() -> bool {
    true
}

/// View-aligned prism slicing (2002).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ViewSlices {
    /// Slicing planes across the scene's depth range.
    #[serde(deserialize_with = "planes")]
    pub planes: u32,
    /// Skip prisms entirely outside the slab of a plane.
    #[serde(default = "yes")]
    pub(crate) trivial_reject: bool,
    #[serde(default)]
    pub(crate) lighting: Lighting,
    /// How the slices reach the frame: drawn and blended by the rasteriser, or composited per
    /// screen tile by compute kernels.
    #[serde(default)]
    pub(crate) compositor: Compositor,
    /// Level of detail: `Off` draws `planes` planes and the texel at full resolution; `Auto`
    /// chooses the plane count (at most `planes`) and the texel's MIP level from the object's
    /// size on screen (Meyer & Neyret 1998).
    #[serde(default)]
    pub lod: Lod,
}

/// Level of detail of `ViewSlices`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Lod {
    /// `planes` planes, the texel at full resolution.
    #[default]
    Off,
    /// Planes about two per pixel (or per texel voxel, when a voxel covers more than a pixel) of
    /// the depth extent at the object's nearest depth, at most `planes`; the texel at the MIP
    /// level whose voxels cover at most a pixel there.
    Auto,
}

/// How `ViewSlices` composites its slice polygons into the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Compositor {
    /// Indirect draws of the slice triangles, back to front, premultiplied-over blending.
    #[default]
    Raster,
    /// Compute: the slice triangles binned into 8 x 8 pixel tiles, each pixel's fragments
    /// composited front to back in registers, stopping once opaque; the layer blended once.
    Tiles,
}

impl crate::scene::methods::MethodKnobs for ViewSlices {
    fn lighting(&self) -> Lighting {
        self.lighting
    }

    fn imported(&self) -> Option<&'static str> {
        Some("ViewSlices(planes: 256)")
    }
}

impl Default for ViewSlices {
    /// What a switch to view slicing starts from: [`SWITCHED_PLANES`](SWITCHED_PLANES) planes.
    fn default() -> Self {
        ViewSlices {
            planes: SWITCHED_PLANES,
            trivial_reject: true,
            lighting: Lighting::Baked,
            compositor: Compositor::Raster,
            lod: Lod::Off,
        }
    }
}
