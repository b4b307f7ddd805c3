// One workgroup of SCAN_THREADS threads scans up to SCAN_THREADS x chunk items: each thread owns a
// contiguous chunk (`scan_chunk`), sums it, and `scan_offsets` gives the sum of the chunks before
// its own and of all (Hillis-Steele over the chunk sums). Call both from uniform control flow.

const SCAN_THREADS: u32 = 256u;

var<workgroup> partial_sums: array<u32, SCAN_THREADS>;

// [begin, end) of thread `lid`'s chunk of `count` items.
fn scan_chunk(lid: u32, count: u32) -> vec2<u32> {
    let chunk = (count + SCAN_THREADS - 1u) / SCAN_THREADS;
    let begin = min(lid * chunk, count);
    return vec2<u32>(begin, min(begin + chunk, count));
}

// x: the sum of the chunks before thread `lid`'s (its first offset); y: the sum of all chunks.
fn scan_offsets(lid: u32, sum: u32) -> vec2<u32> {
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
    let scanned = vec2<u32>(partial_sums[lid] - sum, partial_sums[SCAN_THREADS - 1u]);
    // The caller may reuse partial_sums once every thread has read its values.
    workgroupBarrier();
    return scanned;
}
