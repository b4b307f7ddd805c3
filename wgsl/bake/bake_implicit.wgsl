// Bakes a union of implicit shapes (texel space, s and t periodic) into a premultiplied RGBA texel volume.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"

// true: rgb is the unshaded albedo and `normals` receives N (per-pixel lighting by the renderer);
// false: rgb is Lambert-shaded with bake_params.light and `normals` is not written.
override per_pixel_lighting: bool = false;

// ImplicitShape.kind (twins: SPHERE, TORUS, ... in src/cpu/bake.rs).
const SHAPE_SPHERE: u32 = 0u;
const SHAPE_TORUS: u32 = 1u;
const SHAPE_ELLIPSOID: u32 = 2u;
const SHAPE_METABALLS: u32 = 3u;
const SHAPE_CONSTANT: u32 = 4u;

// Distance standing for "infinitely far" (outside) or, negated, "infinitely deep" (constant).
const FAR: f32 = 1.0e9;

@group(0) @binding(0) var<uniform> bake_params: BakeParams;
@group(0) @binding(1) var<storage, read> shapes: array<ImplicitShape>;
// Metaball centre (xyz) and radius (w); a Metaballs shape uses a range of it.
@group(0) @binding(2) var<storage, read> balls: array<vec4<f32>>;
@group(0) @binding(3) var volume: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(4) var normals: texture_storage_3d<rgba8snorm, write>;

// Ellipsoid distance bound k0 (k0 - 1) / k1 (Quilez): exact on the axes, good near the surface.
fn ellipsoid_distance(q: vec3<f32>, radii: vec3<f32>) -> f32 {
    let k0 = length(q / radii);
    let k1 = length(q / (radii * radii));
    if (k1 < 1.0e-12) {
        return -min(radii.x, min(radii.y, radii.z)); // at the centre
    }
    return k0 * (k0 - 1.0) / k1;
}

// Signed distance of one (non-periodic) copy of a sphere, torus or ellipsoid centred at the origin.
fn local_distance(shape: ImplicitShape, q: vec3<f32>) -> f32 {
    switch shape.kind {
        case SHAPE_SPHERE: {
            return length(q) - shape.params.x;
        }
        case SHAPE_TORUS: {
            return length(vec2<f32>(length(q.xy) - shape.params.x, q.z)) - shape.params.y;
        }
        case SHAPE_ELLIPSOID: {
            return ellipsoid_distance(q, shape.params.xyz);
        }
        default: {
            return FAR; // unknown kinds add nothing to the union
        }
    }
}

// Metaballs: field sum of (1 - (d/r)^2)^3 over every ball and its 9 periodic copies (so blobs
// blend across the tile seam); distance estimate (threshold - field) / |grad field|.
fn metaball_distance(shape: ImplicitShape, p: vec3<f32>) -> f32 {
    var field = 0.0;
    var grad = vec3<f32>(0.0);
    let count = min(shape.ball_count, arrayLength(&balls) - min(shape.first_ball, arrayLength(&balls)));
    for (var b = 0u; b < count; b++) {
        let ball = balls[shape.first_ball + b];
        let r2 = ball.w * ball.w;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let d = p - ball.xyz - vec3<f32>(f32(dx), f32(dy), 0.0);
                let x = dot(d, d) / r2;
                if (x < 1.0) {
                    let a = 1.0 - x;
                    field += a * a * a;
                    grad += (-6.0 * a * a / r2) * d;
                }
            }
        }
    }
    return (shape.params.x - field) / max(length(grad), 1.0e-6);
}

// Signed distance of a shape with s and t periodic: the nearest of the 9 copies at offsets -1,0,1.
fn shape_distance(shape: ImplicitShape, p: vec3<f32>) -> f32 {
    if (shape.kind == SHAPE_CONSTANT) {
        return -FAR;
    }
    if (shape.kind == SHAPE_METABALLS) {
        return metaball_distance(shape, p);
    }
    var d = FAR;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p - shape.center.xyz - vec3<f32>(f32(dx), f32(dy), 0.0);
            d = min(d, local_distance(shape, q));
        }
    }
    return d;
}

struct BakedVoxel {
    rgba: vec4<f32>, // premultiplied
    normal: vec3<f32>,
}

fn bake_implicit_voxel(voxel: vec3<u32>) -> BakedVoxel {
    let res = bake_params.resolution.xyz;
    let p = (vec3<f32>(voxel) + 0.5) / vec3<f32>(res);
    let voxel_size = 1.0 / f32(max(res.x, max(res.y, res.z)));
    let count = min(bake_params.resolution.w, arrayLength(&shapes));
    // Union: the nearest shape gives colour, opacity and normal.
    var best = 0u;
    var best_d = FAR;
    for (var i = 0u; i < count; i++) {
        let d = shape_distance(shapes[i], p);
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    var out: BakedVoxel;
    out.rgba = vec4<f32>(0.0);
    out.normal = vec3<f32>(0.0, 0.0, 1.0);
    if (best_d >= FAR) {
        return out; // no shape
    }
    let shape = shapes[best];
    // Outward normal: central differences of the winning shape's distance over half a voxel.
    let e = 0.5 * voxel_size;
    let g = vec3<f32>(
        shape_distance(shape, p + vec3<f32>(e, 0.0, 0.0)) - shape_distance(shape, p - vec3<f32>(e, 0.0, 0.0)),
        shape_distance(shape, p + vec3<f32>(0.0, e, 0.0)) - shape_distance(shape, p - vec3<f32>(0.0, e, 0.0)),
        shape_distance(shape, p + vec3<f32>(0.0, 0.0, e)) - shape_distance(shape, p - vec3<f32>(0.0, 0.0, e)),
    );
    out.normal = gradient_normal(g);
    // Coverage of the voxel, antialiased over one voxel.
    let coverage = clamp(0.5 - best_d / voxel_size, 0.0, 1.0);
    let alpha = clamp(shape.color.a * coverage, 0.0, 1.0);
    var rgb = shape.color.rgb;
    if (!per_pixel_lighting) {
        rgb = shade_lambert(rgb, out.normal, bake_params.light);
    }
    out.rgba = vec4<f32>(clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * alpha, alpha);
    return out;
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= bake_params.resolution.xyz)) {
        return;
    }
    let baked = bake_implicit_voxel(id);
    textureStore(volume, id, baked.rgba);
    if (per_pixel_lighting) {
        textureStore(normals, id, vec4<f32>(baked.normal, 0.0));
    }
}
