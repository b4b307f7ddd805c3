// Bakes self-shadowing into a texel: each voxel's colour scaled by its transmittance towards a fixed light through the texel's opacity.
#include "shared/types.wgsl"

// Meyer & Neyret 1998, 3.1: the slices store colour only, so shadows are captured in the pattern
// for a light fixed at creation. The march is an exact voxel traversal (Amanatides & Woo) of the
// nearest-voxel opacity, from `shadow.shading.z` voxels off the voxel's centre (a bias against
// a surface shadowing itself on its own voxel steps) towards the light, with extinction
// `shadow.light.w * alpha` per texel unit; s and t wrap (the texel tiles), the march ends where
// it leaves through the top or the bottom (w), after `shadow.resolution.w` voxels, or once the
// optical depth passes `shadow.shading.y`. Twin: `shadow_texel` in src/cpu/shadow_texel.rs.

@group(0) @binding(0) var<uniform> shadow: ShadowParams;
@group(0) @binding(1) var source: texture_3d<f32>;
@group(0) @binding(2) var volume: texture_storage_3d<rgba8unorm, write>;

const FAR: f32 = 1e30;
// A march that starts in matter this opaque first leaves it, counting nothing: a voxel inside a
// solid takes the shadow of the point where the light enters the solid, as the paper fills a
// solid's inside with its surface colour (3.2), for the slices' gaps show the inside.
const SOLID: f32 = 0.99;

// Time (texel units) to cross one voxel along each axis, FAR where the ray runs parallel.
fn crossing(dq: vec3<f32>) -> vec3<f32> {
    var out = vec3<f32>(FAR);
    for (var a = 0; a < 3; a++) {
        if (dq[a] != 0.0) {
            out[a] = 1.0 / abs(dq[a]);
        }
    }
    return out;
}

fn transmittance(voxel: vec3<i32>) -> f32 {
    let res = vec3<i32>(shadow.resolution.xyz);
    // Index space: voxel v spans [v, v + 1); the light's direction in voxels per texel unit.
    let dq = shadow.light.xyz * vec3<f32>(res);
    let delta = crossing(dq);
    let advance = vec3<i32>(sign(dq));
    // The march starts `bias` voxels (along the axis it crosses fastest) towards the light.
    var t = shadow.shading.z * min(delta.x, min(delta.y, delta.z));
    let start = vec3<f32>(voxel) + 0.5 + t * dq;
    var cell = vec3<i32>(floor(start));
    var next = vec3<f32>(FAR); // time of each axis's next boundary
    for (var a = 0; a < 3; a++) {
        if (dq[a] > 0.0) {
            next[a] = t + (f32(cell[a] + 1) - start[a]) / dq[a];
        } else if (dq[a] < 0.0) {
            next[a] = t + (f32(cell[a]) - start[a]) / dq[a];
        }
    }
    var optical = 0.0;
    var inside = true;
    for (var i = 0u; i < shadow.resolution.w && cell.z >= 0 && cell.z < res.z; i++) {
        var axis = 2;
        if (next.x <= next.y && next.x <= next.z) {
            axis = 0;
        } else if (next.y <= next.z) {
            axis = 1;
        }
        let wrapped = vec3<i32>((cell.xy % res.xy + res.xy) % res.xy, cell.z);
        let alpha = clamp(textureLoad(source, wrapped, 0).a, 0.0, 1.0);
        // A sliver (the start on a voxel's face, where f32 and f64 round apart) leaves nothing.
        let sliver = next[axis] - t < 1e-3 * min(delta.x, min(delta.y, delta.z));
        inside = inside && (alpha >= SOLID || sliver);
        if (!inside) {
            optical += shadow.light.w * alpha * (next[axis] - t);
        }
        t = next[axis];
        cell[axis] += advance[axis];
        next[axis] += delta[axis];
        if (optical > shadow.shading.y) {
            break;
        }
    }
    return exp(-optical);
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= shadow.resolution.xyz)) {
        return;
    }
    let v = textureLoad(source, vec3<i32>(id), 0);
    let ambient = shadow.shading.x;
    let light = ambient + (1.0 - ambient) * transmittance(vec3<i32>(id));
    textureStore(volume, id, vec4<f32>(v.rgb * light, v.a));
}
