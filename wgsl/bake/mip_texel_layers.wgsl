// Makes one MIP level of a texel's layers (its w slices as a 2D texture array) from the level above: each texel the mean of the 2x2 it covers within its layer, wrapping in s and t.
@group(0) @binding(0) var finer: texture_2d_array<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d_array<rgba16float, write>;

// Premultiplied colour and opacity average like coverage; normals average to the mean
// direction, renormalised where shaded. The texel repeats in s and t, so past an odd size the
// texel beyond the edge is the first one; w is never filtered (each layer on its own), so a
// height profile keeps its sharpness at every level.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (id.x >= size.x || id.y >= size.y || id.z >= textureNumLayers(coarser)) {
        return;
    }
    let fine = textureDimensions(finer);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let q = 2u * id.xy + vec2<u32>(k & 1u, k >> 1u);
        sum += textureLoad(finer, q % fine, id.z, 0);
    }
    textureStore(coarser, id.xy, id.z, 0.25 * sum);
}
