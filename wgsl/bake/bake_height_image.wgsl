// Bakes a height field read from a grey-level image (filled below h(s,t)) into a premultiplied
// RGBA texel volume: Meyer & Neyret 1998, section 3.2. The normal comes from central differences of
// the bilinear height, one image pixel apart.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"
#include "shared/height_voxel.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

@group(0) @binding(0) var<uniform> bake_params: BakeParams;
@group(0) @binding(1) var<uniform> height_image: HeightImageParams;
@group(0) @binding(2) var<storage, read> heights: array<f32>;
@group(0) @binding(3) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(4) var normals: texture_storage_3d<rgba8snorm, write>;

fn pixel(x: i32, y: i32) -> f32 {
    let w = i32(height_image.width);
    let h = i32(height_image.height);
    let xi = ((x % w) + w) % w;
    let yi = ((y % h) + h) % h;
    return heights[yi * w + xi];
}

// Bilinear with wrapping; pixel centres at (i + 0.5) / size; t = 0 is the bottom row.
fn image_height(st: vec2<f32>) -> f32 {
    let x = st.x * f32(height_image.width) - 0.5;
    let y = (1.0 - st.y) * f32(height_image.height) - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let f = vec2<f32>(x - x0, y - y0);
    let xi = i32(x0);
    let yi = i32(y0);
    let top = mix(pixel(xi, yi), pixel(xi + 1, yi), f.x);
    let bottom = mix(pixel(xi, yi + 1), pixel(xi + 1, yi + 1), f.x);
    return mix(top, bottom, f.y);
}

// (h, dh/ds, dh/dt) with h = base + amplitude * image(s, t).
fn height_image_sample(st: vec2<f32>) -> vec3<f32> {
    let e = vec2<f32>(1.0 / f32(height_image.width), 1.0 / f32(height_image.height));
    let ds = (image_height(st + vec2<f32>(e.x, 0.0)) - image_height(st - vec2<f32>(e.x, 0.0))) / (2.0 * e.x);
    let dt = (image_height(st + vec2<f32>(0.0, e.y)) - image_height(st - vec2<f32>(0.0, e.y))) / (2.0 * e.y);
    let a = height_image.amplitude;
    return vec3<f32>(height_image.base + a * image_height(st), a * ds, a * dt);
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = bake_params.resolution.xyz;
    if (any(id >= res)) {
        return;
    }
    let p = (vec3<f32>(id) + 0.5) / vec3<f32>(res);
    let voxel_size = 1.0 / f32(max(res.x, max(res.y, res.z)));
    let hi = height_image;
    let baked = height_voxel(height_image_sample(p.xy), p, voxel_size, hi.opacity, hi.darkening,
                             hi.color_low.rgb, hi.color_high.rgb, hi.base + hi.amplitude);
    textureStore(volume, id, baked.rgba);
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(baked.normal, 0.0));
    }
}
