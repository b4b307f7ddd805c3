// One jump-flooding pass over a point grid (bake_point_grid.wgsl's first block): each inside sample takes, of its own and its 26 neighbours' closest boundary points at `counts.w` samples away, the nearest, so that after passes of halving steps every inside sample holds about its closest point of the kernels' boundary; CPU twin src/cpu/flood_point_grid.rs.
#include "shared/types.wgsl"

// lo, hi: the grid's corners; counts.w: the step in samples; size: samples per axis.
@group(0) @binding(0) var<uniform> grid_params: MeshGridParams;
// Per sample: the vector to its closest boundary point and the signed distance (positive inside;
// NO_SEED inside where none is known yet). Outside samples hold exact ones and are copied.
@group(0) @binding(1) var<storage, read> flood_from: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> flood_to: array<vec4<f32>>;

// Inside samples without a boundary point yet (twin: NO_SEED).
const NO_SEED: f32 = 3.0e38;

fn sample_point(i: vec3<u32>) -> vec3<f32> {
    let lo = grid_params.lo.xyz;
    let n = grid_params.size.xyz;
    return lo + (grid_params.hi.xyz - lo) * (vec3<f32>(i) / vec3<f32>(n - vec3<u32>(1u)));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = grid_params.size.xyz;
    if (any(id >= n)) {
        return;
    }
    let index = id.x + n.x * (id.y + n.y * id.z);
    var best = flood_from[index];
    if (best.w <= 0.0) {
        flood_to[index] = best;
        return;
    }
    let p = sample_point(id);
    let step = i32(grid_params.counts.w);
    for (var k = 0; k < 27; k++) {
        let d = vec3<i32>(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1) * step;
        let m = vec3<i32>(id) + d;
        if (k == 13 || any(m < vec3<i32>(0)) || any(m >= vec3<i32>(n))) {
            continue;
        }
        let mi = vec3<u32>(m);
        let s = flood_from[mi.x + n.x * (mi.y + n.y * mi.z)];
        if (s.w >= NO_SEED) {
            continue;
        }
        let v = sample_point(mi) + s.xyz - p;
        let dist = length(v);
        if (dist < best.w) {
            best = vec4<f32>(v, dist);
        }
    }
    flood_to[index] = best;
}
