// Counts the triangle-list vertices of every (plane, prism) slice polygon into its plane's cursor.
#include "shared/types.wgsl"
#include "shared/slice_prism.wgsl"

@group(0) @binding(0) var<uniform> slice_params: SliceParams;
@group(0) @binding(1) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(2) var<storage, read> prisms: array<Prism>;
@group(0) @binding(3) var<storage, read_write> plane_cursors: array<atomic<u32>>;

// Skip prisms whose bounding sphere misses the plane before classifying their corners.
override trivial_reject: bool = true;

// x: prism index, y: plane index (0 = back-most).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let index = gid.x;
    let k = gid.y;
    if (index >= slice_params.prism_count || k >= slice_params.plane_count) {
        return;
    }
    let n = fan_vertex_count(slice_prism(index, k).count);
    if (n > 0u) {
        atomicAdd(&plane_cursors[k], n);
    }
}
