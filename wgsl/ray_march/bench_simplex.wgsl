// Evaluates 3D simplex noise `evaluations` times per thread: the cost of one noise evaluation alone, for `voltex bench-hyper`.
#include "shared/simplex.wgsl"

override evaluations: u32 = 256u;

@group(0) @binding(0) var<storage, read_write> bench_out: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var p = vec3<f32>(f32(id.x) * 0.137, f32(id.y) * 0.071, 0.3);
    var sum = 0.0;
    for (var i = 0u; i < evaluations; i++) {
        sum += simplex3(p, i & 7u);
        p += vec3<f32>(0.0113, 0.0271, 0.0197);
    }
    // Stored so that the evaluations cannot be optimised away.
    bench_out[id.y * 4096u + id.x] = sum;
}
