// Copies level 0 of a texel volume (or its normal volume) into the layers of a 2D texture array, one layer per w voxel, as f16.
@group(0) @binding(0) var source: texture_3d<f32>;
@group(0) @binding(1) var layers: texture_storage_2d_array<rgba16float, write>;

// The layers' MIP levels (mip_layers.wgsl) then filter s and t only: a 3D MIP chain also
// halves w and blurs the height profile.
@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= textureDimensions(source))) {
        return;
    }
    textureStore(layers, id.xy, id.z, textureLoad(source, id, 0));
}
