// Builds mip i+1 of a premultiplied RGBA texel volume from mip i with a 2x2x2 box filter.
// `target` is a reserved WGSL word, hence `destination`. Odd sizes clamp the source coordinate;
// s/t periodicity is irrelevant for a box filter.

@group(0) @binding(0) var source: texture_3d<f32>;
@group(0) @binding(1) var destination: texture_storage_3d<rgba8unorm, write>;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= textureDimensions(destination))) {
        return;
    }
    let last = textureDimensions(source, 0) - vec3<u32>(1u);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let offset = vec3<u32>(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        sum += textureLoad(source, min(2u * id + offset, last), 0);
    }
    textureStore(destination, id, sum * 0.125);
}
