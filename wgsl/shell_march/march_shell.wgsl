// ShellMarch: per-pixel ray casting through the shell, made for speed at a measured error; CPU twin in src/methods/shell_march/march_shell.rs.
//
// Per pixel: the prisms of its 8x8 tile's list (binned on the CPU, src/methods/shell_march/tiles.rs),
// nearest first; every sample before the next prism's least distance is final. The intervals of
// the ray inside each prism, with the exact inverse map where the ray enters and leaves (from the
// crossing itself); between them (b, w), hence (s, t, w), interpolated in pieces checked against
// the exact map at two interior points; the samples of all intervals composited in depth order;
// bricks of the texel without opacity jumped over in whole steps; the ray stopped once its
// transmittance is below `min_transmittance`.
#include "shared/types.wgsl"
#include "shared/prism_map.wgsl"
#include "shared/shading.wgsl"

// Work per dispatch, in budget units (a sample is one; see the costs below): the pass is
// dispatched `shell_march_dispatches` times and each pixel resumes from `shell_march_state`,
// because lavapipe ends every loop of an invocation after 65535 iterations in all. Every
// dispatch costs llvmpipe about 10 ms at 128x128 even where all pixels are done (its private
// memory is set up per invocation), so the budget is as large as the loop limit allows for a
// typical unit (a few iterations; images bit-identical to 2048 on the example scenes).
override samples_per_dispatch: u32 = 8192u;
override min_transmittance: f32 = 1e-3;
// Whether some object filters by footprint (`filter: Footprint`): without, the filter's code is
// left out of the compiled kernel.
override filtering: bool = false;
const BOUND_COST: i32 = 2;
const PRISM_COST: i32 = 32;
const PIECE_COST: i32 = 16;
const EXACT_COST: i32 = 6;
// Intervals held at once (more are dropped and counted).
const MAX_ACTIVE: u32 = 16u;
// Most pieces an interval's interpolation is split into; beyond, pieces use the exact map.
const MAX_PIECES: u32 = 8u;
const MAX_SAMPLES: f32 = 1048576.0;
const MAX_ALPHA: f32 = 0.999999;
const FAR: f32 = 3.4e38;
// Raster depth is coarse far from the camera: opaque surfaces from the depth buffer are moved
// back by this relative margin (the objects' own bases are hit exactly).
const DEPTH_SLACK: f32 = 2e-3;

@group(0) @binding(0) var<uniform> frame: FrameParams;
// counts.w: 1 where empty space is skipped (a uniform, not an override constant: the same
// compiled kernel runs with and without it, so skipping is seen to change no pixel, bit for bit).
@group(0) @binding(1) var<uniform> shell_params: ReferenceParams;
// Per 8x8 tile, row by row: its first entry and count in `shell_tile_prisms` (prism indices, each
// tile's nearest first); per prism two rows of `shell_bounds`: its corner box's minimum with its
// least distance from the eye (w), and its maximum.
@group(0) @binding(2) var<storage, read> shell_tiles: array<vec2<u32>>;
@group(0) @binding(15) var<storage, read> shell_tile_prisms: array<u32>;
@group(0) @binding(16) var<storage, read> shell_bounds: array<vec4<f32>>;
// Per prism: the band of w outside which its texel is transparent over its uvs (x > y: all of
// it), from the occupancy pyramid (bake::occupancy::band).
@group(0) @binding(17) var<storage, read> shell_bands: array<vec2<f32>>;
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
// Samples taken, samples skipped, intervals dropped (a full list), pieces mapped exactly.
@group(0) @binding(13) var<storage, read_write> shell_march_counts: array<atomic<u32>>;
@group(0) @binding(14) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;
// Per object, its footprint filter; its texel's MIP levels from 1 on (s and t halved a level, w
// kept), f16 RGBA, each level's rows padded to 32 voxels (copied from the bake's layers).
@group(0) @binding(18) var<storage, read> shell_filters: array<ShellFilter>;
@group(0) @binding(19) var<storage, read> shell_mips: array<vec2<u32>>;
// The same places of the normals' levels, for objects lit per pixel.
@group(0) @binding(20) var<storage, read> shell_normal_mips: array<vec2<u32>>;

#include "shared/aov_depth.wgsl"

// Crossings of one prism with each invocation's ray (shared/shell_march_prism.wgsl): two faces,
// two per side, and the two triangles bounding its band.
const MAX_CROSSINGS: u32 = 10u;
var<workgroup> crossing_t: array<f32, 640>;
var<workgroup> crossing_c: array<vec4<f32>, 640>;
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
// The MIP level its samples read (fractional; 0: level 0 alone).
var<private> iv_level: array<f32, MAX_ACTIVE>;
var<private> held: u32;

var<private> ray: vec3<f32>;
// The pixel's cone: its width per unit distance along the ray.
var<private> cone: f32;
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

// The ray's distances into and out of the box [lo, hi] (empty where x > y).
fn slab(inv: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    let a = lo * inv;
    let b = hi * inv;
    let near = min(a, b);
    let far = max(a, b);
    return vec2<f32>(max(max(near.x, near.y), near.z), min(min(far.x, far.y), far.z));
}

// The direction through screen point (sx, sy), not normalised.
fn direction(sx: f32, sy: f32) -> vec3<f32> {
    return frame.forward.xyz + shell_params.right.xyz * sx + shell_params.up.xyz * sy;
}

// A pixel's width per unit distance at the image's centre (the widest of its two sides); off
// centre the ray is longer by |direction| and the pixel narrower by as much.
fn pixel_cone() -> f32 {
    return max(2.0 * length(shell_params.right.xyz) * frame.viewport.z, 2.0 * length(shell_params.up.xyz) * frame.viewport.w);
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
    let through = direction(sx, sy);
    ray = normalize(through);
    cone = pixel_cone() / length(through);
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
    let tiles_x = (size.x + 7u) / 8u;
    let list = shell_tiles[tile.y * tiles_x + tile.x];
    var next = 0u;
    var finished = !marching;
    while (marching) {
        // The next prism of the list whose box the ray meets where samples may remain.
        var front = FAR;
        var index = 0u;
        while (next < list.y) {
            let p = shell_tile_prisms[list.x + next];
            let lo = shell_bounds[2u * p];
            if (lo.w >= t_opaque) {
                next = list.y;
                break;
            }
            next += 1u;
            budget -= BOUND_COST;
            let hi = shell_bounds[2u * p + 1u];
            let span = slab(inv, lo.xyz, hi.xyz);
            if (span.x <= span.y && span.y >= t_resume && span.x < t_opaque) {
                front = lo.w;
                index = p;
                break;
            }
        }
        // No prism after this one comes nearer than its least distance.
        march_to(min(front, t_opaque));
        finished = transmittance < min_transmittance || (front >= t_opaque && next_held() >= t_opaque);
        if (finished || budget <= 0) {
            t_resume = max(t_resume, min(front, next_held()));
            break;
        }
        expand_prism(index);
    }
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
