// Turns a mesh grid baked at a texel's voxel centres (bake_mesh_grid.wgsl: vector to the closest
// surface point, signed distance positive inside) into the texel's premultiplied RGBA volume, its
// shading baked from the outward normal (Meyer & Neyret 1998, section 3.2); CPU twin
// src/cpu/bake_mesh_texel.rs.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

@group(0) @binding(0) var<uniform> bake_params: BakeParams;
@group(0) @binding(1) var<uniform> mesh_texel: MeshTexelParams;
@group(0) @binding(2) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(3) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(4) var normals: texture_storage_3d<rgba8snorm, write>;
// Coloured meshes: per voxel the colour at the closest surface point, tinted by the texel's
// colour (a stand-in otherwise). The inside takes the colour of its nearest surface, which no
// scan order can bias.
@group(0) @binding(5) var<storage, read> mesh_colors: array<vec4<f32>>;

override colored: bool = false;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= bake_params.resolution.xyz)) {
        return;
    }
    let n = bake_params.resolution.xyz;
    let fill = mesh_texel.mode.y != 0u;
    let index = id.x + n.x * (id.y + n.y * id.z);
    let cell = mesh_grid[index];
    let voxel = mesh_texel.extent.w;
    // Filled: the usual coverage ramp across the surface. Shell: one voxel thick, centred on the
    // surface, so an open or sparse pattern (leaves) never needs an inside.
    var coverage = clamp(0.5 + cell.w / voxel, 0.0, 1.0);
    // Away from the surface: from the closest point to the sample, unless inside a filled mesh.
    var away = -cell.xyz;
    if (fill) {
        away = select(-cell.xyz, cell.xyz, cell.w > 0.0);
    } else {
        coverage = clamp(1.0 - abs(cell.w) / voxel, 0.0, 1.0);
    }
    // Texel space is the bounds box scaled to [0,1]^3: normals scale by the box's size.
    let normal = gradient_normal(away * mesh_texel.extent.xyz);
    let alpha = clamp(mesh_texel.color.w * coverage, 0.0, 1.0);
    var rgb = mesh_texel.color.rgb;
    if (colored) {
        rgb *= mesh_colors[index].rgb;
    }
    if (!per_pixel_lighting) {
        rgb = shade_lambert(rgb, normal, bake_params.light);
    }
    textureStore(volume, id, vec4<f32>(clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * alpha, alpha));
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(normal, 0.0));
    }
}
