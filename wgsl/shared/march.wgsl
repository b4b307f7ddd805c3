// Sampling and shading of hypertexture rays, shared by ray_march.wgsl and splat_segments.wgsl:
// the ray's span and step, the step-corrected opacity, Phong and shadow rays. Reads the kernel's
// `frame`, `hyper`, `depth`, `light_grid` and `light_volume`. CPU twin: src/methods/ray_march/march.rs.
#include "shared/light_volume.wgsl"

// Shading, compiled out when off (set per object from `RayMarch(shading: ...)`): Phong with the
// density gradient by central differences (six more density evaluations), and a secondary ray
// towards the light for shadows.
override phong: bool = false;
override shadows: bool = false;
// `shadows: LightVolume(..)`: the shadows are read from the light volume, not marched.
override volume_shadows: bool = false;
const MIN_TRANSMITTANCE: f32 = 1e-4;
const MAX_ALPHA: f32 = 0.999999;
// Raster depth is coarse far from the camera: opaque surfaces are moved back by this margin.
const DEPTH_SLACK: f32 = 2e-3;

// The sampled stretch of the unit world ray d (object space: origin + dir t) of pixel p:
// (t0, h, n) for samples t0 + (k + 1/2) h, k < n, the bounds' span cut into whole steps, clipped
// by the near plane and opaque surfaces already drawn (n = 0: the ray misses).
fn march_range(p: vec2<u32>, d: vec3<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let cos_d = dot(d, frame.forward.xyz);
    let near = hyper.right.w;
    let far = hyper.up.w;
    let span = bounds_span(origin, dir);
    var t1 = span.y;
    // Opaque surfaces already drawn (base surfaces) stop the ray.
    let z = textureLoad(depth, vec2<i32>(p), 0);
    if (z < 1.0) {
        t1 = min(t1, far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK));
    }
    let t0 = max(span.x, near / cos_d);
    // Whole steps over [t0, t1], sampled at their middles.
    var n = 0u;
    var h = 0.0;
    if (t1 > t0) {
        let step = hyper.bounds_min.w;
        n = u32(max(ceil((t1 - t0) / step), 1.0));
        h = (t1 - t0) / f32(n);
    }
    return vec3<f32>(t0, h, f32(n));
}

// The step-corrected opacity shared by every method: 1 - (1 - a)^(step / opacity_length).
fn step_alpha(a: f32, step: f32) -> f32 {
    return 1.0 - exp2(log2(1.0 - min(a, MAX_ALPHA)) * step / hyper.bounds_max.w);
}

// Phong as the Reference method shades it, at x (object space): the outward normal from the
// world-space density gradient by central differences (facing the viewer where the gradient
// vanishes), and with `shadows` the transmittance towards the light up to the bounds' exit, which
// dims the diffuse and specular terms. Gradient and shadow samples share one loop so the density
// is compiled once for both (lavapipe makes a much slower kernel of several inlined copies).
// Returns the colour (xyz) and the density evaluations it took (w).
fn shade(x: vec3<f32>, ray: vec3<f32>, albedo: vec3<f32>) -> vec4<f32> {
    let e = hyper.march.y;
    var l = vec3<f32>(0.0);
    var h = 0.0;
    var n = 0u;
    if (shadows) {
        l = (hyper.to_local * vec4<f32>(frame.light_dir.xyz, 0.0)).xyz;
        let exit = max(bounds_span(x, l).y, 0.0);
        n = u32(clamp(ceil(exit / hyper.march.x), 1.0, f32(hyper.budget.y)));
        h = exit / f32(n);
    }
    // The light volume: the shadow ray's first sample, then the volume from the end of its step
    // on. The first sample decides how much light a sample just inside dense matter gets (a
    // skin far thinner than the volume's cells); from there on the volume holds the shadow ray.
    if (volume_shadows) {
        n = min(n, 1u);
    }
    var g = vec3<f32>(0.0);
    var lit = 1.0;
    var j = 0u;
    while (j < 6u + n && lit >= MIN_TRANSMITTANCE) {
        let axis = min(j / 2u, 2u);
        let side = select(-1.0, 1.0, (j & 1u) == 0u);
        var p = x + l * ((f32(j) - 5.5) * h);
        if (j < 6u) {
            p = x + hyper.to_local[axis].xyz * (side * e);
        }
        let density = hyper_density(p);
        if (j < 6u) {
            g[axis] += side * density;
        } else {
            lit *= 1.0 - step_alpha(hyper_opacity(density), h);
        }
        j++;
    }
    if (shadows && volume_shadows && lit >= MIN_TRANSMITTANCE) {
        lit *= light_transmittance(x + l * h);
    }
    let len = length(g);
    let normal = select(-ray, -g / len, len > 1e-12);
    let light = frame.light_dir.xyz;
    let ambient = frame.light_dir.w;
    let half_way = normalize(light - ray);
    let diffuse = max(dot(normal, light), 0.0);
    let specular = select(0.0, 0.25 * pow(max(dot(normal, half_way), 0.0), 32.0), diffuse > 0.0);
    let colour = albedo * (ambient + (1.0 - ambient) * diffuse * lit) + vec3<f32>(specular * lit);
    return vec4<f32>(colour, f32(j));
}

