// Appends every slice triangle to the list segment of each (tile, block of planes) it touches; entries past the capacity are dropped and their segments marked by their end.
#include "shared/types.wgsl"
#include "shared/tiles.wgsl"

@group(0) @binding(0) var<uniform> tile_params: TileParams;
@group(0) @binding(1) var<storage, read> draw_args: DrawIndirect;
@group(0) @binding(2) var<storage, read> tile_triangles: array<TileTriangle>;
@group(0) @binding(3) var<storage, read_write> tile_cursors: array<atomic<u32>>;
// Per entry: triangle index << 5 | its plane's slot in the block (plane % 32).
@group(0) @binding(4) var<storage, read_write> tile_entries: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = gid.x;
    if (3u * t + 3u > draw_args.vertex_count || t >= arrayLength(&tile_triangles)) {
        return;
    }
    let tri = tile_triangles[t];
    let r = tri.tiles;
    let block = tri.plane / TILE_PLANES;
    let entry = (t << 5u) | (tri.plane % TILE_PLANES);
    let capacity = min(tile_params.entry_capacity, arrayLength(&tile_entries));
    for (var y = r.y; y <= r.w; y++) {
        for (var x = r.x; x <= r.z; x++) {
            if (!tile_touches(tri, x, y)) {
                continue;
            }
            let at = atomicAdd(&tile_cursors[(y * tile_params.tiles_x + x) * tile_params.blocks + block], 1u);
            // A segment that does not fit is composited from all its planes' triangles instead.
            if (at < capacity) {
                tile_entries[at] = entry;
            }
        }
    }
}
