// The transmittance AOV: the fraction of the background seen through everything drawn, 1 - alpha of the premultiplied frame.
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var hdr: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let a = textureLoad(hdr, vec2<i32>(pixel.xy), 0).a;
    return vec4<f32>(1.0 - a, 0.0, 0.0, 1.0);
}
