//! Bounding volume hierarchies for the kernels: obvhs' BVH2 flattened into GPU nodes.

use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::BvhBuildParams;

use crate::types::ReferenceNode;

/// A BVH2 over `boxes` (obvhs) flattened for the kernels, and the primitive order its leaves
/// index: a node's `min.w` is its primitive count as u32 bits (0: inner node), `max.w` its first
/// primitive (leaf, in that order) or its first child (inner; the second follows it).
pub(crate) fn flat_bvh(boxes: &[Aabb]) -> (Vec<ReferenceNode>, Vec<u32>) {
    let mut time = Default::default();
    let bvh = build_bvh2(boxes, BvhBuildParams::medium_build(), &mut time);
    let nodes = bvh
        .nodes
        .iter()
        .map(|n| ReferenceNode {
            min: [n.aabb.min.x, n.aabb.min.y, n.aabb.min.z, f32::from_bits(n.prim_count)],
            max: [n.aabb.max.x, n.aabb.max.y, n.aabb.max.z, f32::from_bits(n.first_index)],
        })
        .collect();
    (nodes, bvh.primitive_indices)
}
