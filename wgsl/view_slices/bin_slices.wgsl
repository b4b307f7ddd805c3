// Projects every slice triangle to pixels (edges, tile range, texel coordinates) and counts it in each (tile, block of planes) list segment it touches.
#include "shared/types.wgsl"
#include "shared/tiles.wgsl"

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> slice_params: SliceParams;
@group(0) @binding(2) var<uniform> tile_params: TileParams;
@group(0) @binding(3) var<storage, read> slice_vertices: array<SliceVertex>;
@group(0) @binding(4) var<storage, read> draw_args: DrawIndirect;
// After emit_slices: the end of each plane's vertex range.
@group(0) @binding(5) var<storage, read> plane_cursors: array<u32>;
@group(0) @binding(6) var<storage, read_write> tile_triangles: array<TileTriangle>;
@group(0) @binding(7) var<storage, read_write> tile_cursors: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> tile_attributes: array<TileAttributes>;

// The plane whose vertex range holds vertex `v`: the first with an end past it.
fn plane_of(v: u32) -> u32 {
    var lo = 0u;
    var hi = min(slice_params.plane_count, arrayLength(&plane_cursors));
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (plane_cursors[mid] > v) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

// x: triangle index (3 vertices each, plane by plane, back to front).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = gid.x;
    if (3u * t + 3u > draw_args.vertex_count || t >= arrayLength(&tile_triangles)) {
        return;
    }
    let size = vec2<f32>(f32(tile_params.width), f32(tile_params.height));
    let va = slice_vertices[3u * t];
    let vb = slice_vertices[3u * t + 1u];
    let vc = slice_vertices[3u * t + 2u];
    let a = project_to_pixels(va.position.xyz, frame.view_proj, size);
    let b = project_to_pixels(vb.position.xyz, frame.view_proj, size);
    let c = project_to_pixels(vc.position.xyz, frame.view_proj, size);
    let plane = min(plane_of(3u * t), max(slice_params.plane_count, 1u) - 1u);
    let tri = tile_triangle(a, b, c, plane, vec2<u32>(tile_params.tiles_x, tile_params.tiles_y), size);
    tile_triangles[t] = tri;
    tile_attributes[t] = tile_attributes_of(a.xy, b.xy, c.xy, va.uvw.xyz, vb.uvw.xyz, vc.uvw.xyz);
    let r = tri.tiles;
    let block = plane / TILE_PLANES;
    for (var y = r.y; y <= r.w; y++) {
        for (var x = r.x; x <= r.z; x++) {
            if (!tile_touches(tri, x, y)) {
                continue;
            }
            atomicAdd(&tile_cursors[(y * tile_params.tiles_x + x) * tile_params.blocks + block], 1u);
        }
    }
}
