// Exclusive prefix sum of the per-(direction, layer) triangle counts of count_axis_layers.wgsl, in place: the first slot of each slice image's group.
#include "shared/types.wgsl"

@group(0) @binding(0) var<storage, read_write> axis_layer_counts: array<u32>;

const SCAN_THREADS: u32 = 256u;

var<workgroup> partial_sums: array<u32, SCAN_THREADS>;

// One workgroup: each thread owns a contiguous chunk of layers.
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let count = arrayLength(&axis_layer_counts);
    let chunk = (count + SCAN_THREADS - 1u) / SCAN_THREADS;
    let begin = min(lid * chunk, count);
    let end = min(begin + chunk, count);
    var sum = 0u;
    for (var i = begin; i < end; i++) {
        sum += axis_layer_counts[i];
    }
    partial_sums[lid] = sum;
    workgroupBarrier();
    for (var offset = 1u; offset < SCAN_THREADS; offset <<= 1u) {
        var v = partial_sums[lid];
        if (lid >= offset) {
            v += partial_sums[lid - offset];
        }
        workgroupBarrier();
        partial_sums[lid] = v;
        workgroupBarrier();
    }
    var running = partial_sums[lid] - sum;
    for (var i = begin; i < end; i++) {
        let n = axis_layer_counts[i];
        axis_layer_counts[i] = running;
        running += n;
    }
}
