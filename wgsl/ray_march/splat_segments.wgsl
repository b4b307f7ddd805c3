// EWA-style splatting (Gilet & Dischler 2009, section 5.1): one workgroup per interior splat (a sphere) and block of its screen footprint marches, for each pixel of the block, the ray's samples inside the sphere and adds them, weighted by a truncated Gaussian of the ray's distance to the centre, to the pixel's depth slabs. CPU twin: src/methods/ray_march/splat_segments.rs.
#include "shared/types.wgsl"
#include "shared/hypertexture.wgsl"
#include "shared/segments.wgsl"
#include "shared/march.wgsl"

// The samples are the bounds march's own, t0 + (k + 1/2) h (shared/march.wgsl), so every splat
// covering a sample sees the same density there; what the weights blend is each splat's share
// of a slab. Workgroup (splat, y): y is (block, piece), a block of 64 x `pixels` footprint
// pixels (lane l takes pixels l, l + 64, ...: neighbouring lanes march neighbouring rays, whose
// work is alike) and a piece of each chord's samples, sized on the host (`segments.splatting`)
// so that no invocation runs more than lavapipe's 65535 loop iterations (samples x evaluations
// per sample).
// Standard deviation of the screen-space Gaussian, in units of the sphere's projected radius;
// it is cut at that radius (weight exp(-2) there), so rim-only coverage keeps a usable weight.
const SIGMA: f32 = 0.5;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<storage, read> hyper_noises: array<HyperNoise>;
@group(0) @binding(3) var<storage, read> transfer_tables: array<f32>;
@group(0) @binding(4) var depth: texture_depth_2d;
@group(0) @binding(5) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> mesh_depth: array<u32>;
@group(0) @binding(7) var<uniform> segments: SegmentParams;
@group(0) @binding(8) var<storage, read> interior_splats: array<Splat>;
@group(0) @binding(9) var<storage, read_write> splat_slabs: array<atomic<u32>>;
// `shadows: LightVolume(..)`: the object's light volume (stand-ins otherwise).
@group(0) @binding(10) var<uniform> light_grid: LightVolumeParams;
@group(0) @binding(11) var<storage, read> light_volume: array<u32>;

// Adds one splat's stretch of slab j: `count` samples from `first`, optical depth `tau`, colour
// times optical depth `colour`, out of the slab's `samples`.
fn add_slab(base: u32, j: u32, first: u32, count: u32, samples: u32, weight: f32, tau: f32, colour: vec3<f32>) {
    let w = base + SLAB_HEADER + SLAB_WORDS * j;
    let cut = min(1.0, TAU_CAP / max(tau, 1e-30));
    let t = u32(round(weight * tau * cut * TAU_SCALE));
    let c = vec3<u32>(round(weight * min(colour * cut, vec3<f32>(4.0 * TAU_CAP)) * TAU_SCALE));
    atomicAdd(&splat_slabs[w], t);
    atomicAdd(&splat_slabs[w + 1u], c.x);
    atomicAdd(&splat_slabs[w + 2u], c.y);
    atomicAdd(&splat_slabs[w + 3u], c.z);
    atomicAdd(&splat_slabs[w + 4u], u32(round(weight * f32(count) / f32(samples) * SHARE_SCALE)));
    atomicMax(&splat_slabs[w + 5u], ~first);
    atomicMax(&splat_slabs[w + 6u], first + count);
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if (group.x >= segments.counts.y) {
        return;
    }
    let splat = interior_splats[group.x];
    let centre = splat.center.xyz;
    let radius = splat.center.w;
    let rect = footprint(centre, radius);
    if (any(rect.zw < rect.xy)) {
        return;
    }
    let columns = u32(rect.z - rect.x + 1);
    let pixels = columns * u32(rect.w - rect.y + 1);
    let pieces = segments.splatting.z;
    let per_piece = segments.splatting.w;
    let piece = group.y % pieces;
    let first_pixel = (group.y / pieces) * 64u * segments.splatting.y + lane;
    let last_pixel = min(first_pixel + 64u * segments.splatting.y, pixels);
    let size = vec2<u32>(frame.viewport.xy);
    let slabs = segments.splatting.x;
    let origin = hyper.to_local[3].xyz;
    let empty = hyper_color(0.0);
    let oc = origin - centre;
    for (var i = first_pixel; i < last_pixel; i += 64u) {
        let p = vec2<u32>(u32(rect.x) + i % columns, u32(rect.y) + i / columns);
        let d = pixel_direction(p);
        let dir = (hyper.to_local * vec4<f32>(d, 0.0)).xyz;
        let range = march_range(p, d, origin, dir);
        let n = u32(range.z);
        // The chord |origin + dir t - centre| <= radius; 1 - q^2 = disc / (a r^2) with q the
        // ray's distance to the centre over the radius: sin of the ray's angle to the centre over
        // sin of the sphere's angular radius (the pixel's distance to the projected centre in
        // projected radii, up to perspective).
        let a = dot(dir, dir);
        let b = dot(dir, oc);
        let disc = b * b - a * (dot(oc, oc) - radius * radius);
        if (n == 0u || disc <= 0.0) {
            continue;
        }
        let q2 = max(1.0 - disc / (a * radius * radius), 0.0);
        let weight = exp(-0.5 * q2 / (SIGMA * SIGMA));
        let root = sqrt(disc);
        let t0 = range.x;
        let h = range.y;
        // Samples t0 + (k + 1/2) h inside the chord, then this row's piece of them.
        let lo = u32(clamp(ceil(((-b - root) / a - t0) / h - 0.5), 0.0, f32(n)));
        let hi = u32(clamp(floor(((-b + root) / a - t0) / h - 0.5) + 1.0, 0.0, f32(n)));
        let k0 = lo + piece * per_piece;
        let k1 = min(k0 + per_piece, hi);
        if (k0 >= k1) {
            continue;
        }
        let base = (p.y * size.x + p.x) * slab_stride();
        var j = k0 * slabs / n;
        var next = slab_start(j + 1u, n);
        var first = k0;
        var tau = 0.0;
        var colour = vec3<f32>(0.0);
        var evaluations = 0u;
        let noised = noised_evaluations;
        for (var k = k0; k < k1; k++) {
            if (k >= next) {
                add_slab(base, j, first, k - first, next - slab_start(j, n), weight, tau, colour);
                j = k * slabs / n;
                next = slab_start(j + 1u, n);
                first = k;
                tau = 0.0;
                colour = vec3<f32>(0.0);
            }
            let x = origin + dir * (t0 + (f32(k) + 0.5) * h);
            let density = hyper_density(x);
            evaluations += 1u;
            var rgba = empty;
            if (density > 0.0) {
                rgba = hyper_color(density);
            }
            if (rgba.a > 1e-6) {
                // The step's optical depth: -ln of its step-corrected transmittance.
                let depth_k = -log(1.0 - min(rgba.a, MAX_ALPHA)) * h / hyper.bounds_max.w;
                var c = rgba.rgb;
                if (phong) {
                    let shaded = shade(x, d, c);
                    c = shaded.xyz;
                    evaluations += u32(shaded.w);
                }
                tau += depth_k;
                colour += c * depth_k;
            }
        }
        add_slab(base, j, first, k1 - first, next - slab_start(j, n), weight, tau, colour);
        atomicAdd(&splat_slabs[base], evaluations);
        atomicAdd(&splat_slabs[base + 1u], noised_evaluations - noised);
        atomicMax(&splat_slabs[base + 2u], n);
    }
}
