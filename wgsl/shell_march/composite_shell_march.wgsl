// Blends the ShellMarch layer (march_shell.wgsl's premultiplied colour and coverage) over the frame (premultiplied-over blending).
#include "shared/types.wgsl"
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var shell_march_rgba: texture_2d<f32>;
@group(0) @binding(1) var<uniform> object: ObjectParams;

#include "shared/aov_coverage.wgsl"

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(shell_march_rgba, vec2<i32>(pixel.xy), 0);
}

// Coverage AOV: the layer's alpha, into the slot of the object it draws (a scene asking for
// coverage draws at most one object with this method: see src/render/aov.rs).
@fragment
fn fs_coverage(@builtin(position) pixel: vec4<f32>) -> Coverage {
    return coverage_slot(object.index, textureLoad(shell_march_rgba, vec2<i32>(pixel.xy), 0).a);
}
