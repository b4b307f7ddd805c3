// Pixel rays of a RayMarch object and their segments: the span of the enlarged bounds, and the
// per-pixel boundaries that depth peeling finds. Reads the kernel's `frame`, `hyper` and
// `segments`. CPU twin: src/methods/ray_march/peel_segments.rs (same names).

// f32 bits of +infinity: no boundary found.
const NO_DEPTH: u32 = 0x7f800000u;

// Parameters (entry, exit) where the ray o + t d (object space) is inside the enlarged bounds;
// entry > exit when it misses. Zero direction components are nudged, never divided by.
fn bounds_span(o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    let tiny = vec3<f32>(1e-30);
    let safe = select(d, select(-tiny, tiny, d >= vec3<f32>(0.0)), abs(d) < tiny);
    let a = (hyper.bounds_min.xyz - o) / safe;
    let b = (hyper.bounds_max.xyz - o) / safe;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec2<f32>(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// No pixel: a thread of a workgroup past the viewport's edge.
const NO_PIXEL: u32 = 0xffffffffu;

// The index of pixel p in the viewport (rows top to bottom), or NO_PIXEL outside it.
fn viewport_pixel(p: vec2<u32>) -> u32 {
    let size = vec2<u32>(frame.viewport.xy);
    return select(NO_PIXEL, p.y * size.x + p.x, all(p < size));
}

// The unit world direction (camera-relative) of the ray through the middle of pixel p.
fn pixel_direction(p: vec2<u32>) -> vec3<f32> {
    let sx = 2.0 * (f32(p.x) + 0.5) * frame.viewport.z - 1.0;
    let sy = 1.0 - 2.0 * (f32(p.y) + 0.5) * frame.viewport.w;
    return normalize(frame.forward.xyz + hyper.right.xyz * sx + hyper.up.xyz * sy);
}

// Words per pixel of `segment_bounds`: the segment the marcher is on, the ray's start (slot 0),
// then the entry (odd slots) and exit (even slots) of each peel, as f32 bits of the ray
// parameter (world distance from the eye).
fn segment_stride() -> u32 {
    return 2u * segments.counts.z + 2u;
}

// Screen coordinate range (lo, hi) along unit `axis` (scaled by `scale`, the half extent at
// unit depth) of a sphere at camera-relative c with radius r in front of the camera (depth z - r > 0):
// x / z is monotonic in z for fixed x, so the extremes are at the depth range's ends.
fn screen_range(c: vec3<f32>, r: f32, z: f32, axis: vec3<f32>, scale: f32) -> vec2<f32> {
    let a = dot(c, axis);
    let lo = min((a - r) / (z - r), (a - r) / (z + r));
    let hi = max((a + r) / (z - r), (a + r) / (z + r));
    return vec2<f32>(lo, hi) / scale;
}

// The footprint of a sphere (object space centre, radius): the screen rectangle (lo.xy, hi.xy,
// pixels, inclusive) of its world bounding sphere, the whole screen when the sphere reaches the
// eye's plane; empty (hi < lo) behind the near plane or off screen.
fn footprint(centre: vec3<f32>, radius: f32) -> vec4<i32> {
    let size = vec2<u32>(frame.viewport.xy);
    let c = (segments.from_local * vec4<f32>(centre, 1.0)).xyz;
    let r = radius * segments.surface.y;
    let z = dot(c, frame.forward.xyz);
    if (z + r <= hyper.right.w) {
        return vec4<i32>(0, 0, -1, -1);
    }
    var lo = vec2<i32>(0, 0);
    var hi = vec2<i32>(size) - vec2<i32>(1);
    if (z - r > 0.5 * hyper.right.w) {
        let width = length(hyper.right.xyz);
        let height = length(hyper.up.xyz);
        let sx = screen_range(c, r, z, hyper.right.xyz / width, width);
        let sy = screen_range(c, r, z, hyper.up.xyz / height, height);
        let w = f32(size.x);
        let h = f32(size.y);
        // Clamped as floats first: far outside the screen they may not fit an i32.
        let limit = vec2<f32>(size);
        let a = clamp(floor(vec2<f32>((sx.x + 1.0) * 0.5 * w, (1.0 - sy.y) * 0.5 * h) - 0.5), vec2<f32>(-1.0), limit);
        let b = clamp(ceil(vec2<f32>((sx.y + 1.0) * 0.5 * w, (1.0 - sy.x) * 0.5 * h) - 0.5), vec2<f32>(-1.0), limit);
        lo = max(lo, vec2<i32>(a));
        hi = min(hi, vec2<i32>(b));
    }
    return vec4<i32>(lo, hi);
}

// EWA-style splatting's per-pixel sums (`splat_slabs`, integer atomics in fixed point, so the sum
// does not depend on the order splats add in): a header (density evaluations, those that ran the
// noises, the ray's sample count n), then per depth slab SLAB_WORDS words: the weighted optical
// depth, the weighted optical depth times rgb (three words), the weighted share of the slab's
// samples covered, the complement (!k) of its first covered sample and its last covered sample
// plus one (0: none). Slab j holds samples k with k * slabs / n = j.
const SLAB_HEADER: u32 = 3u;
const SLAB_WORDS: u32 = 7u;
// Optical depth and colour are kept to 1/4096; one splat adds at most TAU_CAP (opaque already):
// 2^18 per contribution leaves room for 16384 contributions per slab.
const TAU_SCALE: f32 = 4096.0;
const TAU_CAP: f32 = 64.0;
// Covered shares (at most 1 per splat) are kept to 1/65536.
const SHARE_SCALE: f32 = 65536.0;

fn slab_stride() -> u32 {
    return SLAB_HEADER + SLAB_WORDS * segments.splatting.x;
}

// The first sample of slab j of a ray of n samples: the least k with k * slabs / n >= j.
fn slab_start(j: u32, n: u32) -> u32 {
    return (j * n + segments.splatting.x - 1u) / segments.splatting.x;
}
