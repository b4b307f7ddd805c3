// Bakes one level of one direction's slice images from a texel volume: each slice combines 2^level voxel slices.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> axis_bake: AxisBake;
@group(0) @binding(1) var volume: texture_3d<f32>;
@group(0) @binding(2) var destination: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(3) var<storage, read_write> axis_occupancy: array<atomic<u32>>;

// Combining n premultiplied voxels (a merge of slice pairs, level by level): the transmittance
// per unit length is the geometric mean, 1 - alpha = prod(1 - a_k)^(1/n), so the slab keeps its
// optical depth when drawn n times as thick; colours are averaged weighted by extinction
// -ln(1 - a_k), which does not depend on the side the slab is seen from.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = axis_bake.resolution.xyz;
    let direction = axis_bake.resolution.w;
    var size = r.xy;
    if (direction == 0u) {
        size = r.yz;
    } else if (direction == 1u) {
        size = r.xz;
    }
    let slices = axis_bake.level.z;
    if (id.x >= size.x || id.y >= size.y || id.z >= slices) {
        return;
    }
    let span = 1u << axis_bake.level.x;
    let begin = id.z * span;
    let end = min(begin + span, r[direction]);
    var optical = 0.0;
    var colour = vec3<f32>(0.0);
    for (var j = begin; j < end; j++) {
        var p = vec3<u32>(id.x, id.y, j);
        if (direction == 0u) {
            p = vec3<u32>(j, id.x, id.y);
        } else if (direction == 1u) {
            p = vec3<u32>(id.x, j, id.y);
        }
        let v = textureLoad(volume, p, 0);
        let a = clamp(v.a, 0.0, 1.0);
        if (a > 0.0) {
            let e = -log(max(1.0 - a, 1e-6));
            optical += e;
            colour += e * v.rgb / a;
        }
    }
    var out = vec4<f32>(0.0);
    if (optical > 0.0) {
        let alpha = 1.0 - exp(-optical / f32(end - begin));
        out = vec4<f32>(colour / optical * alpha, alpha);
    }
    textureStore(destination, id.xy, axis_bake.level.y + id.z, out);
    if (out.a >= 0.5 / 255.0) {
        atomicOr(&axis_occupancy[axis_bake.level.w + id.z], 1u);
    }
}
