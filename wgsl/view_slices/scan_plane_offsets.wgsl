// Exclusive prefix sum of the per-plane slice vertex counts, in place, and the indirect draw arguments (whole sweep and per plane).
#include "shared/types.wgsl"
#include "shared/scan.wgsl"

@group(0) @binding(0) var<uniform> slice_params: SliceParams;
@group(0) @binding(1) var<storage, read_write> plane_cursors: array<u32>;
@group(0) @binding(2) var<storage, read_write> draw_args: DrawIndirect;
// One draw per plane, for drawing the planes of overlapping objects interleaved by depth.
@group(0) @binding(3) var<storage, read_write> plane_draws: array<DrawIndirect>;

// One workgroup: each thread owns a contiguous chunk of planes (at most 64 for 16384 planes).
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let range = scan_chunk(lid, min(slice_params.plane_count, arrayLength(&plane_cursors)));
    var sum = 0u;
    for (var i = range.x; i < range.y; i++) {
        sum += plane_cursors[i];
    }
    let scanned = scan_offsets(lid, sum);
    var running = scanned.x;
    let capacity = slice_params.vertex_capacity;
    for (var i = range.x; i < range.y; i++) {
        let c = plane_cursors[i];
        plane_cursors[i] = running;
        // What emit_slices writes of this plane below the capacity.
        let first = min(running, capacity);
        plane_draws[i] = DrawIndirect(min(c, capacity - first), 1u, first, 0u);
        running += c;
    }
    if (lid == SCAN_THREADS - 1u) {
        draw_args = DrawIndirect(min(scanned.y, slice_params.vertex_capacity), 1u, 0u, 0u);
    }
}
