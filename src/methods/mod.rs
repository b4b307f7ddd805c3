//! Host side of each method: view-aligned prism slicing, axis-aligned slices, the reference ray
//! caster, hypertexture ray marching, and the opaque base surface. Each declares what it brings
//! to the render graph ([`Contribution`]) and is registered once, in [`REGISTRY`].

pub mod axis_slices;
pub mod base_surface;
pub mod ray_march;
pub mod reference;
pub mod view_slices;

/// What a method brings to the render graph: the object filters its objects match (passes are
/// instanced over them), and the per-object resources and counts its inputs provide (graph files
/// bind and use them by name). The graph core checks graph files against the union of these.
pub struct Contribution {
    pub method: &'static str,
    pub filters: &'static [&'static str],
    pub resources: &'static [&'static str],
    pub counts: &'static [&'static str],
}

/// Every method, registered once.
pub const REGISTRY: &[&Contribution] = &[
    &base_surface::CONTRIBUTION,
    &view_slices::CONTRIBUTION,
    &axis_slices::CONTRIBUTION,
    &reference::CONTRIBUTION,
    &ray_march::CONTRIBUTION,
];
