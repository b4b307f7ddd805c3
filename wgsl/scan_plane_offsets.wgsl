// Exclusive prefix sum of the per-plane slice vertex counts, in place, and the indirect draw arguments (whole sweep and per plane).
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> slice_params: SliceParams;
@group(0) @binding(1) var<storage, read_write> plane_cursors: array<u32>;
@group(0) @binding(2) var<storage, read_write> draw_args: DrawIndirect;
// One draw per plane, for drawing the planes of overlapping objects interleaved by depth.
@group(0) @binding(3) var<storage, read_write> plane_draws: array<DrawIndirect>;

const SCAN_THREADS: u32 = 256u;

var<workgroup> partial_sums: array<u32, SCAN_THREADS>;

// One workgroup: each thread owns a contiguous chunk of planes (at most 64 for 16384 planes).
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let count = min(slice_params.plane_count, arrayLength(&plane_cursors));
    let chunk = (count + SCAN_THREADS - 1u) / SCAN_THREADS;
    let begin = min(lid * chunk, count);
    let end = min(begin + chunk, count);
    var sum = 0u;
    for (var i = begin; i < end; i++) {
        sum += plane_cursors[i];
    }
    partial_sums[lid] = sum;
    workgroupBarrier();
    // Inclusive Hillis-Steele scan of the 256 chunk sums.
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
    let capacity = slice_params.vertex_capacity;
    for (var i = begin; i < end; i++) {
        let c = plane_cursors[i];
        plane_cursors[i] = running;
        // What emit_slices writes of this plane below the capacity.
        let first = min(running, capacity);
        plane_draws[i] = DrawIndirect(min(c, capacity - first), 1u, first, 0u);
        running += c;
    }
    if (lid == SCAN_THREADS - 1u) {
        let total = partial_sums[lid];
        draw_args = DrawIndirect(min(total, slice_params.vertex_capacity), 1u, 0u, 0u);
    }
}
