// ShellMarch: per-pixel ray casting through the shell, made for speed at a measured error; CPU twin in src/methods/shell_march/march_shell.rs.
//
// Per 8x8 tile (one workgroup): one best-first walk of the BVH over prism bounds, nodes taken in
// order of their distance from the eye (a bound on every pixel's ray distance in them) and kept
// only where they meet the tile's frustum, in workgroup memory; its leaves are handed to all
// pixels in batches, after which every sample before the nearest unvisited box is known. Per
// pixel: the
// intervals of the ray inside each prism, with the exact inverse map where the ray enters and
// leaves (from the crossing itself); between them (b, w), hence (s, t, w), interpolated in pieces
// checked against the exact map at two interior points; the samples of all intervals composited
// in depth order; bricks of the texel without opacity jumped over in whole steps; the ray stopped
// once its transmittance is below `min_transmittance`.
#include "shared/types.wgsl"
#include "shared/prism_map.wgsl"
#include "shared/shading.wgsl"
// Only bvh.wgsl's node layout is used: the walk here is best-first (the tile heap below), not its stack.
const STACK_SIZE: u32 = 1u;
#include "shared/bvh.wgsl"

// Work per dispatch, in budget units (a sample is one; see the costs below): the pass is
// dispatched `shell_march_dispatches` times and each pixel resumes from `shell_march_state`,
// because lavapipe ends every loop of an invocation after 65535 iterations in all. Every
// dispatch costs llvmpipe about 10 ms at 128x128 even where all pixels are done (its private
// memory is set up per invocation), so the budget is as large as the loop limit allows for a
// typical unit (a few iterations; images bit-identical to 2048 on the example scenes).
override samples_per_dispatch: u32 = 8192u;
override min_transmittance: f32 = 1e-3;
override skip_empty: bool = true;
const NODE_COST: i32 = 4;
const PRISM_COST: i32 = 32;
const PIECE_COST: i32 = 16;
const EXACT_COST: i32 = 6;
// Pending BVH nodes of a tile, and intervals held at once (more are dropped and counted).
const HEAP_SIZE: u32 = 256u;
const MAX_ACTIVE: u32 = 16u;
// Leaves handed to the pixels at once, and the prisms after which a batch is closed: a small batch
// keeps the intervals held few, a larger one the barriers rare.
const BATCH_LEAVES: u32 = 16u;
const BATCH_PRISMS: u32 = 8u;
// Most pieces an interval's interpolation is split into; beyond, pieces use the exact map.
const MAX_PIECES: u32 = 8u;
const MAX_SAMPLES: f32 = 1048576.0;
const MAX_ALPHA: f32 = 0.999999;
const FAR: f32 = 3.4e38;
// Raster depth is coarse far from the camera: opaque surfaces from the depth buffer are moved
// back by this relative margin (the objects' own bases are hit exactly).
const DEPTH_SLACK: f32 = 2e-3;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> shell_params: ReferenceParams;
@group(0) @binding(2) var<storage, read> shell_nodes: array<BvhNode>;
@group(0) @binding(3) var<storage, read> shell_prisms: array<ReferencePrism>;
@group(0) @binding(4) var<storage, read> shell_objects: array<ReferenceObject>;
@group(0) @binding(5) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(6) var<storage, read> vertex_frames: array<VertexFrame>;
@group(0) @binding(7) var<storage, read> texel_atlas: array<u32>;
@group(0) @binding(8) var<storage, read> normal_atlas: array<u32>;
// Per object, levels of bricks of 4, 16 and 64 voxels: non-zero where some voxel within one
// voxel of the brick (the trilinear filter's reach from half a voxel outside it) has opacity.
@group(0) @binding(9) var<storage, read> shell_occupancy: array<u32>;
@group(0) @binding(10) var depth: texture_depth_2d;
@group(0) @binding(11) var shell_march_rgba: texture_storage_2d<rgba32float, write>;
@group(0) @binding(12) var<storage, read_write> shell_march_state: array<ReferenceState>;
// Samples taken, samples skipped, intervals or nodes dropped (a full list), pieces mapped exactly.
@group(0) @binding(13) var<storage, read_write> shell_march_counts: array<atomic<u32>>;
@group(0) @binding(14) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;

#include "shared/aov_depth.wgsl"

// The tile's walk: a binary heap of nodes on their distance from the eye, the frustum's side
// planes (through the eye), and the leaves of the current batch with the heap's front after it.
// Kept by invocation 0; the others read the batch between barriers.
var<workgroup> heap_t: array<f32, HEAP_SIZE>;
var<workgroup> heap_node: array<u32, HEAP_SIZE>;
var<workgroup> heap_count: u32;
var<workgroup> planes: array<vec3<f32>, 4>;
var<workgroup> batch: array<u32, BATCH_LEAVES>;
var<workgroup> batch_count: u32;
var<workgroup> batch_front: f32;
// Pixels of the tile still marching in this dispatch; the least resume distance and the largest
// opaque distance among them (f32 bits: non-negative floats order as their bits).
var<workgroup> tile_active: atomic<u32>;
var<workgroup> tile_resume: atomic<u32>;
var<workgroup> tile_opaque: atomic<u32>;
var<workgroup> tile_go: bool;
// Crossings of one prism with each invocation's ray (shared/shell_march_prism.wgsl): two faces, two per side.
const MAX_CROSSINGS: u32 = 8u;
var<workgroup> crossing_t: array<f32, 512>;
var<workgroup> crossing_c: array<vec4<f32>, 512>;
var<private> crossing_count: u32;
// This invocation's index in the workgroup.
var<private> slot: u32;

// The intervals held: span, sample spacing and count, next sample, and the current piece of the
// interpolation (its span and (b, w) at both ends, or `exact`).
var<private> iv_prism: array<u32, MAX_ACTIVE>;
var<private> iv_t0: array<f32, MAX_ACTIVE>;
var<private> iv_t1: array<f32, MAX_ACTIVE>;
var<private> iv_h: array<f32, MAX_ACTIVE>;
var<private> iv_n: array<u32, MAX_ACTIVE>;
var<private> iv_k: array<u32, MAX_ACTIVE>;
var<private> iv_next: array<f32, MAX_ACTIVE>;
var<private> iv_pieces: array<u32, MAX_ACTIVE>;
var<private> iv_piece: array<u32, MAX_ACTIVE>;
var<private> iv_exact: array<bool, MAX_ACTIVE>;
var<private> iv_ta: array<f32, MAX_ACTIVE>;
var<private> iv_tb: array<f32, MAX_ACTIVE>;
var<private> iv_ca: array<vec4<f32>, MAX_ACTIVE>;
var<private> iv_cb: array<vec4<f32>, MAX_ACTIVE>;
var<private> iv_c1: array<vec4<f32>, MAX_ACTIVE>;
var<private> held: u32;

var<private> ray: vec3<f32>;
var<private> t_near: f32;
var<private> t_resume: f32;
var<private> t_opaque: f32;
var<private> budget: i32;
var<private> rgb: vec3<f32>;
var<private> transmittance: f32;
var<private> pixel: u32;
var<private> opaque_found: bool;
var<private> taken: u32;
var<private> skipped: u32;
var<private> dropped: u32;
var<private> exact_pieces: u32;

#include "shared/shell_march_prism.wgsl"
#include "shared/shell_march_samples.wgsl"

fn slab(inv: vec3<f32>, node: BvhNode) -> vec2<f32> {
    let a = node.lo * inv;
    let b = node.hi * inv;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec2<f32>(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}


// Whether the box [lo, hi] may meet the tile's frustum: on the inner side of all four planes.
fn in_frustum(lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let c = 0.5 * (lo + hi);
    let r = 0.5 * (hi - lo);
    var inside = true;
    for (var i = 0u; i < 4u; i++) {
        inside = inside && dot(planes[i], c) + dot(abs(planes[i]), r) >= 0.0;
    }
    return inside;
}

// Queues node n if it meets the frustum where some pixel of the tile may still take samples (a
// binary heap on the box's distance from the eye, a lower bound of any unit ray's t in it).
fn push_node(n: u32, resume: f32, opaque: f32) {
    let node = shell_nodes[n];
    let near = length(clamp(vec3<f32>(0.0), node.lo, node.hi));
    let far = length(max(abs(node.lo), abs(node.hi)));
    if (far < resume || near >= opaque || !in_frustum(node.lo, node.hi)) {
        return;
    }
    if (heap_count >= HEAP_SIZE) {
        dropped += 1u;
        return;
    }
    var i = heap_count;
    heap_count += 1u;
    while (i > 0u && heap_t[(i - 1u) / 2u] > near) {
        heap_t[i] = heap_t[(i - 1u) / 2u];
        heap_node[i] = heap_node[(i - 1u) / 2u];
        i = (i - 1u) / 2u;
    }
    heap_t[i] = near;
    heap_node[i] = n;
}

// Takes the nearest queued node off the heap.
fn pop_node() -> u32 {
    let top = heap_node[0];
    heap_count -= 1u;
    let t = heap_t[heap_count];
    let n = heap_node[heap_count];
    var i = 0u;
    loop {
        var c = 2u * i + 1u;
        if (c >= heap_count) {
            break;
        }
        if (c + 1u < heap_count && heap_t[c + 1u] < heap_t[c]) {
            c += 1u;
        }
        if (heap_t[c] >= t) {
            break;
        }
        heap_t[i] = heap_t[c];
        heap_node[i] = heap_node[c];
        i = c;
    }
    heap_t[i] = t;
    heap_node[i] = n;
    return top;
}

// Invocation 0: the next batch of leaves, nearest first, and the heap's front after them.
fn next_batch() {
    let resume = bitcast<f32>(atomicLoad(&tile_resume));
    let opaque = bitcast<f32>(atomicLoad(&tile_opaque));
    batch_count = 0u;
    var prisms = 0u;
    while (heap_count > 0u && batch_count < BATCH_LEAVES && prisms < BATCH_PRISMS) {
        let n = pop_node();
        let node = shell_nodes[n];
        if (node.count > 0u) {
            batch[batch_count] = n;
            batch_count += 1u;
            prisms += node.count;
        } else {
            push_node(node.first, resume, opaque);
            push_node(node.first + 1u, resume, opaque);
        }
    }
    batch_front = select(FAR, heap_t[0], heap_count > 0u);
}

// The direction through screen point (sx, sy), not normalised.
fn direction(sx: f32, sy: f32) -> vec3<f32> {
    return frame.forward.xyz + shell_params.right.xyz * sx + shell_params.up.xyz * sy;
}

// Invocation 0: the tile's frustum and its root.
fn start_tile(tile: vec2<u32>) {
    let x0 = 2.0 * f32(tile.x * 8u) * frame.viewport.z - 1.0;
    let x1 = 2.0 * f32(tile.x * 8u + 8u) * frame.viewport.z - 1.0;
    let y0 = 1.0 - 2.0 * f32(tile.y * 8u) * frame.viewport.w;
    let y1 = 1.0 - 2.0 * f32(tile.y * 8u + 8u) * frame.viewport.w;
    let corners = array<vec3<f32>, 4>(direction(x0, y0), direction(x1, y0), direction(x1, y1), direction(x0, y1));
    let centre = direction(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    for (var i = 0u; i < 4u; i++) {
        let n = cross(corners[i], corners[(i + 1u) % 4u]);
        planes[i] = select(-n, n, dot(n, centre) >= 0.0);
    }
    heap_count = 0u;
    if (shell_params.counts.x > 0u) {
        push_node(0u, bitcast<f32>(atomicLoad(&tile_resume)), bitcast<f32>(atomicLoad(&tile_opaque)));
    }
}

// This pixel's share of a batch: the prisms of the leaves its ray crosses where samples may still
// be taken join the held intervals, and everything before the heap's front is composited.
fn march_batch(inv: vec3<f32>) {
    for (var b = 0u; b < batch_count; b++) {
        budget -= NODE_COST;
        let node = shell_nodes[batch[b]];
        let span = slab(inv, node);
        if (span.x <= span.y && span.y >= t_resume && span.x < t_opaque) {
            for (var p = 0u; p < node.count; p++) {
                expand_prism(node.first + p);
            }
        }
    }
    march_to(min(batch_front, t_opaque));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32, @builtin(workgroup_id) tile: vec3<u32>) {
    let size = vec2<u32>(frame.viewport.xy);
    pixel = id.y * size.x + id.x;
    slot = local;
    let inside = id.x < size.x && id.y < size.y;
    var state = ReferenceState(vec4<f32>(0.0), vec4<f32>(0.0, 0.0, 1.0, 0.0));
    if (inside) {
        state = shell_march_state[pixel];
    }
    // resume: x the first sample not composited, y 1 once started, z 1 once finished.
    var marching = state.resume.z == 0.0;
    let sx = 2.0 * (f32(id.x) + 0.5) * frame.viewport.z - 1.0;
    let sy = 1.0 - 2.0 * (f32(id.y) + 0.5) * frame.viewport.w;
    ray = normalize(direction(sx, sy));
    let cos_d = dot(ray, frame.forward.xyz);
    let near = shell_params.right.w;
    let far = shell_params.up.w;
    t_near = near / cos_d;
    rgb = state.color.rgb;
    transmittance = state.color.a;
    t_resume = state.resume.x;
    if (state.resume.y == 0.0) {
        rgb = vec3<f32>(0.0);
        transmittance = 1.0;
        t_resume = t_near;
    }
    // Opaque surfaces already drawn (base surfaces) stop the ray.
    t_opaque = FAR;
    if (inside) {
        let z = textureLoad(depth, vec2<i32>(id.xy), 0);
        if (z < 1.0) {
            t_opaque = far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK);
        }
    }
    budget = i32(samples_per_dispatch);
    let inv = 1.0 / ray;
    held = 0u;
    if (local == 0u) {
        atomicStore(&tile_active, 0u);
        atomicStore(&tile_resume, bitcast<u32>(FAR));
        atomicStore(&tile_opaque, 0u);
    }
    workgroupBarrier();
    if (marching) {
        atomicAdd(&tile_active, 1u);
        atomicMin(&tile_resume, bitcast<u32>(max(t_resume, 0.0)));
        atomicMax(&tile_opaque, bitcast<u32>(t_opaque));
    }
    workgroupBarrier();
    if (local == 0u && atomicLoad(&tile_active) > 0u) {
        start_tile(tile.xy);
    }
    var finished = false;
    loop {
        workgroupBarrier();
        if (local == 0u) {
            tile_go = atomicLoad(&tile_active) > 0u;
            if (tile_go) {
                next_batch();
            }
        }
        if (!workgroupUniformLoad(&tile_go)) {
            break;
        }
        if (marching) {
            march_batch(inv);
            let front = batch_front;
            finished = transmittance < min_transmittance || (front >= t_opaque && next_held() >= t_opaque);
            if (finished || budget <= 0) {
                marching = false;
                t_resume = max(t_resume, min(front, next_held()));
                atomicSub(&tile_active, 1u);
            }
        }
    }
    // Invocation 0 counts the tile's dropped nodes even where its own pixel was done.
    if (taken > 0u) {
        atomicAdd(&shell_march_counts[0], taken);
    }
    if (skipped > 0u) {
        atomicAdd(&shell_march_counts[1], skipped);
    }
    if (dropped > 0u) {
        atomicAdd(&shell_march_counts[2], dropped);
    }
    if (exact_pieces > 0u) {
        atomicAdd(&shell_march_counts[3], exact_pieces);
    }
    if (!inside || state.resume.z != 0.0) {
        return;
    }
    shell_march_state[pixel] = ReferenceState(vec4<f32>(rgb, transmittance), vec4<f32>(t_resume, 1.0, select(0.0, 1.0, finished), 0.0));
    textureStore(shell_march_rgba, vec2<i32>(id.xy), vec4<f32>(rgb * frame.light_color.rgb, 1.0 - transmittance));
}
