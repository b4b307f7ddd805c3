// Exclusive prefix sum of the per-prism slice vertex counts (prisms sorted back to front) and the indirect draw arguments.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> axis_params: AxisParams;
@group(0) @binding(1) var<storage, read_write> axis_choices: array<AxisChoice>;
@group(0) @binding(2) var<storage, read_write> axis_draw_args: DrawIndirect;

const SCAN_THREADS: u32 = 256u;

var<workgroup> partial_sums: array<u32, SCAN_THREADS>;

// One workgroup: each thread owns a contiguous chunk of prisms.
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let count = min(axis_params.resolution.w, arrayLength(&axis_choices));
    let chunk = (count + SCAN_THREADS - 1u) / SCAN_THREADS;
    let begin = min(lid * chunk, count);
    let end = min(begin + chunk, count);
    var sum = 0u;
    for (var i = begin; i < end; i++) {
        sum += axis_choices[i].vertex_count;
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
    let total = partial_sums[SCAN_THREADS - 1u];
    let capacity = axis_params.flags.y;
    // The drawn range ends before the first prism that does not fit (never expected: the host
    // sizes the buffer for the finest level of every prism).
    var fits_until = total;
    for (var i = begin; i < end; i++) {
        axis_choices[i].vertex_offset = running;
        let n = axis_choices[i].vertex_count;
        if (running + n > capacity) {
            fits_until = min(fits_until, running);
        }
        running += n;
    }
    workgroupBarrier();
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
