// Volume objects (OpenVDB grids): one thread per pixel marches the grid's index box front to back, resumable across dispatches; RayMarch samples each step's middle, Reference (`exact`) integrates the optical depth of each voxel cell exactly; CPU twin src/methods/volume/march_volume.rs.
#include "shared/types.wgsl"
#include "shared/volume.wgsl"

// Reference: the ray is cut at every voxel cell's faces, and the optical depth of each piece
// (the trilinear interpolant is a cubic along it) is integrated by Simpson's rule, exactly.
override exact: bool = false;
// Shading as hypertextures have it: Phong with the density gradient, shadow rays to the light.
override phong: bool = false;
override shadows: bool = false;
const MIN_TRANSMITTANCE: f32 = 1e-4;
// Raster depth is coarse far from the camera: opaque surfaces are moved back by this margin.
const DEPTH_SLACK: f32 = 2e-3;

// Work per dispatch is bounded by `volume_params.budget` (loop iterations): lavapipe ends every
// loop of an invocation after 65535 iterations in all, so the pass is dispatched
// `volume_dispatches` times and each pixel resumes from `volume_state`.

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> volume_params: VolumeParams;
@group(0) @binding(2) var<storage, read> volume_table: array<u32>;
@group(0) @binding(3) var volume_density: texture_3d<f32>;
@group(0) @binding(4) var volume_color: texture_3d<f32>;
@group(0) @binding(5) var depth: texture_depth_2d;
@group(0) @binding(6) var<storage, read_write> volume_state: array<MarchState>;

// Extinction (per world unit) at index point x.
fn extinction(x: vec3<f32>) -> f32 {
    return volume_params.medium.w * volume_density_at(x);
}

// Transmittance from index point x to the box's exit towards the light (index direction l,
// one world unit long), by the midpoint rule at the shadow step; and the samples it took.
fn shadow(x: vec3<f32>, l: vec3<f32>) -> vec2<f32> {
    let exit = max(volume_span(x, l, volume_params.box_lo.xyz, volume_params.box_hi.xyz).y, 0.0);
    let n = u32(clamp(ceil(exit / volume_params.box_hi.w), 1.0, f32(volume_params.budget.y)));
    let h = exit / f32(n);
    var tau = 0.0;
    for (var j = 0u; j < n; j++) {
        tau += extinction(x + l * ((f32(j) + 0.5) * h)) * h;
    }
    return vec2<f32>(exp(-tau), f32(n));
}

// The light scattered towards the eye at index point x (world ray d): albedo times colour,
// lit as hypertextures are (ambient, Phong with the density gradient, shadows); and the
// iterations it took.
fn shade(x: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let albedo = volume_params.medium.rgb * volume_color_at(x);
    if (!phong) {
        return vec4<f32>(albedo, 0.0);
    }
    // World gradient = A^T (index gradient), A the linear part of world to index.
    let e = 0.5;
    let gi = vec3<f32>(
        volume_density_at(x + vec3<f32>(e, 0.0, 0.0)) - volume_density_at(x - vec3<f32>(e, 0.0, 0.0)),
        volume_density_at(x + vec3<f32>(0.0, e, 0.0)) - volume_density_at(x - vec3<f32>(0.0, e, 0.0)),
        volume_density_at(x + vec3<f32>(0.0, 0.0, e)) - volume_density_at(x - vec3<f32>(0.0, 0.0, e)),
    );
    let m = volume_params.to_index;
    let g = transpose(mat3x3<f32>(m[0].xyz, m[1].xyz, m[2].xyz)) * gi;
    let len = length(g);
    let normal = select(-d, -g / len, len > 1e-12);
    let light = frame.light_dir.xyz;
    var lit = vec2<f32>(1.0, 0.0);
    if (shadows) {
        lit = shadow(x, (m * vec4<f32>(light, 0.0)).xyz);
    }
    let ambient = frame.light_dir.w;
    let diffuse = max(dot(normal, light), 0.0);
    let half_way = normalize(light - d);
    let specular = select(0.0, 0.25 * pow(max(dot(normal, half_way), 0.0), 32.0), diffuse > 0.0);
    let colour = albedo * (ambient + (1.0 - ambient) * diffuse * lit.x) + vec3<f32>(specular * lit.x);
    return vec4<f32>(colour, lit.y);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let pixel = id.y * size.x + id.x;
    let state = volume_state[pixel];
    if (state.resume.z > 0.0) {
        return;
    }
    let sx = 2.0 * (f32(id.x) + 0.5) * frame.viewport.z - 1.0;
    let sy = 1.0 - 2.0 * (f32(id.y) + 0.5) * frame.viewport.w;
    let d = normalize(frame.forward.xyz + volume_params.right.xyz * sx + volume_params.up.xyz * sy);
    // The ray in index space: x(t) = origin + dir t at world distance t from the eye.
    let origin = volume_params.to_index[3].xyz;
    let dir = (volume_params.to_index * vec4<f32>(d, 0.0)).xyz;
    let span = volume_span(origin, dir, volume_params.box_lo.xyz, volume_params.box_hi.xyz);
    let near = volume_params.right.w;
    let far = volume_params.up.w;
    let cos_d = dot(d, frame.forward.xyz);
    var t1 = span.y;
    // Opaque surfaces already drawn stop the ray.
    let z = textureLoad(depth, vec2<i32>(id.xy), 0);
    if (z < 1.0) {
        t1 = min(t1, far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK));
    }
    let t0 = max(span.x, near / cos_d);
    let step = volume_params.box_lo.w;
    var rgb = state.color.rgb;
    var transmittance = 1.0 - state.color.a;
    var budget = i32(volume_params.budget.x);
    let worst = i32(volume_params.budget.z);
    var at = state.resume.x;
    var done = false;
    if (!exact) {
        // Samples t0 + (k + 1/2) h of whole steps over [t0, t1]; `at` is the next k.
        var n = 0u;
        var h = 0.0;
        if (t1 > t0) {
            n = u32(max(ceil((t1 - t0) / step), 1.0));
            h = (t1 - t0) / f32(n);
        }
        var k = u32(at);
        while (k < n && transmittance >= MIN_TRANSMITTANCE && budget >= worst) {
            budget -= 1;
            let x = origin + dir * (t0 + (f32(k) + 0.5) * h);
            let c = floor(x);
            let b = volume_brick(vec3<i32>(c));
            if (b.x == 0u) {
                // An empty leaf or top cell: on to the first sample past it.
                let side = f32(b.y);
                let lo = floor(c / side) * side;
                let exit = volume_span(origin, dir, lo, lo + side).y;
                k = max(k + 1u, u32(clamp(ceil((exit - t0) / h - 0.5), 0.0, f32(n))));
                continue;
            }
            let sigma = volume_params.medium.w * volume_lerp(volume_corners(vec3<i32>(c)), x - c);
            if (sigma > 0.0) {
                let alpha = 1.0 - exp(-sigma * h);
                let s = shade(x, d);
                budget -= i32(s.w);
                rgb += s.rgb * alpha * transmittance;
                transmittance *= 1.0 - alpha;
            }
            k++;
        }
        at = f32(k);
        done = k >= n;
    } else {
        // Pieces of the ray within one voxel cell, each cut into parts of at most `step`;
        // `at` is where the next part starts (0: at t0).
        var t = max(at, t0);
        // A nudge of 1e-4 voxel along the ray finds the cell a piece lies in.
        let nudge = 1e-4 / max(length(dir), 1e-30);
        while (t < t1 && transmittance >= MIN_TRANSMITTANCE && budget >= worst) {
            budget -= 1;
            let ahead = min(t + nudge, 0.5 * (t + t1));
            let c = floor(origin + dir * ahead);
            let b = volume_brick(vec3<i32>(c));
            if (b.x == 0u) {
                let side = f32(b.y);
                let lo = floor(c / side) * side;
                t = min(max(volume_span(origin, dir, lo, lo + side).y, ahead), t1);
                continue;
            }
            let end = min(max(volume_span(origin, dir, c, c + 1.0).y, ahead), t1);
            let corners = volume_corners(vec3<i32>(c));
            let m = max(ceil((end - t) / step), 1.0);
            let h = (end - t) / m;
            let start = t;
            for (var j = 0.0; j < m; j += 1.0) {
                if (budget < worst || transmittance < MIN_TRANSMITTANCE) {
                    break;
                }
                budget -= 1;
                let a = start + j * h;
                let fa = volume_lerp(corners, origin + dir * a - c);
                let fm = volume_lerp(corners, origin + dir * (a + 0.5 * h) - c);
                let fb = volume_lerp(corners, origin + dir * (a + h) - c);
                let tau = volume_params.medium.w * h * (fa + 4.0 * fm + fb) / 6.0;
                if (tau > 0.0) {
                    let alpha = 1.0 - exp(-tau);
                    let s = shade(origin + dir * (a + 0.5 * h), d);
                    budget -= i32(s.w);
                    rgb += s.rgb * alpha * transmittance;
                    transmittance *= 1.0 - alpha;
                }
                t = select(a + h, end, j + 1.0 >= m);
            }
        }
        at = t;
        done = t >= t1;
    }
    let finished = done || transmittance < MIN_TRANSMITTANCE;
    volume_state[pixel] = MarchState(
        vec4<f32>(rgb, 1.0 - transmittance),
        vec4<f32>(at, state.resume.y + f32(i32(volume_params.budget.x) - budget), select(0.0, 1.0, finished), 0.0),
    );
}
