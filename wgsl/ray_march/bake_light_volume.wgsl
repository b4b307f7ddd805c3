// The light volume of a hypertexture object (`shadows: LightVolume(..)`): one thread per column of the light's grid marches the density away from the light, storing the transmittance towards it at every vertex; CPU twin src/methods/ray_march/light_volume.rs.
#include "shared/types.wgsl"
#include "shared/hypertexture.wgsl"
#include "shared/light_march.wgsl"

@group(0) @binding(0) var<uniform> hyper: HyperParams;
@group(0) @binding(1) var<storage, read> hyper_noises: array<HyperNoise>;
@group(0) @binding(2) var<storage, read> transfer_tables: array<f32>;
// Mesh objects: the baked grid and its largest inside distance (f32 bits); stand-ins otherwise.
@group(0) @binding(3) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> mesh_depth: array<u32>;
@group(0) @binding(5) var<uniform> light_grid: LightVolumeParams;
@group(0) @binding(6) var<storage, read_write> light_volume: array<u32>;

// What a shadow ray's sample sees (`shade` in march.wgsl).
fn light_opacity(p: vec3<f32>) -> f32 {
    return hyper_opacity(hyper_density(p));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= light_grid.counts.x || id.y >= light_grid.counts.y) {
        return;
    }
    light_column(id.xy);
}
