// Exclusive prefix sum of the per-(tile, block of planes) triangle counts, in place: where each list segment starts.
#include "shared/types.wgsl"
#include "shared/scan.wgsl"

@group(0) @binding(0) var<uniform> tile_params: TileParams;
@group(0) @binding(1) var<storage, read_write> tile_cursors: array<u32>;

// One workgroup: each thread owns a contiguous chunk of segments.
@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    let count = min(tile_params.tiles_x * tile_params.tiles_y * tile_params.blocks, arrayLength(&tile_cursors));
    let range = scan_chunk(lid, count);
    var sum = 0u;
    for (var i = range.x; i < range.y; i++) {
        sum += tile_cursors[i];
    }
    var running = scan_offsets(lid, sum).x;
    for (var i = range.x; i < range.y; i++) {
        let c = tile_cursors[i];
        tile_cursors[i] = running;
        running += c;
    }
}
