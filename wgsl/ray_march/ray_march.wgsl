// Hypertexture ray marching (Gilet & Dischler 2009): one thread per pixel marches the object's enlarged bounds, or the segments depth peeling found, front to back, resumable across dispatches; CPU twin src/methods/ray_march/march.rs.
#include "shared/types.wgsl"
#include "shared/hypertexture.wgsl"
#include "shared/segments.wgsl"
#include "shared/march.wgsl"

// `RayMarch(segments: DepthPeeling(..))`: march only the segments in `segment_bounds`
// (peel_segments.wgsl), in order, instead of the whole span of the bounds.
override peeling: bool = false;

// Work per dispatch is bounded by `hyper.budget` (density evaluations): the pass is dispatched
// `ray_march_dispatches` times and each pixel resumes from `ray_march_state`. Lavapipe ends every
// loop of an invocation after 65535 iterations in all (one per sample, per noise, per shadow
// sample), and real GPUs have watchdogs, so no single dispatch may march a whole long ray.

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<storage, read> hyper_noises: array<HyperNoise>;
@group(0) @binding(3) var<storage, read> transfer_tables: array<f32>;
@group(0) @binding(4) var depth: texture_depth_2d;
@group(0) @binding(5) var<storage, read_write> ray_march_state: array<MarchState>;
// Mesh objects: the baked grid and its largest inside distance (f32 bits); stand-ins otherwise.
@group(0) @binding(6) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> mesh_depth: array<u32>;
// Depth peeling's segments (stand-ins without it); the marcher keeps its segment in word 0.
@group(0) @binding(8) var<uniform> segments: SegmentParams;
@group(0) @binding(9) var<storage, read_write> segment_bounds: array<u32>;
// `shadows: LightVolume(..)`: the object's light volume (stand-ins otherwise).
@group(0) @binding(10) var<uniform> light_grid: LightVolumeParams;
@group(0) @binding(11) var<storage, read> light_volume: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = viewport_pixel(id.xy);
    if (pixel == NO_PIXEL) {
        return;
    }
    let state = ray_march_state[pixel];
    if (state.resume.z > 0.0) {
        return;
    }
    let d = pixel_direction(id.xy);
    // The ray in object space: x(t) = origin + dir t is the local point of world point d t.
    let origin = hyper.to_local[3].xyz;
    let dir = (hyper.to_local * vec4<f32>(d, 0.0)).xyz;
    let range = march_range(id.xy, d, origin, dir);
    let t0 = range.x;
    let h = range.y;
    let n = u32(range.z);
    var rgb = state.color.rgb;
    var transmittance = 1.0 - state.color.a;
    var k = u32(state.resume.x);
    // Adaptive stride (`RayMarch(adaptive: ..)`): sample k was reached from sample k - stride;
    // in empty space the stride doubles up to `hyper.budget.w` fine steps, and a strided sample
    // that finds matter is dropped for the samples after k - stride, taken one by one. Only
    // stride-1 samples are composited, so each weighs one fine step h.
    var stride = u32(-state.resume.z) + 1u;
    let max_stride = max(hyper.budget.w, 1u);
    var budget = i32(hyper.budget.x);
    let worst = i32(hyper.budget.z);
    // Most samples of the bounds are far from the object: their density is 0.
    let empty = hyper_color(0.0);
    // The bounds are one segment. With depth peeling, segment i is [entry i, exit i] of this
    // pixel (an exit not found: the bounds' exit), and only the samples above inside it are
    // taken: the same samples as the bounds march, less those in empty space.
    var segment = 0u;
    var segment_count = 1u;
    let base = pixel * segment_stride();
    if (peeling) {
        segment = segment_bounds[base];
        segment_count = segments.counts.z;
    }
    while (segment < segment_count && transmittance >= MIN_TRANSMITTANCE && budget >= worst) {
        var end = n;
        if (peeling) {
            let entry = segment_bounds[base + 2u + 2u * segment];
            if (entry == NO_DEPTH || n == 0u) {
                segment = segment_count;
                break;
            }
            // Samples t0 + (k + 0.5) h within [entry, exit].
            let first = ceil((bitcast<f32>(entry) - t0) / h - 0.5);
            let last = floor((bitcast<f32>(segment_bounds[base + 3u + 2u * segment]) - t0) / h - 0.5);
            let first_k = u32(clamp(first, 0.0, f32(n)));
            if (k < first_k) {
                k = first_k;
                stride = 1u;
            }
            end = u32(clamp(last + 1.0, 0.0, f32(n)));
        }
        while (k < end && transmittance >= MIN_TRANSMITTANCE && budget >= worst) {
            let x = origin + dir * (t0 + (f32(k) + 0.5) * h);
            let density = hyper_density(x);
            var rgba = empty;
            if (density > 0.0) {
                rgba = hyper_color(density);
            }
            budget -= 1;
            if (density > 0.0 && stride > 1u) {
                k = k + 1u - stride;
                stride = 1u;
                continue;
            }
            if (rgba.a > 1e-6) {
                let alpha = step_alpha(rgba.a, h);
                var colour = rgba.rgb;
                if (phong) {
                    let shaded = shade(x, d, colour);
                    colour = shaded.xyz;
                    budget -= i32(shaded.w);
                }
                rgb += colour * alpha * transmittance;
                transmittance *= 1.0 - alpha;
            }
            stride = select(1u, min(2u * stride, max_stride), density <= 0.0);
            // The last sample of a stretch is always taken.
            if (k + stride >= end && k + 1u < end) {
                stride = end - 1u - k;
            }
            k += stride;
        }
        if (k < end) {
            break;
        }
        // A stride may overshoot the stretch: the next one begins afresh at its first sample.
        k = end;
        stride = 1u;
        segment++;
    }
    if (peeling) {
        segment_bounds[base] = segment;
    }
    let finished = segment >= segment_count || transmittance < MIN_TRANSMITTANCE;
    // resume: next sample, density evaluations so far, 1 once finished else 1 - stride,
    // evaluations that ran the noises.
    let evaluations = state.resume.y + f32(i32(hyper.budget.x) - budget);
    let progress = select(1.0 - f32(stride), 1.0, finished);
    ray_march_state[pixel] = MarchState(
        vec4<f32>(rgb, 1.0 - transmittance),
        vec4<f32>(f32(k), evaluations, progress, state.resume.w + f32(noised_evaluations)),
    );
}
