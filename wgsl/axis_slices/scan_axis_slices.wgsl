// Exclusive prefix sum of the per-prism slice vertex counts (prisms sorted back to front) and the indirect draw arguments.
#include "shared/types.wgsl"
#include "shared/scan.wgsl"

@group(0) @binding(0) var<uniform> axis_params: AxisParams;
@group(0) @binding(1) var<storage, read_write> axis_choices: array<AxisChoice>;
@group(0) @binding(2) var<storage, read_write> axis_draw_args: DrawIndirect;

// One workgroup: each thread owns a contiguous chunk of prisms.
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let range = scan_chunk(lid, min(axis_params.resolution.w, arrayLength(&axis_choices)));
    var sum = 0u;
    for (var i = range.x; i < range.y; i++) {
        sum += axis_choices[i].vertex_count;
    }
    let scanned = scan_offsets(lid, sum);
    var running = scanned.x;
    let total = scanned.y;
    let capacity = axis_params.flags.y;
    // The drawn range ends before the first prism that does not fit (never expected: the host
    // sizes the buffer for the finest level of every prism).
    var fits_until = total;
    for (var i = range.x; i < range.y; i++) {
        axis_choices[i].vertex_offset = running;
        let n = axis_choices[i].vertex_count;
        if (running + n > capacity) {
            fits_until = min(fits_until, running);
        }
        running += n;
    }
    partial_sums[lid] = fits_until;
    workgroupBarrier();
    if (lid == 0u) {
        var drawn = total;
        for (var t = 0u; t < SCAN_THREADS; t++) {
            drawn = min(drawn, partial_sums[t]);
        }
        axis_draw_args = DrawIndirect(drawn, 1u, 0u, 0u);
    }
}
