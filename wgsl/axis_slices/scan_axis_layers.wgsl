// Exclusive prefix sum of the per-(direction, layer) triangle counts of count_axis_layers.wgsl, in place: the first slot of each slice image's group.
#include "shared/types.wgsl"
#include "shared/scan.wgsl"

@group(0) @binding(0) var<storage, read_write> axis_layer_counts: array<u32>;

// One workgroup: each thread owns a contiguous chunk of layers.
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let range = scan_chunk(lid, arrayLength(&axis_layer_counts));
    var sum = 0u;
    for (var i = range.x; i < range.y; i++) {
        sum += axis_layer_counts[i];
    }
    var running = scan_offsets(lid, sum).x;
    for (var i = range.x; i < range.y; i++) {
        let n = axis_layer_counts[i];
        axis_layer_counts[i] = running;
        running += n;
    }
}
