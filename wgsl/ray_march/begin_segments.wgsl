// Depth peeling, first step: per pixel, the ray's start (near plane or bounds entry) and no boundaries yet; a ray that starts inside the splat surface enters there. CPU twin: src/methods/ray_march/peel_segments.rs.
#include "shared/types.wgsl"
#include "shared/fields.wgsl"
#include "shared/segments.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<uniform> segments: SegmentParams;
@group(0) @binding(3) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> mesh_depth: array<u32>;
@group(0) @binding(5) var<storage, read_write> segment_bounds: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = viewport_pixel(id.xy);
    if (pixel == NO_PIXEL) {
        return;
    }
    let stride = segment_stride();
    let base = pixel * stride;
    let d = pixel_direction(id.xy);
    let origin = hyper.to_local[3].xyz;
    let dir = (hyper.to_local * vec4<f32>(d, 0.0)).xyz;
    let span = bounds_span(origin, dir);
    let start = max(span.x, hyper.right.w / dot(d, frame.forward.xyz));
    segment_bounds[base] = 0u;
    segment_bounds[base + 1u] = bitcast<u32>(start);
    for (var i = 2u; i < stride; i++) {
        segment_bounds[base + i] = NO_DEPTH;
    }
    // Inside the splat surface (the camera within the object): no front face to enter through.
    if (span.x < span.y && support_distance(origin + dir * start) < segments.surface.x) {
        segment_bounds[base + 2u] = bitcast<u32>(start);
    }
}
