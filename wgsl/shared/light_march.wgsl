// The light volume's bake, for kernels of any density (bake_light_volume.wgsl for hypertextures):
// one column of the grid marched from the light's side away from it. At each vertex it stores
// the transmittance towards the light (its shadow ray: `m` sub-steps per layer, sampled at their
// middles, with the shared step-corrected opacity) and its openness (the transmittance of one
// layer of the matter at the vertex), packed as two unorm16. The kernel supplies
// `light_opacity(p)`, the opacity per opacity length at an object-space point, and declares
// `light_grid` and `light_volume`. CPU twin: src/methods/ray_march/light_volume.rs.

const LIGHT_MIN_TRANSMITTANCE: f32 = 1e-4;

// 1 - (1 - a)^(length / opacity length), as `step_alpha` (march.wgsl).
fn light_alpha(a: f32, length: f32) -> f32 {
    return 1.0 - exp2(log2(1.0 - min(a, 0.999999)) * length / light_grid.u.w);
}

fn light_column(ij: vec2<u32>) {
    let n = light_grid.counts;
    let w = light_grid.w.xyz;
    let base = light_grid.origin.xyz + f32(ij.x) * light_grid.u.xyz + f32(ij.y) * light_grid.v.xyz;
    var t = 1.0;
    for (var k = 0u; k < n.z; k++) {
        let p = base + f32(k) * w;
        // Once dark, a column stays dark: its sub-steps are skipped (the openness is not).
        if (k > 0u && t >= LIGHT_MIN_TRANSMITTANCE) {
            for (var s = 0u; s < n.w; s++) {
                let q = p - w * ((f32(s) + 0.5) / f32(n.w));
                t *= 1.0 - light_alpha(light_opacity(q), light_grid.origin.w);
            }
        }
        let open = 1.0 - light_alpha(light_opacity(p), light_grid.v.w);
        light_volume[(k * n.y + ij.y) * n.x + ij.x] = pack2x16unorm(vec2<f32>(t, open));
    }
}
