//! The opaque base surface under every textured object, drawn by `base_surface/draw_base.wgsl`
//! (its vertices are built with the object's plan in `render`).

use super::Contribution;

pub const CONTRIBUTION: Contribution = Contribution {
    method: "base surface",
    filters: &["BaseSurface"],
    resources: &["base_vertices"],
    counts: &["base_vertices"],
};
