// Resolves the nearest opaque hit of every pixel (1 / z bits) into the depth AOV: camera-space z, 1e10 where nothing opaque was hit.
#include "shared/types.wgsl"
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<storage, read> aov_opaque_depth: array<u32>;

// Depth of a pixel without an opaque hit (as Blender's Cycles writes for the background).
const NO_HIT_DEPTH: f32 = 1e10;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let bits = aov_opaque_depth[u32(pixel.y) * u32(frame.viewport.x) + u32(pixel.x)];
    let z = select(NO_HIT_DEPTH, 1.0 / bitcast<f32>(bits), bits != 0u);
    return vec4<f32>(z, 0.0, 0.0, 1.0);
}
