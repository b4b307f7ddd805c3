// Takes `samples` trilinear samples of a 3D texture per thread, marching along z: the adapter's texture sample rate, for `voltex bench --limits`.

@group(0) @binding(0) var bench_volume: texture_3d<f32>;
@group(0) @binding(1) var bench_sampler: sampler;
@group(0) @binding(2) var<storage, read_write> bench_out: array<f32>;

override samples: u32 = 256u;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let uv = (vec2<f32>(id.xy) + 0.5) / 256.0;
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i < samples; i++) {
        sum += textureSampleLevel(bench_volume, bench_sampler, vec3<f32>(uv, (f32(i) + 0.5) / f32(samples)), 0.0);
    }
    // Stored so that the samples cannot be optimised away.
    bench_out[id.y * 256u + id.x] = sum.x + sum.y + sum.z + sum.w;
}
