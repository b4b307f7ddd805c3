// Blends the layer composite_tiles made over the frame (premultiplied-over blending by the pipeline).
#include "shared/types.wgsl"
#include "shared/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> tile_params: TileParams;
@group(0) @binding(1) var<storage, read> tile_layer: array<vec4<f32>>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    return tile_layer[u32(pixel.y) * tile_params.width + u32(pixel.x)];
}
