// Hypertexture ray marching (Gilet & Dischler 2009): one thread per pixel marches the object's enlarged bounds, or the segments depth peeling found, front to back, resumable across dispatches; CPU twin src/cpu/ray_march.rs.
#include "shared/types.wgsl"
#include "shared/hypertexture.wgsl"
#include "shared/segments.wgsl"

// Shading, compiled out when off (set per object from `RayMarch(shading: ...)`): Phong with the
// density gradient by central differences (six more density evaluations), and a secondary ray
// towards the light for shadows.
override phong: bool = false;
override shadows: bool = false;
// `RayMarch(segments: DepthPeeling(..))`: march only the segments in `segment_bounds`
// (peel_segments.wgsl), in order, instead of the whole span of the bounds.
override peeling: bool = false;

// Work per dispatch is bounded by `hyper.budget` (density evaluations): the pass is dispatched
// `ray_march_dispatches` times and each pixel resumes from `ray_march_state`. Lavapipe ends every
// loop of an invocation after 65535 iterations in all (one per sample, per noise, per shadow
// sample), and real GPUs have watchdogs, so no single dispatch may march a whole long ray.
const MIN_TRANSMITTANCE: f32 = 1e-4;
const MAX_ALPHA: f32 = 0.999999;
// Raster depth is coarse far from the camera: opaque surfaces are moved back by this margin.
const DEPTH_SLACK: f32 = 2e-3;

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

// The step-corrected opacity shared by every method: 1 - (1 - a)^(step / opacity_length).
fn step_alpha(a: f32, step: f32) -> f32 {
    return 1.0 - exp2(log2(1.0 - min(a, MAX_ALPHA)) * step / hyper.bounds_max.w);
}

// Phong as the Reference method shades it, at x (object space): the outward normal from the
// world-space density gradient by central differences (facing the viewer where the gradient
// vanishes), and with `shadows` the transmittance towards the light up to the bounds' exit, which
// dims the diffuse and specular terms. Gradient and shadow samples share one loop so the density
// is compiled once for both (lavapipe makes a much slower kernel of several inlined copies).
// Returns the colour (xyz) and the density evaluations it took (w).
fn shade(x: vec3<f32>, ray: vec3<f32>, albedo: vec3<f32>) -> vec4<f32> {
    let e = hyper.march.y;
    var l = vec3<f32>(0.0);
    var h = 0.0;
    var n = 0u;
    if (shadows) {
        l = (hyper.to_local * vec4<f32>(frame.light_dir.xyz, 0.0)).xyz;
        let exit = max(bounds_span(x, l).y, 0.0);
        n = u32(clamp(ceil(exit / hyper.march.x), 1.0, f32(hyper.budget.y)));
        h = exit / f32(n);
    }
    var g = vec3<f32>(0.0);
    var lit = 1.0;
    var j = 0u;
    while (j < 6u + n && lit >= MIN_TRANSMITTANCE) {
        let axis = min(j / 2u, 2u);
        let side = select(-1.0, 1.0, (j & 1u) == 0u);
        var p = x + l * ((f32(j) - 5.5) * h);
        if (j < 6u) {
            p = x + hyper.to_local[axis].xyz * (side * e);
        }
        let density = hyper_density(p);
        if (j < 6u) {
            g[axis] += side * density;
        } else {
            lit *= 1.0 - step_alpha(hyper_opacity(density), h);
        }
        j++;
    }
    let len = length(g);
    let normal = select(-ray, -g / len, len > 1e-12);
    let light = frame.light_dir.xyz;
    let ambient = frame.light_dir.w;
    let half_way = normalize(light - ray);
    let diffuse = max(dot(normal, light), 0.0);
    let specular = select(0.0, 0.25 * pow(max(dot(normal, half_way), 0.0), 32.0), diffuse > 0.0);
    let colour = albedo * (ambient + (1.0 - ambient) * diffuse * lit) + vec3<f32>(specular * lit);
    return vec4<f32>(colour, f32(j));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let pixel = id.y * size.x + id.x;
    let state = ray_march_state[pixel];
    if (state.resume.z > 0.0) {
        return;
    }
    let forward = frame.forward.xyz;
    let d = pixel_direction(id.xy);
    let cos_d = dot(d, forward);
    let near = hyper.right.w;
    let far = hyper.up.w;
    // The ray in object space: x(t) = origin + dir t is the local point of world point d t.
    let origin = hyper.to_local[3].xyz;
    let dir = (hyper.to_local * vec4<f32>(d, 0.0)).xyz;
    let span = bounds_span(origin, dir);
    var t1 = span.y;
    // Opaque surfaces already drawn (base surfaces) stop the ray.
    let z = textureLoad(depth, vec2<i32>(id.xy), 0);
    if (z < 1.0) {
        t1 = min(t1, far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK));
    }
    let t0 = max(span.x, near / cos_d);
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
    // Whole steps over [t0, t1], sampled at their middles.
    var n = 0u;
    var h = 0.0;
    if (t1 > t0) {
        let step = hyper.bounds_min.w;
        n = u32(max(ceil((t1 - t0) / step), 1.0));
        h = (t1 - t0) / f32(n);
    }
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
