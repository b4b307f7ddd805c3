// Bakes a hypertexture (Gilet & Dischler 2009) into a premultiplied RGBA texel volume (Meyer & Neyret 1998, section 3.3): per voxel the density and colour transfer at the voxel centre, shaded from the density gradient; CPU twin src/cpu/bake_hypertexture.rs.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"
#include "shared/hypertexture.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

// resolution.xyz: the whole volume; resolution.w: the first w layer of this dispatch (a large
// volume is baked in slabs of layers, one dispatch each).
@group(0) @binding(0) var<uniform> bake_params: BakeParams;
// The hypertexture as RayMarch packs it, except: bounds_min.xyz, bounds_max.xyz the box of object
// space that maps onto texel space [0,1]^3; march.y the central-difference offset (object units).
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<storage, read> hyper_noises: array<HyperNoise>;
@group(0) @binding(3) var<storage, read> transfer_tables: array<f32>;
// Mesh objects: the baked grid and its largest inside distance (f32 bits); stand-ins otherwise.
@group(0) @binding(4) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> mesh_depth: array<u32>;
@group(0) @binding(6) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(7) var normals: texture_storage_3d<rgba8snorm, write>;

// Below this opacity a voxel is empty: its gradient is not evaluated.
const MIN_OPACITY: f32 = 1e-6;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let id = vec3<u32>(gid.xy, gid.z + bake_params.resolution.w);
    let res = bake_params.resolution.xyz;
    if (any(id >= res)) {
        return;
    }
    let lo = hyper.bounds_min.xyz;
    let extent = hyper.bounds_max.xyz - lo;
    let x = lo + extent * (vec3<f32>(id) + 0.5) / vec3<f32>(res);
    let e = hyper.march.y;
    // Sample 0 is the voxel centre, 1 to 6 the central differences (+x, -x, +y, ...): one loop, so
    // the density is compiled once (lavapipe makes a much slower kernel of inlined copies).
    var rgba = vec4<f32>(0.0);
    var g = vec3<f32>(0.0);
    var j = 0u;
    while (j < 7u) {
        var p = x;
        let axis = min((j - 1u) / 2u, 2u);
        let side = select(-1.0, 1.0, (j & 1u) == 1u);
        if (j > 0u) {
            p[axis] += side * e;
        }
        let density = hyper_density(p);
        if (j == 0u) {
            rgba = hyper_color(density);
            if (rgba.a <= MIN_OPACITY) {
                break;
            }
        } else {
            g[axis] += side * density;
        }
        j++;
    }
    // Outward: the density falls outwards. Texel space is the box scaled to [0,1]^3, so the
    // texel-space gradient is the object-space one times the box's size.
    let normal = gradient_normal(-g * extent);
    let alpha = clamp(rgba.a, 0.0, 1.0);
    var rgb = rgba.rgb;
    if (!per_pixel_lighting) {
        rgb = shade_lambert(rgb, normal, bake_params.light);
    }
    textureStore(volume, id, vec4<f32>(clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * alpha, alpha));
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(normal, 0.0));
    }
}
