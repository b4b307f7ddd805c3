//! AxisSlices' scene-file knobs: types, defaults and ranges (scene layer, see
//! `scene::methods`).

use crate::scene::values::{adapter, checked_f64};
use serde::{Deserialize, Serialize};

checked_f64!(SliceDepth, |v| v > 0.0 && v <= 1024.0, "a depth in (0, 1024] voxels");
checked_f64!(SlicePixels, |v| v > 0.0 && v <= 1024.0, "a slice distance in (0, 1024] pixels");
checked_f64!(MaxAngle, |v| v > 0.0 && v < 90.0, "a view angle in (0, 90) degrees");
adapter!(slice_depth, f64, SliceDepth, |v| v.0);
adapter!(slice_pixels, f64, SlicePixels, |v| v.0);
adapter!(max_angle, f64, MaxAngle, |v| v.0);

fn yes() -> bool {
    true
}

/// Meyer & Neyret 1998: the texel baked into slice images along s, t and w with power-of-two
/// levels; per base triangle one direction and level chosen by the quality criteria.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSlices {
    /// `d` of the criterion `h tan(a) / d <= 1`: how deep, in voxels, the inside of a contour
    /// may be seen between two slices.
    #[serde(default = "one_f64", deserialize_with = "slice_depth")]
    pub depth: f64,
    /// `p` of the criterion `h sin(a) / (z / f) <= p`: the largest apparent distance between two
    /// slices on screen, in pixels.
    #[serde(default = "one_f64", deserialize_with = "slice_pixels")]
    pub pixels: f64,
    /// Largest view angle (degrees from a slice set's normal) the criteria are evaluated at.
    #[serde(default = "default_max_angle", deserialize_with = "max_angle")]
    pub max_angle: f64,
    /// Which slice sets may be chosen (default `Three`).
    #[serde(default)]
    pub directions: SliceDirections,
    /// How slices are composited: binary alpha (default) or blended.
    #[serde(default)]
    pub blend: SliceBlend,
    /// Skip prisms hidden behind the opaque base surfaces: exact (every pixel a prism's corners
    /// can cover already holds a nearer base surface), so it never changes the image.
    #[serde(default)]
    pub occlusion_culling: bool,
    /// Skip slices (and so texels) whose slice image is empty.
    #[serde(default = "yes")]
    pub empty_culling: bool,
    /// `Texels`: texel by texel, back to front; `Slices`: grouped by slice image (section 4.3,
    /// for the texture cache), binary alpha only.
    #[serde(default)]
    pub draw_order: DrawOrder,
    /// MIP-mapped slice images (section 2.2): each image's level chosen by its screen-space
    /// footprint (the fragment's texture-coordinate derivatives), against minification aliasing.
    #[serde(default)]
    pub mipmaps: bool,
}

/// The order in which `AxisSlices` draws its slices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum DrawOrder {
    /// Prisms back to front, each prism's slices back to front (needed by blending).
    #[default]
    Texels,
    /// All slices sampling one slice image together (depth test and alpha test keep the image).
    Slices,
}

fn one_f64() -> f64 {
    1.0
}
fn default_max_angle() -> f64 {
    80.0
}

/// The slice sets `AxisSlices` chooses from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum SliceDirections {
    /// Horizontal (w) and the two vertical sets (s, t), chosen per triangle.
    #[default]
    Three,
    /// Horizontal slices only (to measure what the vertical sets gain).
    Horizontal,
}

/// How `AxisSlices` composites its slices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum SliceBlend {
    /// The paper's binary alpha: the step-corrected opacity thresholded at 1/2, depth-tested and
    /// written, so intersecting texels are right.
    #[default]
    Binary,
    /// Semi-transparent slices blended back to front within each prism, prisms sorted back to
    /// front by centre: slices of overlapping prisms are not interleaved.
    Blended,
}

impl crate::scene::methods::MethodKnobs for AxisSlices {
    fn check(&self) -> Result<(), String> {
        if self.draw_order == DrawOrder::Slices && self.blend == SliceBlend::Blended {
            return Err("`draw_order: Slices` needs `blend: Binary` (blended slices must stay back to front \
                        within each texel)"
                .into());
        }
        Ok(())
    }
}

impl Default for AxisSlices {
    /// The paper's criteria `d = p = 1` over 80 degrees, three slice sets, binary alpha.
    fn default() -> Self {
        AxisSlices {
            depth: 1.0,
            pixels: 1.0,
            max_angle: 80.0,
            directions: SliceDirections::Three,
            blend: SliceBlend::Binary,
            occlusion_culling: false,
            empty_culling: true,
            draw_order: DrawOrder::Texels,
            mipmaps: false,
        }
    }
}
