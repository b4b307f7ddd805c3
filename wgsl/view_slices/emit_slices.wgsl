// Writes every (plane, prism) slice polygon, fan-triangulated, at its plane's scanned offset: back to front.
#include "shared/types.wgsl"
#include "shared/slice_prism.wgsl"

@group(0) @binding(0) var<uniform> slice_params: SliceParams;
@group(0) @binding(1) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(2) var<storage, read> prisms: array<Prism>;
@group(0) @binding(3) var<storage, read_write> plane_cursors: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> slice_vertices: array<SliceVertex>;
// Per prism, its camera-relative bounding sphere (centre, radius).
@group(0) @binding(5) var<storage, read> prism_spheres: array<vec4<f32>>;

// Skip prisms whose bounding sphere misses the plane before classifying their corners.
override trivial_reject: bool = true;
// Planes per thread (set by the host, which sizes the dispatch with it).
override planes_per_thread: u32 = 32u;

fn slice_vertex(poly: ptr<function, SlicePolygon>, i: u32, index: u32) -> SliceVertex {
    return SliceVertex(vec4<f32>((*poly).pos[i], bitcast<f32>(index)), vec4<f32>((*poly).uvw[i], 0.0));
}

// x: prism index, y: block of planes (0 = back-most).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let index = gid.x;
    if (index >= slice_params.prism_count) {
        return;
    }
    var c = load_prism(index);
    let range = plane_range(&c, gid.y);
    for (var k = range.x; k < range.y; k++) {
        var poly = slice_prism(&c, k);
        emit(&poly, k, index);
    }
}

// Appends one polygon, fan-triangulated, to its plane's range.
fn emit(poly: ptr<function, SlicePolygon>, k: u32, index: u32) {
    let n = fan_vertex_count((*poly).count);
    if (n == 0u) {
        return;
    }
    let base = atomicAdd(&plane_cursors[k], n);
    let capacity = min(slice_params.vertex_capacity, arrayLength(&slice_vertices));
    // A polygon straddling the capacity is written as degenerate triangles below it, so the
    // drawn range [0, vertex_count) never holds stale vertices.
    let fits = base <= capacity && n <= capacity - base;
    let v0 = slice_vertex(poly, 0u, index);
    for (var f = 0u; f + 2u < (*poly).count; f++) {
        for (var c = 0u; c < 3u; c++) {
            let corner = select(f + c, 0u, c == 0u); // fan (0, f+1, f+2)
            let at = base + 3u * f + c;
            if (fits) {
                slice_vertices[at] = slice_vertex(poly, corner, index);
            } else if (at < capacity) {
                slice_vertices[at] = v0;
            }
        }
    }
}
