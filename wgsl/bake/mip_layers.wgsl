// Makes one MIP level of a 2D texture array (AxisSlices' slice images, a texel's layers) from the level above: each texel the mean of the 2x2 it covers within its layer.
@group(0) @binding(0) var finer: texture_2d_array<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d_array<rgba16float, write>;

// Premultiplied colour averages like coverage, so a minified image keeps its mean opacity and
// the colour it shows; normals average to the mean direction, renormalised where shaded.
// Filtering stays within a layer. Past an odd size the texel beyond the edge is the first one
// along an axis the texel repeats (columns: s or t; rows too with `wrap_rows`: a w slice's t, a
// texel layer's t) and the last one along w, which does not repeat (an s or t slice's rows).
override wrap_rows: bool = false;

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
        let p = vec2<u32>(q.x % fine.x, select(min(q.y, fine.y - 1u), q.y % fine.y, wrap_rows));
        sum += textureLoad(finer, p, id.z, 0);
    }
    textureStore(coarser, id.xy, id.z, 0.25 * sum);
}
