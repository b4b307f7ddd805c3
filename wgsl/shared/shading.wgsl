// Shading precomputed at bake time (and usable per pixel): normals from gradients, Lambert and
// Phong with an ambient term. CPU twin: src/cpu/bake.rs (same names).

// Unit outward normal from a gradient; (0,0,1) where the gradient vanishes (deep inside a shape).
fn gradient_normal(g: vec3<f32>) -> vec3<f32> {
    let len = length(g);
    if (len < 1.0e-6) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    return g / len;
}

// Normalized direction, or (0,0,1) for a zero vector (a light must point somewhere).
fn safe_direction(v: vec3<f32>) -> vec3<f32> {
    return gradient_normal(v);
}

// albedo * (ambient + (1 - ambient) * max(N.L, 0)); `light` = (direction towards the light, ambient).
fn shade_lambert(albedo: vec3<f32>, normal: vec3<f32>, light: vec4<f32>) -> vec3<f32> {
    let l = safe_direction(light.xyz);
    return albedo * (light.w + (1.0 - light.w) * max(dot(normal, l), 0.0));
}

// The highlight of per-pixel lighting, the same for every method (draw_slices, trace_reference).
const PIXEL_SPECULAR: f32 = 0.25;
const PIXEL_SHININESS: f32 = 32.0;

// Lambert plus a white Blinn-Phong highlight, for per-pixel lighting of baked normals.
// `view` points from the surface towards the eye.
fn shade_phong(albedo: vec3<f32>, normal: vec3<f32>, light: vec4<f32>, view: vec3<f32>,
               specular: f32, shininess: f32) -> vec3<f32> {
    let l = safe_direction(light.xyz);
    let h = safe_direction(l + safe_direction(view));
    let lit = select(0.0, 1.0, dot(normal, l) > 0.0);
    let spec = specular * lit * pow(max(dot(normal, h), 0.0), shininess);
    return shade_lambert(albedo, normal, light) + vec3<f32>(spec);
}
