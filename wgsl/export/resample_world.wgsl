// `voltex export --world`: a textured object's look resampled into world voxels. One workgroup per
// 8^3 leaf the shell touches; each invocation fills one x-row of it. A voxel lets through the mean
// transmittance (across one voxel) of n^3 sub-points spread over its cell (n from the footprint of a voxel in texel voxels): per
// sub-point the exact inverse prism map (shared/prism_map.wgsl) of every prism listed for the
// leaf gives (s, t, w), and the texel is filtered trilinearly there. A sub-point takes the first
// prism that holds it: one on a side two prisms share counts once. CPU twin:
// src/render/export/resample_world.rs.
#include "shared/types.wgsl"
#include "shared/prism_map.wgsl"

@group(0) @binding(0) var<uniform> world_params: WorldParams;
// Per leaf of this dispatch: xyz its first voxel (index space), w its first entry in
// world_prism_ids; one more entry ends the last leaf's list.
@group(0) @binding(1) var<storage, read> world_leaves: array<vec4<i32>>;
// Per leaf, the prisms whose bounds meet it.
@group(0) @binding(2) var<storage, read> world_prism_ids: array<u32>;
// The shell relative to the anchor voxel's centre (src/mesh/shell.rs).
@group(0) @binding(3) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(4) var<storage, read> shell_prisms: array<Prism>;
// Per prism, its bounding sphere (centre relative to the anchor, radius).
@group(0) @binding(7) var<storage, read> prism_spheres: array<vec4<f32>>;
// The texel at full precision (rgba32float, premultiplied), read without a sampler.
@group(0) @binding(5) var texel_volume: texture_3d<f32>;
// Per voxel (leaf by leaf, 512 each in OpenVDB's x-major order): x the extinction per world unit
// (from the sub-points' mean transmittance across the voxel), yzw the opacity-weighted colour.
@group(0) @binding(6) var<storage, read_write> world_voxels: array<vec4<f32>>;

// As the Reference: opacity below 1 keeps the extinction finite; a fainter sample adds nothing.
const MAX_ALPHA: f32 = 0.999999;
const MIN_ALPHA: f32 = 1e-6;

// 1 - exp(-y) for y >= 0, without the cancellation of small y (WGSL has no expm1).
fn one_minus_exp(y: f32) -> f32 {
    if (y < 1e-2) {
        return y * (1.0 - y * (0.5 - y * (1.0 / 6.0 - y / 24.0)));
    }
    return 1.0 - exp(-y);
}

// -ln(1 - x) for x in [0, 1] (infinite at 1), without the cancellation of small x (no log1p).
fn minus_log_one_minus(x: f32) -> f32 {
    if (x < 1e-2) {
        return x * (1.0 + x * (0.5 + x * (1.0 / 3.0 + x * 0.25)));
    }
    return -log(1.0 - x);
}

#include "shared/shell_prism.wgsl"

// Texel voxel i along an axis of n: repeating (s, t) or clamped (w).
fn wrap_axis(i: i32, n: i32, repeat: bool) -> i32 {
    if (repeat) {
        return ((i % n) + n) % n;
    }
    return clamp(i, 0, n - 1);
}

// Trilinear filtering of the texel at (s, t, w), centres at (i + 0.5) / n, as the volume sampler.
fn texel_at(uvw: vec3<f32>) -> vec4<f32> {
    let n = vec3<i32>(world_params.resolution.xyz);
    let x = uvw * vec3<f32>(n) - 0.5;
    let i0 = floor(x);
    let f = x - i0;
    let i = vec3<i32>(i0);
    var out = vec4<f32>(0.0);
    for (var k = 0; k < 8; k++) {
        let o = vec3<i32>(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        let w = select(1.0 - f, f, o == vec3<i32>(1));
        let at = vec3<i32>(
            wrap_axis(i.x + o.x, n.x, true),
            wrap_axis(i.y + o.y, n.y, true),
            wrap_axis(i.z + o.z, n.z, false),
        );
        out += w.x * w.y * w.z * textureLoad(texel_volume, at, 0);
    }
    return out;
}

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let leaf = group.x;
    if (leaf >= world_params.counts.x) {
        return;
    }
    let entry = world_leaves[leaf];
    let first = u32(entry.w);
    let end = u32(world_leaves[leaf + 1u].w);
    let n = world_params.anchor.w;
    let voxel = world_params.voxel.x;
    let inv_length = world_params.voxel.y;
    for (var x = 0; x < 8; x++) {
        let ijk = entry.xyz + vec3<i32>(x, i32(local >> 3u), i32(local & 7u));
        let centre = vec3<f32>(ijk - world_params.anchor.xyz) * voxel;
        var sigma = 0.0;
        var covered = 0.0;
        var emitted = vec3<f32>(0.0);
        for (var q = 0; q < n * n * n; q++) {
            let sub = (vec3<f32>(vec3<i32>(q % n, (q / n) % n, q / (n * n))) + 0.5) / f32(n) - 0.5;
            let p = centre + sub * voxel;
            for (var e = first; e < end; e++) {
                let index = world_prism_ids[e];
                let prism = shell_prisms[index];
                let sphere = prism_spheres[index];
                let d = p - sphere.xyz;
                if (dot(d, d) > sphere.w * sphere.w) {
                    continue;
                }
                var shape = load_shape(index);
                let c = prism_inverse(p, &shape);
                if (c.w < 0.0) {
                    continue;
                }
                let st = c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy;
                let texel = texel_at(vec3<f32>(st, c.w));
                let a = clamp(texel.w, 0.0, MAX_ALPHA);
                if (a > MIN_ALPHA) {
                    let s = -log(1.0 - a) * inv_length;
                    sigma += s;
                    let opacity = one_minus_exp(s * voxel);
                    covered += opacity;
                    emitted += texel.xyz / a * opacity;
                }
                break;
            }
        }
        // The extinction whose transmittance across the voxel is the sub-points' mean (those
        // without extinction let all the light through): a voxel half covered by an opaque
        // pattern lets half the light through, as the pattern does; the mean extinction would
        // make it opaque and grow dense silhouettes by up to a voxel. At most the mean
        // extinction, which it equals where the sub-points agree.
        let count = f32(n * n * n);
        let density = min(sigma / count, minus_log_one_minus(covered / count) / voxel);
        var colour = vec3<f32>(0.0);
        if (covered > 0.0) {
            colour = emitted / covered;
        }
        world_voxels[leaf * 512u + u32(x) * 64u + local] = vec4<f32>(density, colour);
    }
}
