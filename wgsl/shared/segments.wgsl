// Pixel rays of a RayMarch object and their segments: the span of the enlarged bounds, and the
// per-pixel boundaries that depth peeling finds. Reads the kernel's `frame`, `hyper` and
// `segments`. CPU twin: src/cpu/peel_segments.rs (same names).

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
