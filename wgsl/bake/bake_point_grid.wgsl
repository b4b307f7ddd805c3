// Bakes a point set (hypertexture Points objects) into a grid: per sample the vector to the closest point of the union of its kernels' balls and the signed distance to it (positive inside), then the sum of the kernels (1 - r^2/R^2)^3 over the saturation; CPU twin src/cpu/bake_point_grid.rs.
#include "shared/types.wgsl"
#include "shared/bvh.wgsl"

// lo, hi: the grid's corners (hi.w: 1 / saturation); counts: samples per axis, points, BVH
// nodes; size: samples per axis.
@group(0) @binding(0) var<uniform> grid_params: MeshGridParams;
// The bytes of a `ReferenceNode` (mesh::bvh::flat_bvh) over the kernels' boxes, read with
// integer counts (as bake_mesh_grid.wgsl does).
struct BvhNode {
    lo: vec3<f32>,
    // Kernels in the leaf (0: inner node).
    count: u32,
    hi: vec3<f32>,
    // First kernel (leaf) or first child (inner; the second follows it).
    first: u32,
}

@group(0) @binding(1) var<storage, read> point_nodes: array<BvhNode>;
// xyz the centre, w the radius, in the BVH's leaf order.
@group(0) @binding(2) var<storage, read> point_kernels: array<vec4<f32>>;
// n^3 samples (vector to the closest ball surface point, signed distance), then n^3 densities (x).
@group(0) @binding(3) var<storage, read_write> mesh_grid: array<vec4<f32>>;

const STACK_SIZE: u32 = 64u;

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
    let lo = grid_params.lo.xyz;
    let p = lo + (grid_params.hi.xyz - lo) * (vec3<f32>(id) / vec3<f32>(n - vec3<u32>(1u)));
    // The smallest |p - c| - R (negative inside a ball: minus the deepest ball's depth), its
    // kernel's centre; the kernel sum and its gradient. A box farther than the best (or than 0
    // once inside) holds neither a closer ball nor a kernel that reaches p.
    var best = 3.4e38;
    var centre = p;
    var sum = 0.0;
    var gradient = vec3<f32>(0.0);
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
                if (t > 0.0) {
                    sum += t * t * t;
                    gradient -= d * (6.0 * t * t / (k.w * k.w));
                }
            }
        } else {
            let near_first = box_gap(p, point_nodes[first]) <= box_gap(p, point_nodes[first + 1u]);
            bvh_push(&stack, select(first, first + 1u, near_first), select(first + 1u, first, near_first));
        }
    }
    // Outside: towards the closest ball. Inside: outwards, down the kernel sum's gradient (away
    // from the deepest ball's centre where the gradient vanishes), as far as the deepest ball's
    // depth (a lower bound of the distance to the boundary).
    var out = normalize(p - centre);
    if (dot(p - centre, p - centre) == 0.0) {
        out = vec3<f32>(0.0);
    }
    if (best < 0.0 && dot(gradient, gradient) > 1e-12) {
        out = -normalize(gradient);
    }
    let index = id.x + n.x * (id.y + n.y * id.z);
    mesh_grid[index] = vec4<f32>(out * -best, -best);
    mesh_grid[n.x * n.y * n.z + index] = vec4<f32>(sum * grid_params.hi.w, 0.0, 0.0, 0.0);
}
