// Blends the reference tracer's premultiplied layer over the frame (premultiplied-over blending).
#include "shared/types.wgsl"

@group(0) @binding(0) var reference_rgba: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(reference_rgba, vec2<i32>(pixel.xy), 0);
}
