// Debug view: counts how many slice polygons cover each pixel (additive), to show seams and overlaps.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<storage, read> slice_vertices: array<SliceVertex>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return frame.view_proj * vec4<f32>(slice_vertices[index].position.xyz, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
