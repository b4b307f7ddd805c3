// Bakes a periodic Perlin height field (filled below h(s,t)) into a premultiplied RGBA texel volume.
#include "shared/types.wgsl"
#include "shared/noise.wgsl"
#include "shared/shading.wgsl"
#include "shared/height_voxel.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

@group(0) @binding(0) var<uniform> bake_params: BakeParams;
@group(0) @binding(1) var<uniform> heightfield: HeightfieldParams;
@group(0) @binding(2) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(3) var normals: texture_storage_3d<rgba8snorm, write>;

// (h, dh/ds, dh/dt) with h = base + amplitude * (0.5 + 0.5 * fbm) and the analytic noise gradient.
fn heightfield_sample(hf: HeightfieldParams, st: vec2<f32>) -> vec3<f32> {
    let n = perlin_fbm_periodic(st, hf.frequency, hf.octaves, hf.seed);
    return vec3<f32>(hf.base + hf.amplitude * (0.5 + 0.5 * n.x), 0.5 * hf.amplitude * n.yz);
}

fn bake_heightfield_voxel(hf: HeightfieldParams, voxel: vec3<u32>) -> BakedVoxel {
    let res = bake_params.resolution.xyz;
    let p = (vec3<f32>(voxel) + 0.5) / vec3<f32>(res);
    let voxel_size = 1.0 / f32(max(res.x, max(res.y, res.z)));
    return height_voxel(heightfield_sample(hf, p.xy), p, voxel_size, hf.opacity, hf.darkening,
                        hf.color_low.rgb, hf.color_high.rgb, hf.base + hf.amplitude);
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= bake_params.resolution.xyz)) {
        return;
    }
    let baked = bake_heightfield_voxel(heightfield, id);
    textureStore(volume, id, baked.rgba);
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(baked.normal, 0.0));
    }
}
