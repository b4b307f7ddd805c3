// Ground truth: exact ray casting through the prisms of every Reference object, one pixel per thread; CPU twin in src/methods/reference/trace_reference.rs.
#include "shared/types.wgsl"
#include "shared/prism_map.wgsl"
#include "shared/shading.wgsl"
#include "shared/bvh.wgsl"

// Work per dispatch, in samples (a window's collection counts WINDOW_COST): the pass is dispatched
// `reference_dispatches` times and each pixel resumes from `reference_state`. Lavapipe ends every
// loop of an invocation after 65535 iterations in all, and real GPUs have watchdogs, so no single
// dispatch may march a whole long ray.
override samples_per_dispatch: u32 = 512u;
const WINDOW_COST: u32 = 16u;
// Intervals held per window: a ray meeting more prisms is traced in several windows.
const MAX_SEGMENTS: u32 = 16u;
const STACK_SIZE: u32 = 48u;
const MIN_TRANSMITTANCE: f32 = 1e-4;
const MAX_ALPHA: f32 = 0.999999;
const FAR: f32 = 3.4e38;
// Raster depth is coarse far from the camera: opaque surfaces from the depth buffer are moved
// back by this relative margin (the Reference objects' own bases are hit exactly).
const DEPTH_SLACK: f32 = 2e-3;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> reference_params: ReferenceParams;
@group(0) @binding(2) var<storage, read> reference_nodes: array<ReferenceNode>;
@group(0) @binding(3) var<storage, read> reference_prisms: array<ReferencePrism>;
@group(0) @binding(4) var<storage, read> reference_objects: array<ReferenceObject>;
@group(0) @binding(5) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(6) var<storage, read> vertex_frames: array<VertexFrame>;
@group(0) @binding(7) var<storage, read> texel_atlas: array<u32>;
@group(0) @binding(8) var<storage, read> normal_atlas: array<u32>;
@group(0) @binding(9) var depth: texture_depth_2d;
@group(0) @binding(10) var reference_rgba: texture_storage_2d<rgba32float, write>;
@group(0) @binding(11) var<storage, read_write> reference_state: array<ReferenceState>;
// The depth AOV: the nearest opaque sample of each pixel (shared/aov_depth.wgsl).
@group(0) @binding(12) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;
// xy: the first pixel of this dispatch. A frame rendered in steps (the preview) dispatches tiles
// of the image, each in its own submission; a whole frame dispatches every pixel from (0, 0).
@group(0) @binding(13) var<uniform> step_origin: vec4<u32>;

#include "shared/aov_depth.wgsl"

// The intervals of the current window: the MAX_SEGMENTS earliest starts at or after the window's
// start; `cut` is the earliest start that did not fit, so everything before it is complete.
var<private> seg_t0: array<f32, MAX_SEGMENTS>;
var<private> seg_t1: array<f32, MAX_SEGMENTS>;
var<private> seg_prism: array<u32, MAX_SEGMENTS>;
var<private> seg_count: u32;
var<private> cut: f32;
var<private> t_opaque: f32;
// Some prism's texel at the last sample was opaque (the depth AOV).
var<private> sample_opaque: bool;

fn load_shape(index: u32) -> PrismShape {
    let ids = reference_prisms[index].vertices.xyz;
    let a = shell_vertices[ids.x];
    let b = shell_vertices[ids.y];
    let c = shell_vertices[ids.z];
    return PrismShape(
        array<vec3<f32>, 3>(a.bottom.xyz, b.bottom.xyz, c.bottom.xyz),
        array<vec3<f32>, 3>(a.top.xyz, b.top.xyz, c.top.xyz),
        array<u32, 3>(ids.x, ids.y, ids.z),
    );
}

fn keep(prism: u32, t0: f32, t1: f32) {
    if (t0 < cut) {
        if (seg_count < MAX_SEGMENTS) {
            seg_t0[seg_count] = t0;
            seg_t1[seg_count] = t1;
            seg_prism[seg_count] = prism;
            seg_count += 1u;
        } else {
            var latest = 0u;
            for (var i = 1u; i < MAX_SEGMENTS; i++) {
                if (seg_t0[i] > seg_t0[latest]) {
                    latest = i;
                }
            }
            if (t0 >= seg_t0[latest]) {
                cut = t0;
            } else {
                cut = seg_t0[latest];
                seg_t0[latest] = t0;
                seg_t1[latest] = t1;
                seg_prism[latest] = prism;
            }
        }
    }
}

// The parts of the ray in [t_start, inf) inside prism `index` go to `keep`; a crossing of an
// opaque base from above ends the ray there.
fn collect_prism(d: vec3<f32>, index: u32, t_start: f32) {
    var shape = load_shape(index);
    let object = reference_objects[reference_prisms[index].vertices.w];
    if ((object.resolution.w & 2u) != 0u) {
        let n = cross(shape.bottom[1] - shape.bottom[0], shape.bottom[2] - shape.bottom[0]);
        let tb = ray_triangle(d, shape.bottom[0], shape.bottom[1], shape.bottom[2]);
        if (dot(d, n) < 0.0 && tb > reference_params.right.w) {
            t_opaque = min(t_opaque, tb);
        }
    }
    let hits = boundary_hits(d, &shape);
    var t0 = t_start;
    var open = false;
    var start = 0.0;
    for (var k = 0u; k <= hits.count; k++) {
        let t1 = select(FAR, hits.t[min(k, 7u)], k < hits.count);
        if (t1 > t0) {
            // Between consecutive crossings the ray is wholly inside or outside: test the middle.
            var inside = false;
            if (k < hits.count) {
                inside = prism_inverse(d * (0.5 * (t0 + t1)), &shape).w >= 0.0;
            }
            if (inside && !open) {
                open = true;
                start = t0;
            } else if (!inside && open) {
                open = false;
                keep(index, start, t0);
            }
            t0 = t1;
        }
    }
}

fn slab(inv: vec3<f32>, node: ReferenceNode) -> vec2<f32> {
    let a = node.min.xyz * inv;
    let b = node.max.xyz * inv;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec2<f32>(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// Walks the BVH over prism bounds, collecting the intervals after t_start.
fn collect(d: vec3<f32>, t_start: f32) {
    seg_count = 0u;
    cut = FAR;
    let inv = 1.0 / d;
    var stack = bvh_stack(0u, reference_params.counts.x == 0u);
    while (stack.top > 0u) {
        let node = reference_nodes[bvh_pop(&stack)];
        let span = slab(inv, node);
        if (span.x <= span.y && span.y >= t_start && span.x <= min(t_opaque, cut)) {
            let count = bitcast<u32>(node.min.w);
            let first = bitcast<u32>(node.max.w);
            if (count > 0u) {
                for (var i = 0u; i < count; i++) {
                    collect_prism(d, first + i, t_start);
                }
            } else {
                bvh_push(&stack, first, first + 1u);
            }
        }
    }
}

struct Axis {
    i0: u32,
    i1: u32,
    f: f32,
}

fn axis(c: f32, n: u32, wrap: bool) -> Axis {
    let x = c * f32(n) - 0.5;
    let fl = floor(x);
    let m = i32(n);
    var i0 = i32(fl);
    var i1 = i0 + 1;
    if (wrap) {
        i0 = ((i0 % m) + m) % m;
        i1 = ((i1 % m) + m) % m;
    } else {
        i0 = clamp(i0, 0, m - 1);
        i1 = clamp(i1, 0, m - 1);
    }
    return Axis(u32(i0), u32(i1), x - fl);
}

// Trilinear filtering as the volume sampler does it: repeat in s and t, clamp in w, level 0.
fn sample_volume(object: ReferenceObject, uvw: vec3<f32>, normals: bool) -> vec4<f32> {
    let ax = axis(fract(uvw.x), object.resolution.x, true);
    let ay = axis(fract(uvw.y), object.resolution.y, true);
    let az = axis(uvw.z, object.resolution.z, false);
    let pitch = object.atlas.y;
    let rows = object.resolution.y;
    let offset = select(object.atlas.x, object.atlas.z, normals);
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let x = select(ax.i0, ax.i1, (k & 1u) != 0u);
        let y = select(ay.i0, ay.i1, (k & 2u) != 0u);
        let z = select(az.i0, az.i1, (k & 4u) != 0u);
        let weight = select(1.0 - ax.f, ax.f, (k & 1u) != 0u) * select(1.0 - ay.f, ay.f, (k & 2u) != 0u)
            * select(1.0 - az.f, az.f, (k & 4u) != 0u);
        let at = offset + (z * rows + y) * pitch + x;
        if (normals) {
            out += unpack4x8snorm(normal_atlas[at]) * weight;
        } else {
            out += unpack4x8unorm(texel_atlas[at]) * weight;
        }
    }
    return out;
}

// Per-pixel lighting as draw_slices.wgsl does it (shared/shading.wgsl), with the exact barycentrics.
fn shade(object: ReferenceObject, shape: ptr<function, PrismShape>, b: vec3<f32>, uvw: vec3<f32>, ray: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    let fa = vertex_frames[(*shape).ids[0]];
    let fb = vertex_frames[(*shape).ids[1]];
    let fc = vertex_frames[(*shape).ids[2]];
    let ds = b.x * fa.ds.xyz + b.y * fb.ds.xyz + b.z * fc.ds.xyz;
    let dt = b.x * fa.dt.xyz + b.y * fb.dt.xyz + b.z * fc.dt.xyz;
    let dw = b.x * ((*shape).top[0] - (*shape).bottom[0]) + b.y * ((*shape).top[1] - (*shape).bottom[1]) + b.z * ((*shape).top[2] - (*shape).bottom[2]);
    let sign_j = select(-1.0, 1.0, dot(ds, cross(dt, dw)) >= 0.0);
    let tn = sample_volume(object, uvw, true).xyz;
    var n = cross(dt, dw) * sign_j * tn.x + cross(dw, ds) * sign_j * tn.y + cross(ds, dt) * sign_j * tn.z;
    n = select(-ray, normalize(n), dot(n, n) > 1e-20);
    return shade_phong(albedo, n, frame.light_dir, -ray, PIXEL_SPECULAR, PIXEL_SHININESS);
}

// Extinction (w) and extinction-weighted colour (xyz) of prism `index` at x.
fn segment_sample(index: u32, x: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let prism = reference_prisms[index];
    let object = reference_objects[prism.vertices.w];
    var shape = load_shape(index);
    let inv = prism_inverse(x, &shape);
    let st = inv.x * prism.uv01.xy + inv.y * prism.uv01.zw + inv.z * prism.uv2.xy;
    let uvw = vec3<f32>(st, inv.w);
    let texel = sample_volume(object, uvw, false);
    let alpha = clamp(texel.a, 0.0, MAX_ALPHA);
    var out = vec4<f32>(0.0);
    sample_opaque = sample_opaque || (inv.w >= 0.0 && texel.a >= OPAQUE_ALPHA);
    if (inv.w >= 0.0 && alpha > 1e-6) {
        var colour = texel.rgb / alpha;
        if ((object.resolution.w & 1u) != 0u) {
            colour = shade(object, &shape, inv.xyz, uvw, d, colour);
        }
        let sigma = -log(1.0 - alpha) / object.params.x;
        out = vec4<f32>(colour * sigma, sigma);
    }
    return out;
}

// The sum over the intervals covering [a, b] (overlapping objects add their extinctions).
fn sample_point(d: vec3<f32>, t: f32, a: f32, b: f32) -> vec4<f32> {
    let x = d * t;
    var acc = vec4<f32>(0.0);
    for (var i = 0u; i < seg_count; i++) {
        if (seg_t0[i] <= a && seg_t1[i] >= b) {
            acc += segment_sample(seg_prism[i], x, d);
        }
    }
    return acc;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) invocation: vec3<u32>) {
    let id = invocation + vec3<u32>(step_origin.xy, 0u);
    let size = vec2<u32>(frame.viewport.xy);
    let pixel = id.y * size.x + id.x;
    var state = ReferenceState(vec4<f32>(0.0, 0.0, 0.0, 1.0), vec4<f32>(0.0));
    if (id.x < size.x && id.y < size.y) {
        state = reference_state[pixel];
    }
    // resume: x where to go on, y 1 once started, z 1 once finished.
    if (id.x >= size.x || id.y >= size.y || state.resume.z != 0.0) {
        return;
    }
    let sx = 2.0 * (f32(id.x) + 0.5) * frame.viewport.z - 1.0;
    let sy = 1.0 - 2.0 * (f32(id.y) + 0.5) * frame.viewport.w;
    let forward = frame.forward.xyz;
    let d = normalize(forward + reference_params.right.xyz * sx + reference_params.up.xyz * sy);
    let cos_d = dot(d, forward);
    let near = reference_params.right.w;
    let far = reference_params.up.w;
    var rgb = state.color.rgb;
    var transmittance = state.color.a;
    var t_start = state.resume.x;
    if (state.resume.y == 0.0) {
        rgb = vec3<f32>(0.0);
        transmittance = 1.0;
        t_start = near / cos_d;
    }
    // Opaque surfaces already drawn (base surfaces) stop the ray.
    let z = textureLoad(depth, vec2<i32>(id.xy), 0);
    t_opaque = FAR;
    if (z < 1.0) {
        t_opaque = far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK);
    }
    var budget = samples_per_dispatch;
    var finished = false;
    var opaque_found = false;
    // Each window holds the next MAX_SEGMENTS intervals and is marched from t_start to its cut.
    while (!finished && budget >= WINDOW_COST) {
        budget -= WINDOW_COST;
        collect(d, t_start);
        let end = min(cut, t_opaque);
        var a = t_start;
        while (a < end && transmittance >= MIN_TRANSMITTANCE && budget > 0u) {
            // Next boundary after a: where an interval starts or ends, or the window's end.
            var b = end;
            var step = FAR;
            for (var i = 0u; i < seg_count; i++) {
                if (seg_t0[i] > a) {
                    b = min(b, seg_t0[i]);
                } else if (seg_t1[i] > a) {
                    b = min(b, seg_t1[i]);
                    step = min(step, reference_objects[reference_prisms[seg_prism[i]].vertices.w].params.y);
                }
            }
            var next = b;
            if (step < FAR) {
                // Whole steps over [a, b]; stopping early resumes at the last finished step.
                let n = u32(max(ceil((b - a) / step), 1.0));
                let h = (b - a) / f32(n);
                var k = 0u;
                while (k < n && transmittance >= MIN_TRANSMITTANCE && budget > 0u) {
                    sample_opaque = false;
                    let s = sample_point(d, a + (f32(k) + 0.5) * h, a, b);
                    if (sample_opaque && !opaque_found) {
                        opaque_found = true;
                        record_opaque_depth(pixel, (a + (f32(k) + 0.5) * h) * cos_d);
                    }
                    if (s.w > 0.0) {
                        let alpha = 1.0 - exp(-s.w * h);
                        rgb += s.xyz / s.w * alpha * transmittance;
                        transmittance *= 1.0 - alpha;
                    }
                    k += 1u;
                    budget -= 1u;
                }
                if (k < n) {
                    next = a + f32(k) * h;
                }
            }
            a = next;
        }
        if (transmittance < MIN_TRANSMITTANCE) {
            finished = true;
        } else if (a < end) {
            t_start = a; // out of budget: resume here
        } else if (cut >= t_opaque || cut >= FAR || cut <= t_start) {
            // (cut <= t_start: more than MAX_SEGMENTS intervals start at one point; they are
            // dropped rather than looping forever.)
            finished = true;
        } else {
            t_start = cut;
        }
    }
    reference_state[pixel] = ReferenceState(vec4<f32>(rgb, transmittance), vec4<f32>(t_start, 1.0, select(0.0, 1.0, finished), 0.0));
    textureStore(reference_rgba, vec2<i32>(id.xy), vec4<f32>(rgb * frame.light_color.rgb, 1.0 - transmittance));
}
