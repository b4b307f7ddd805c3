// Bakes a mesh into a grid (hypertexture mesh objects, mesh texels): per sample the vector to the closest surface point and the signed distance (positive inside, by ray parity voted over three directions; no parity for shells) of the union of its closed parts, the largest inside distance, and for coloured meshes the colour at the closest point; CPU twin src/cpu/bake_mesh_grid.rs.
#include "shared/types.wgsl"
#include "shared/bvh.wgsl"
#include "shared/grid_sample.wgsl"

@group(0) @binding(0) var<uniform> grid_params: MeshGridParams;
// `BvhNode`s (shared/bvh.wgsl): one BVH per closed part, concatenated (children and triangles
// indexed in the whole).
@group(0) @binding(1) var<storage, read> mesh_nodes: array<BvhNode>;
// Per part: x its root node.
@group(0) @binding(5) var<storage, read> mesh_parts: array<vec4<u32>>;
// Three corners per triangle, in leaf order.
@group(0) @binding(2) var<storage, read> mesh_triangles: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> mesh_grid: array<vec4<f32>>;
// The largest inside distance, as u32 bits (non-negative floats order as their bits).
@group(0) @binding(4) var<storage, read_write> mesh_depth: array<atomic<u32>>;
// Coloured meshes (mesh texels of OBJs with vertex colours): the corners' colours in the order
// of mesh_triangles, and per sample the colour at its closest surface point.
@group(0) @binding(6) var<storage, read> mesh_corner_colors: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> mesh_colors: array<vec4<f32>>;

override colored: bool = false;

const STACK_SIZE: u32 = 64u;
// Parity rays leave along these directions (twin: DIRECTIONS): skewed off the axes so that they
// do not run along the faces and edges of axis-aligned meshes; three votes outvote a ray that
// grazes an edge (counted by both or neither of its triangles).
const DIR0: vec3<f32> = vec3<f32>(0.99947, 0.02718, 0.01732);
const DIR1: vec3<f32> = vec3<f32>(0.01414, 0.99935, 0.03317);
const DIR2: vec3<f32> = vec3<f32>(0.03162, 0.02236, 0.99925);

fn corner(t: u32, k: u32) -> vec3<f32> {
    return mesh_triangles[3u * t + k].xyz;
}

fn on_segment(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let ab = b - a;
    let len2 = dot(ab, ab);
    if (len2 <= 0.0) {
        return a;
    }
    return a + ab * clamp(dot(p - a, ab) / len2, 0.0, 1.0);
}

// The closest point of triangle abc to p, by the Voronoi regions of its corners, edges and face.
fn on_triangle(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return a;
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return b;
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return c;
    }
    let vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        return a + ab * (d1 / (d1 - d3));
    }
    let vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let sum = va + vb + vc;
    if (sum <= 0.0) {
        // A sliver with no face region: its closest point is on an edge.
        let q0 = on_segment(p, a, b);
        let q1 = on_segment(p, b, c);
        let q2 = on_segment(p, c, a);
        var q = q0;
        if (dot(q1 - p, q1 - p) < dot(q - p, q - p)) {
            q = q1;
        }
        if (dot(q2 - p, q2 - p) < dot(q - p, q - p)) {
            q = q2;
        }
        return q;
    }
    return a + ab * (vb / sum) + ac * (vc / sum);
}

fn box_distance2(p: vec3<f32>, node: BvhNode) -> f32 {
    let q = max(max(node.lo - p, p - node.hi), vec3<f32>(0.0));
    return dot(q, q);
}

struct Closest {
    point: vec3<f32>,
    triangle: u32,
}

// The closest surface point to p and its triangle: the BVH walked nearer child first, skipping
// boxes farther than the best so far.
fn closest_point(p: vec3<f32>, root: u32) -> Closest {
    var best = 3.4e38;
    var point = p;
    var triangle = 0u;
    var stack = bvh_stack(root, false);
    while (stack.top > 0u) {
        let node = mesh_nodes[bvh_pop(&stack)];
        if (box_distance2(p, node) >= best) {
            continue;
        }
        let count = node.count;
        let first = node.first;
        if (count > 0u) {
            for (var i = 0u; i < count; i++) {
                let t = first + i;
                let q = on_triangle(p, corner(t, 0u), corner(t, 1u), corner(t, 2u));
                let d2 = dot(q - p, q - p);
                if (d2 < best) {
                    best = d2;
                    point = q;
                    triangle = t;
                }
            }
        } else {
            let near_first = box_distance2(p, mesh_nodes[first]) <= box_distance2(p, mesh_nodes[first + 1u]);
            bvh_push(&stack, select(first, first + 1u, near_first), select(first + 1u, first, near_first));
        }
    }
    return Closest(point, triangle);
}

// The colour at q, a point of triangle t: its corners' colours by barycentric weights.
fn color_at(q: vec3<f32>, t: u32) -> vec4<f32> {
    let a = corner(t, 0u);
    let e1 = corner(t, 1u) - a;
    let e2 = corner(t, 2u) - a;
    let e = q - a;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let det = d11 * d22 - d12 * d12;
    var w = vec3<f32>(1.0 / 3.0);
    if (det > 1e-30 * d11 * d22) {
        let v = (d22 * dot(e, e1) - d12 * dot(e, e2)) / det;
        let u = (d11 * dot(e, e2) - d12 * dot(e, e1)) / det;
        w = clamp(vec3<f32>(1.0 - v - u, v, u), vec3<f32>(0.0), vec3<f32>(1.0));
        w /= max(w.x + w.y + w.z, 1e-30);
    }
    let c = mesh_corner_colors[3u * t] * w.x + mesh_corner_colors[3u * t + 1u] * w.y
        + mesh_corner_colors[3u * t + 2u] * w.z;
    return vec4<f32>(c.rgb, 1.0);
}

// Whether the ray o + t d (t > 0) crosses triangle t (Moller-Trumbore).
fn crosses(o: vec3<f32>, d: vec3<f32>, t: u32) -> bool {
    let a = corner(t, 0u);
    let e1 = corner(t, 1u) - a;
    let e2 = corner(t, 2u) - a;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if (det == 0.0) {
        return false;
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = dot(tv, pv) * inv;
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dot(e2, qv) * inv > 0.0;
}

// The number of triangles the ray from o along d crosses, odd when o is inside.
fn crossings(o: vec3<f32>, d: vec3<f32>, root: u32) -> u32 {
    let inv = 1.0 / d;
    var hits = 0u;
    var stack = bvh_stack(root, false);
    while (stack.top > 0u) {
        let node = mesh_nodes[bvh_pop(&stack)];
        let a = (node.lo - o) * inv;
        let b = (node.hi - o) * inv;
        let lo = min(a, b);
        let hi = max(a, b);
        if (max(max(lo.x, lo.y), lo.z) > min(min(hi.x, hi.y), hi.z) || min(min(hi.x, hi.y), hi.z) < 0.0) {
            continue;
        }
        let count = node.count;
        let first = node.first;
        if (count > 0u) {
            for (var i = 0u; i < count; i++) {
                hits += u32(crosses(o, d, first + i));
            }
        } else {
            bvh_push(&stack, first, first + 1u);
        }
    }
    return hits;
}

// 8 x 8 x 1: lavapipe ran this kernel about 300 times slower with 4 x 4 x 4 workgroups.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = grid_params.size.xyz;
    if (any(id >= n)) {
        return;
    }
    let p = grid_sample_point(grid_params, id);
    let parity = grid_params.size.w != 0u;
    // The union of the parts: the largest signed distance of any part.
    var best = vec4<f32>(0.0, 0.0, 0.0, -3.4e38);
    var best_closest = Closest(p, 0u);
    for (var part = 0u; part < grid_params.counts.w; part++) {
        let root = mesh_parts[part].x;
        let closest = closest_point(p, root);
        let q = closest.point;
        var votes = 0u;
        if (parity) {
            votes = (crossings(p, DIR0, root) & 1u) + (crossings(p, DIR1, root) & 1u)
                + (crossings(p, DIR2, root) & 1u);
        }
        let dist = length(q - p);
        let signed = select(-dist, dist, votes >= 2u);
        if (signed > best.w) {
            best = vec4<f32>(q - p, signed);
            best_closest = closest;
        }
    }
    let index = id.x + n.x * (id.y + n.y * id.z);
    mesh_grid[index] = best;
    if (colored) {
        mesh_colors[index] = color_at(best_closest.point, best_closest.triangle);
    }
    let inside = best.w > 0.0;
    let dist = best.w;
    if (inside) {
        atomicMax(&mesh_depth[0], bitcast<u32>(dist));
    }
}
