// Counts the triangle-list vertices of every (plane, prism) slice polygon into its plane's cursor.
#include "shared/types.wgsl"
#include "shared/slice_prism.wgsl"

@group(0) @binding(0) var<uniform> slice_params: SliceParams;
@group(0) @binding(1) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(2) var<storage, read> prisms: array<Prism>;
@group(0) @binding(3) var<storage, read_write> plane_cursors: array<atomic<u32>>;
// Per prism, its camera-relative bounding sphere (centre, radius).
@group(0) @binding(4) var<storage, read> prism_spheres: array<vec4<f32>>;

// Skip prisms whose bounding sphere misses the plane before classifying their corners.
override trivial_reject: bool = true;
// Planes per thread (set by the host, which sizes the dispatch with it).
override planes_per_thread: u32 = 32u;

// x: prism index, y: block of planes (0 = back-most).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= slice_params.prism_count) {
        return;
    }
    var c = load_prism(gid.x);
    let range = plane_range(&c, gid.y);
    for (var k = range.x; k < range.y; k++) {
        let n = fan_vertex_count(slice_prism(&c, k).count);
        if (n > 0u) {
            atomicAdd(&plane_cursors[k], n);
        }
    }
}
