// Evaluates a hypertexture's noise, soft object, table lookup, vector field, density and colour at given points (twin tests); CPU twin src/cpu/hypertexture.rs.
#include "shared/types.wgsl"
#include "shared/hypertexture.wgsl"

@group(0) @binding(0) var<uniform> hyper: HyperParams;
@group(0) @binding(1) var<storage, read> hyper_noises: array<HyperNoise>;
@group(0) @binding(2) var<storage, read> transfer_tables: array<f32>;
// xyz: the point (object space); w: a noise seed (u32 bits).
@group(0) @binding(3) var<storage, read> probe_points: array<vec4<f32>>;
// Four per point: (simplex3(p, seed), O(p), table 0 at fract(|p.x|), simplex4((p, 0.37 p.x + 1.3),
// seed)), (V(p), 0),
// (density, simplex3_tiled(p, seed, the first noise's tile), 0, 0), rgba of the density.
@group(0) @binding(4) var<storage, read_write> probe_values: array<vec4<f32>>;
// Mesh objects: the baked grid and its largest inside distance (f32 bits); stand-ins otherwise.
@group(0) @binding(5) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> mesh_depth: array<u32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&probe_points)) {
        return;
    }
    let p = probe_points[i].xyz;
    let seed = bitcast<u32>(probe_points[i].w);
    let n4 = simplex4(vec4<f32>(p, 0.37 * p.x + 1.3), seed);
    probe_values[4u * i] = vec4<f32>(simplex3(p, seed), object_density(p), transfer_lookup(0u, fract(abs(p.x))), n4);
    probe_values[4u * i + 1u] = vec4<f32>(vector_field(p), 0.0);
    let density = hyper_density(p);
    let tiled = simplex3_tiled(p, seed, vec3<i32>(hyper_noises[0].tile.xyz));
    probe_values[4u * i + 2u] = vec4<f32>(density, tiled, 0.0, 0.0);
    probe_values[4u * i + 3u] = hyper_color(density);
}
