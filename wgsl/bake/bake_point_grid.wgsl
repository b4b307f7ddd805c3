// Bakes a point set (hypertexture Points objects) into a grid: per outside sample the vector to the closest point of the union of its kernels' balls and the signed distance to it (inside samples are left to flood_point_grid.wgsl), then per sample the sum of the kernels (1 - r^2/R^2)^3 over the saturation; CPU twin src/cpu/bake_point_grid.rs.
#include "shared/types.wgsl"
#include "shared/bvh.wgsl"
#include "shared/grid_sample.wgsl"

// lo, hi: the grid's corners (hi.w: 1 / saturation); counts: samples per axis, points, BVH
// nodes; size: samples per axis.
@group(0) @binding(0) var<uniform> grid_params: MeshGridParams;
// `BvhNode`s (shared/bvh.wgsl) over the kernels' boxes.
@group(0) @binding(1) var<storage, read> point_nodes: array<BvhNode>;
// xyz the centre, w the radius, in the BVH's leaf order.
@group(0) @binding(2) var<storage, read> point_kernels: array<vec4<f32>>;
// n^3 samples (vector to the closest boundary point, signed distance: positive inside, NO_SEED
// until flood_point_grid.wgsl finds the point), then n^3 densities (x).
@group(0) @binding(3) var<storage, read_write> mesh_grid: array<vec4<f32>>;

const STACK_SIZE: u32 = 64u;
// Inside samples whose closest boundary point is not known yet (twin: NO_SEED).
const NO_SEED: f32 = 3.0e38;

fn box_gap(p: vec3<f32>, node: BvhNode) -> f32 {
    return length(max(max(node.lo - p, p - node.hi), vec3<f32>(0.0)));
}

// 8 x 8 x 1, as bake_mesh_grid.wgsl (lavapipe runs BVH walks far slower in 4 x 4 x 4 groups).
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = grid_params.size.xyz;
    if (any(id >= n)) {
        return;
    }
    let p = grid_sample_point(grid_params, id);
    // The smallest |p - c| - R (negative inside a ball), its kernel's centre; the kernel sum. A
    // box farther than the best (or than 0 once inside) holds neither a closer ball nor a
    // kernel that reaches p.
    var best = 3.4e38;
    var centre = p;
    var sum = 0.0;
    var stack = bvh_stack(0u, grid_params.counts.z == 0u);
    while (stack.top > 0u) {
        let node = point_nodes[bvh_pop(&stack)];
        if (box_gap(p, node) > max(best, 0.0)) {
            continue;
        }
        let count = node.count;
        let first = node.first;
        if (count > 0u) {
            for (var i = 0u; i < count; i++) {
                let k = point_kernels[first + i];
                let d = p - k.xyz;
                let r = length(d);
                if (r - k.w < best) {
                    best = r - k.w;
                    centre = k.xyz;
                }
                let t = 1.0 - dot(d, d) / (k.w * k.w);
                sum += select(0.0, t * t * t, t > 0.0);
            }
        } else {
            let near_first = box_gap(p, point_nodes[first]) <= box_gap(p, point_nodes[first + 1u]);
            bvh_push(&stack, select(first, first + 1u, near_first), select(first + 1u, first, near_first));
        }
    }
    // Outside (or on the boundary): to the closest ball's closest point, which is on the
    // boundary of the union (a point of another ball would be closer).
    var cell = vec4<f32>(0.0, 0.0, 0.0, NO_SEED);
    if (best >= 0.0) {
        let r = length(p - centre);
        cell = vec4<f32>(select(vec3<f32>(0.0), (centre - p) * (best / r), r > 0.0), -best);
    }
    let index = id.x + n.x * (id.y + n.y * id.z);
    mesh_grid[index] = cell;
    mesh_grid[n.x * n.y * n.z + index] = vec4<f32>(sum * grid_params.hi.w, 0.0, 0.0, 0.0);
}
