// Bakes a volume (an OpenVDB grid's brick atlas) into a premultiplied RGBA texel volume: per voxel the density at the voxel centre of the box mapped onto texel space, opacity 1 - exp(-sigma_t opacity_length), colour albedo times the colour grid, shaded from the density gradient; CPU twin src/bake/volume.rs.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"
#include "shared/volume.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

@group(0) @binding(0) var<uniform> bake_params: BakeParams;
// to_index: texel space [0,1]^3 to the grid's index space; box_lo.w: the texel's opacity length.
@group(0) @binding(1) var<uniform> volume_params: VolumeParams;
@group(0) @binding(2) var<storage, read> volume_table: array<u32>;
@group(0) @binding(3) var volume_density: texture_3d<f32>;
@group(0) @binding(4) var volume_color: texture_3d<f32>;
@group(0) @binding(5) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(6) var normals: texture_storage_3d<rgba8snorm, write>;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let id = vec3<u32>(gid.xy, gid.z + bake_params.resolution.w);
    let res = bake_params.resolution.xyz;
    if (any(id >= res)) {
        return;
    }
    let m = volume_params.to_index;
    let x = (m * vec4<f32>((vec3<f32>(id) + 0.5) / vec3<f32>(res), 1.0)).xyz;
    let sigma = volume_params.medium.w * volume_density_at(x);
    let alpha = 1.0 - exp(-sigma * volume_params.box_lo.w);
    if (alpha <= 0.0) {
        textureStore(volume, id, vec4<f32>(0.0));
        return;
    }
    // The gradient by central differences half a voxel apart, taken to texel space (the
    // transpose of the texel-to-index map's linear part).
    let e = 0.5;
    let gi = vec3<f32>(
        volume_density_at(x + vec3<f32>(e, 0.0, 0.0)) - volume_density_at(x - vec3<f32>(e, 0.0, 0.0)),
        volume_density_at(x + vec3<f32>(0.0, e, 0.0)) - volume_density_at(x - vec3<f32>(0.0, e, 0.0)),
        volume_density_at(x + vec3<f32>(0.0, 0.0, e)) - volume_density_at(x - vec3<f32>(0.0, 0.0, e)),
    );
    let g = transpose(mat3x3<f32>(m[0].xyz, m[1].xyz, m[2].xyz)) * gi;
    let normal = gradient_normal(-g);
    var rgb = volume_params.medium.rgb * volume_color_at(x);
    if (!per_pixel_lighting) {
        rgb = shade_lambert(rgb, normal, bake_params.light);
    }
    textureStore(volume, id, vec4<f32>(clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * alpha, alpha));
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(normal, 0.0));
    }
}
