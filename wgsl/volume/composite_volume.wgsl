// Blends a volume object's premultiplied layer (its per-pixel march state) over the frame.
#include "shared/types.wgsl"
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<storage, read> volume_state: array<MarchState>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<u32>(pixel.xy);
    let s = volume_state[p.y * u32(frame.viewport.x) + p.x];
    return vec4<f32>(s.color.rgb * frame.light_color.rgb, s.color.a);
}
