// Composites each pixel's slice fragments front to back in registers, a workgroup per tile, stopping once opaque: a premultiplied layer.
#include "shared/types.wgsl"
#include "shared/tiles.wgsl"
#include "shared/slice_shading.wgsl"

override per_pixel_lighting: bool = false;

// The parameters are read as storage, not uniforms: lavapipe (Mesa 22.3) inlines uniforms that
// loop and branch conditions depend on, and overflows a fixed array doing it for this kernel.

@group(0) @binding(0) var<storage, read> frame: FrameParams;
@group(0) @binding(1) var<storage, read> object: ObjectParams;
@group(0) @binding(2) var<storage, read> slice_params: SliceParams;
@group(0) @binding(3) var<storage, read> tile_params: TileParams;
@group(0) @binding(4) var<storage, read> slice_vertices: array<SliceVertex>;
@group(0) @binding(5) var<storage, read> prisms: array<Prism>;
@group(0) @binding(6) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(7) var volume: texture_3d<f32>;
@group(0) @binding(8) var normals: texture_3d<f32>;
@group(0) @binding(9) var volume_sampler: sampler;
@group(0) @binding(10) var<storage, read> vertex_frames: array<VertexFrame>;
@group(0) @binding(11) var<storage, read> draw_args: DrawIndirect;
@group(0) @binding(12) var<storage, read> plane_cursors: array<u32>;
@group(0) @binding(13) var<storage, read> tile_triangles: array<TileTriangle>;
// After fill_tiles: the end of each (tile, block) segment; it starts where the previous ends.
@group(0) @binding(14) var<storage, read> tile_cursors: array<u32>;
@group(0) @binding(15) var<storage, read> tile_entries: array<u32>;
// Depth of the opaque surfaces drawn before (base surfaces, binary axis slices).
@group(0) @binding(16) var depth: texture_depth_2d;
@group(0) @binding(17) var<storage, read> tile_attributes: array<TileAttributes>;
@group(0) @binding(18) var<storage, read_write> tile_layer: array<vec4<f32>>;
@group(0) @binding(19) var volume_layers: texture_2d_array<f32>;
@group(0) @binding(20) var normal_layers: texture_2d_array<f32>;

// A pixel stops once less than this of what lies behind shows through (as the Reference does).
const MIN_TRANSMITTANCE: f32 = 1e-4;

// The interpolation frame of triangle t at barycentrics `bary` (per-pixel lighting).
fn tile_frame(t: u32, bary: vec3<f32>) -> SliceFrame {
    let fa = slice_vertex_frame(slice_vertices[3u * t]);
    let fb = slice_vertex_frame(slice_vertices[3u * t + 1u]);
    let fc = slice_vertex_frame(slice_vertices[3u * t + 2u]);
    return SliceFrame(
        bary.x * fa.n_s + bary.y * fb.n_s + bary.z * fc.n_s,
        bary.x * fa.n_t + bary.y * fb.n_t + bary.z * fc.n_t,
        bary.x * fa.n_w + bary.y * fb.n_w + bary.z * fc.n_w,
    );
}

// One workgroup per tile, one invocation per pixel. No barrier: a pixel (on a CPU adapter, a
// SIMD row of pixels) stops on its own once opaque.
@compute @workgroup_size(TILE_SIZE, TILE_SIZE)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    let pixel = group.xy * TILE_SIZE + local.xy;
    let inside = pixel.x < tile_params.width && pixel.y < tile_params.height;
    let p = vec2<f32>(pixel) + 0.5;
    let tile = group.y * tile_params.tiles_x + group.x;
    let blocks = tile_params.blocks;
    let capacity = min(tile_params.entry_capacity, arrayLength(&tile_entries));
    let opacity_length = object.opacity_length;
    var behind = 1.0;
    if (inside) {
        behind = textureLoad(depth, vec2<i32>(pixel), 0);
    }
    var rgb = vec3<f32>(0.0);
    var transmittance = select(0.0, 1.0, inside);
    // This pixel's ray and step correction, from its first fragment (the same for all).
    var ray = vec3<f32>(0.0, 0.0, 1.0);
    var exponent = -1.0;
    // Per plane of the block: the triangle covering this pixel (one at most: the slices of one
    // plane do not overlap), so the list's order within a segment does not matter.
    var slots: array<u32, TILE_PLANES>;
    for (var b = blocks; b > 0u && transmittance > MIN_TRANSMITTANCE; b--) {
        let block = b - 1u;
        for (var s = 0u; s < TILE_PLANES; s++) {
            slots[s] = NO_TRIANGLE;
        }
        let segment = tile * blocks + block;
        let end = tile_cursors[segment];
        let start = select(tile_cursors[max(segment, 1u) - 1u], 0u, segment == 0u);
        if (end <= capacity) {
            for (var e = start; e < end; e++) {
                let entry = tile_entries[e];
                if (tile_cover(tile_triangles[entry >> 5u], p).x >= 0.0) {
                    slots[entry & (TILE_PLANES - 1u)] = entry >> 5u;
                }
            }
        } else {
            // The segment overflowed the lists: test every triangle of the block's planes.
            let first = block * TILE_PLANES;
            let last = min(first + TILE_PLANES, min(slice_params.plane_count, arrayLength(&plane_cursors)));
            for (var k = first; k < last; k++) {
                let begin = select(plane_cursors[max(k, 1u) - 1u], 0u, k == 0u) / 3u;
                let finish = min(plane_cursors[k], draw_args.vertex_count) / 3u;
                for (var t = begin; t < finish; t++) {
                    if (tile_cover(tile_triangles[t], p).x >= 0.0) {
                        slots[k - first] = t;
                    }
                }
            }
        }
        // Front to back (higher planes are nearer), one fragment per iteration: each pixel skips
        // its empty slots first, so a SIMD row shades as often as its busiest pixel has
        // fragments, not once per plane any of its pixels has one.
        var s = TILE_PLANES;
        loop {
            while (s > 0u && slots[s - 1u] == NO_TRIANGLE) {
                s--;
            }
            if (s == 0u || transmittance <= MIN_TRANSMITTANCE) {
                break;
            }
            s--;
            let t = slots[s];
            // The rasteriser's depth test (Less) against the opaque surfaces.
            if (!(tile_triangles[t].depth < behind)) {
                continue;
            }
            var f = SliceFrame(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
            if (exponent < 0.0 || per_pixel_lighting) {
                let bary = tile_cover(tile_triangles[t], p);
                let rel = bary.x * slice_vertices[3u * t].position.xyz
                    + bary.y * slice_vertices[3u * t + 1u].position.xyz
                    + bary.z * slice_vertices[3u * t + 2u].position.xyz;
                ray = normalize(rel);
                exponent = slice_exponent(ray, opacity_length);
                if per_pixel_lighting {
                    f = tile_frame(t, bary);
                }
            }
            // A triangle's texel coordinates are affine in the pixel: its derivatives are exact.
            let at = tile_attributes[t];
            let c = slice_fragment(tile_attribute(at, p), texel_level(at.d_x.xyz, at.d_y.xyz), ray, exponent, f);
            rgb += transmittance * c.rgb;
            transmittance *= 1.0 - c.a;
        }
    }
    if (inside) {
        tile_layer[pixel.y * tile_params.width + pixel.x] = vec4<f32>(rgb, 1.0 - transmittance);
    }
}
