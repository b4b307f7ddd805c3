// Draws a base surface opaque with depth (also into base_depth), lit by the frame's light (vertex pulling, 3 per triangle).
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> object: ObjectParams;
@group(0) @binding(2) var<storage, read> base_vertices: array<BaseVertex>;
// AOVs (fs_coverage, fs_depth): the nearest opaque hit per pixel.
@group(0) @binding(3) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;

#include "shared/aov_coverage.wgsl"
#include "shared/aov_depth.wgsl"

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) rel: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VsOut {
    let v = base_vertices[index];
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.normal = v.normal.xyz;
    out.rel = v.position.xyz;
    return out;
}

struct FsOut {
    @location(0) color: vec4<f32>,
    // The depth again, readable by compute passes (occlusion culling) that run between draws.
    @location(1) depth: f32,
}

@fragment
fn fs_main(in: VsOut) -> FsOut {
    var n = normalize(in.normal);
    // Two-sided: light the side facing the camera.
    if dot(n, in.rel) > 0.0 {
        n = -n;
    }
    let ambient = frame.light_dir.w;
    let diffuse = max(dot(n, frame.light_dir.xyz), 0.0);
    let rgb = object.base_color.rgb * (ambient + (1.0 - ambient) * diffuse) * frame.light_color.rgb;
    return FsOut(vec4<f32>(rgb, 1.0), in.clip.z);
}

// Coverage AOV: a base surface covers its pixels wholly.
@fragment
fn fs_coverage(in: VsOut) -> Coverage {
    return coverage_slot(object.index, 1.0);
}

// Depth AOV: a base surface is opaque.
@fragment
fn fs_depth(in: VsOut) {
    record_opaque_depth(fragment_pixel(in.clip), dot(in.rel, frame.forward.xyz));
}
