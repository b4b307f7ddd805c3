// Composites the premultiplied HDR accumulation over the background into the linear output.
#include "shared/types.wgsl"
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var hdr: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(hdr, vec2<i32>(pixel.xy), 0);
    return vec4<f32>(c.rgb + (1.0 - c.a) * frame.background.rgb, 1.0);
}
