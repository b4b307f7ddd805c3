// The light volume's lookup, for the marchers' shading (march.wgsl): the transmittance towards
// the light at an object-space point from the eight grid vertices around it, weighted trilinearly
// and by each vertex's openness, so that vertices buried in opaque matter do not darken the lit
// surface above them. Reads the kernel's `light_grid` and `light_volume`. CPU twin:
// src/methods/ray_march/light_volume.rs (same names).

// Weight of plain trilinear interpolation (where every vertex is buried).
const LIGHT_OPEN_FLOOR: f32 = 1e-3;

// Vertex i + o of the cell at i, weighted trilinearly by the fraction f: (weight x transmittance,
// weight x openness x transmittance, weight x openness).
fn light_corner(i: vec3<u32>, o: vec3<u32>, f: vec3<f32>) -> vec3<f32> {
    let n = light_grid.counts;
    let c = i + o;
    let s = unpack2x16unorm(light_volume[(c.z * n.y + c.y) * n.x + c.x]);
    let w3 = select(vec3<f32>(1.0) - f, f, o == vec3<u32>(1u));
    let w = w3.x * w3.y * w3.z;
    return vec3<f32>(w * s.x, w * s.y * s.x, w * s.y);
}

// Unrolled: lavapipe counts loop iterations against a per-invocation budget (see ray_march.wgsl).
fn light_transmittance(x: vec3<f32>) -> f32 {
    let n = light_grid.counts.xyz;
    let g = clamp((light_grid.to_grid * vec4<f32>(x, 1.0)).xyz, vec3<f32>(0.0), vec3<f32>(n - 1u));
    let i = min(vec3<u32>(g), n - 2u);
    let f = g - vec3<f32>(i);
    let sum = light_corner(i, vec3<u32>(0u, 0u, 0u), f) + light_corner(i, vec3<u32>(1u, 0u, 0u), f)
        + light_corner(i, vec3<u32>(0u, 1u, 0u), f) + light_corner(i, vec3<u32>(1u, 1u, 0u), f)
        + light_corner(i, vec3<u32>(0u, 0u, 1u), f) + light_corner(i, vec3<u32>(1u, 0u, 1u), f)
        + light_corner(i, vec3<u32>(0u, 1u, 1u), f) + light_corner(i, vec3<u32>(1u, 1u, 1u), f);
    return (sum.y + LIGHT_OPEN_FLOOR * sum.x) / (sum.z + LIGHT_OPEN_FLOOR);
}
