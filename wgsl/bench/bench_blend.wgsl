// Draws full-screen layers blended premultiplied-over, each fragment with one trilinear 3D texture fetch: the adapter's blended fill rate, for `voltex bench --limits`.

@group(0) @binding(0) var bench_volume: texture_3d<f32>;
@group(0) @binding(1) var bench_sampler: sampler;

override layers: f32 = 64.0;

struct Out {
    @builtin(position) position: vec4<f32>,
    @location(0) uvw: vec3<f32>,
}

// One full-screen triangle per instance (a layer).
@vertex
fn vs_main(@builtin(vertex_index) v: u32, @builtin(instance_index) layer: u32) -> Out {
    let xy = vec2<f32>(f32((v << 1u) & 2u), f32(v & 2u));
    var out: Out;
    out.position = vec4<f32>(xy * 2.0 - 1.0, 0.5, 1.0);
    out.uvw = vec3<f32>(xy, (f32(layer) + 0.5) / layers);
    return out;
}

@fragment
fn fs_main(in: Out) -> @location(0) vec4<f32> {
    let texel = textureSampleLevel(bench_volume, bench_sampler, in.uvw, 0.0);
    return vec4<f32>(texel.rgb * 0.05, 0.05);
}
