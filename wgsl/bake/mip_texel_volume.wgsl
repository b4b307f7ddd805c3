// Makes one MIP level of a texel volume (or its normal volume) from the level above: each voxel the mean of the 2x2x2 voxels it covers.
@group(0) @binding(0) var finer: texture_3d<f32>;
@group(0) @binding(1) var coarser: texture_storage_3d<rgba8unorm, write>;

// The volume holds premultiplied colour and opacity, which average like coverage (as the slice
// images of mip_axis_slices); normals average to the mean direction, renormalised where
// shaded. An odd size repeats its last voxel (the one past the edge). The host declares
// `coarser` rgba8snorm for normals and rgba32float for full-precision volumes.
@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id >= size)) {
        return;
    }
    let last = textureDimensions(finer) - vec3<u32>(1u);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let p = min(2u * id + vec3<u32>(k & 1u, (k >> 1u) & 1u, k >> 2u), last);
        sum += textureLoad(finer, p, 0);
    }
    textureStore(coarser, id, 0.125 * sum);
}
