// Draws layers of `cells` x `cells` squares (two triangles each) blended premultiplied-over, each fragment with one trilinear 3D texture fetch, for `voltex bench --limits`: one square a layer gives the adapter's blended fill rate, small squares its cost per triangle.

@group(0) @binding(0) var bench_volume: texture_3d<f32>;
@group(0) @binding(1) var bench_sampler: sampler;

override layers: f32 = 16.0;
// Squares per row of the target; each is `1 / cells` of its width.
override cells: u32 = 64u;

struct Out {
    @builtin(position) position: vec4<f32>,
    @location(0) uvw: vec3<f32>,
}

// Triangle t of a layer (an instance): square t / 2, its lower (0) or upper (1) half.
@vertex
fn vs_main(@builtin(vertex_index) v: u32, @builtin(instance_index) layer: u32) -> Out {
    let t = v / 3u;
    let square = t / 2u;
    // Corners (0,0) (1,0) (0,1) for the lower half, (1,0) (1,1) (0,1) for the upper.
    let offsets = array<vec2<f32>, 6>(vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(0.0, 1.0), vec2(1.0, 0.0), vec2(1.0, 1.0), vec2(0.0, 1.0));
    let at = vec2<f32>(f32(square % cells), f32(square / cells)) + offsets[v % 3u + 3u * (t % 2u)];
    let xy = at / f32(cells);
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
