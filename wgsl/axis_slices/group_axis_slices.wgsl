// Copies each emitted slice triangle into its slice image's group (slots from scan_axis_layers.wgsl) after the emitted ones, and points the indirect draw at the groups.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> axis_params: AxisParams;
// [0, capacity): as emitted (texel by texel); [capacity, 2 capacity): grouped by slice image.
@group(0) @binding(1) var<storage, read_write> axis_vertices: array<AxisVertex>;
@group(0) @binding(2) var<storage, read_write> axis_draw_args: DrawIndirect;
@group(0) @binding(3) var<storage, read_write> axis_layer_counts: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let first = 3u * gid.x;
    let capacity = axis_params.flags.y;
    if (gid.x == 0u) {
        axis_draw_args.first_vertex = capacity;
    }
    if (first >= axis_draw_args.vertex_count) {
        return;
    }
    let tex = axis_vertices[first].texcoord;
    let key = u32(tex.w + 0.5) * (arrayLength(&axis_layer_counts) / 3u) + u32(tex.z + 0.5);
    // Within a group the order is the atomics': depth and alpha tests make it irrelevant.
    let to = capacity + 3u * atomicAdd(&axis_layer_counts[key], 1u);
    for (var i = 0u; i < 3u; i++) {
        axis_vertices[to + i] = axis_vertices[first + i];
    }
}
