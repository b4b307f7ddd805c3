// Draws view-aligned slice polygons with trilinear texel sampling, step-corrected opacity, premultiplied.
#include "shared/types.wgsl"
#include "shared/shading.wgsl"
#include "shared/barycentrics.wgsl"

// Per-pixel (Phong) lighting from the baked normals instead of the shading baked into the texel.
override per_pixel_lighting: bool = false;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> object: ObjectParams;
@group(0) @binding(2) var<uniform> slice_params: SliceParams;
@group(0) @binding(3) var<storage, read> slice_vertices: array<SliceVertex>;
@group(0) @binding(4) var<storage, read> prisms: array<Prism>;
@group(0) @binding(5) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(6) var volume: texture_3d<f32>;
@group(0) @binding(7) var normals: texture_3d<f32>;
@group(0) @binding(8) var volume_sampler: sampler;
@group(0) @binding(9) var<storage, read> vertex_frames: array<VertexFrame>;
// AOVs (fs_coverage, fs_depth): the nearest opaque hit per pixel.
@group(0) @binding(10) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;

#include "shared/aov_coverage.wgsl"
#include "shared/aov_depth.wgsl"

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uvw: vec3<f32>,
    @location(1) rel: vec3<f32>,
    // Columns of the inverse-transpose of the texel-to-world Jacobian (up to scale) at this point.
    @location(2) n_s: vec3<f32>,
    @location(3) n_t: vec3<f32>,
    @location(4) n_w: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VsOut {
    let v = slice_vertices[index];
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.uvw = v.uvw.xyz;
    out.rel = v.position.xyz;
    if per_pixel_lighting {
        // The Jacobian J = [dP/ds, dP/dt, dP/dw] interpolated from the prism's vertices at this
        // point (barycentrics in the prism's cross-section at height w), so it is continuous
        // across prism edges; normals transform with cofactor(J) = det(J) inverse(J)^T.
        let prism = prisms[bitcast<u32>(v.position.w)];
        let ids = prism.vertices.xyz;
        let a = shell_vertices[ids.x];
        let b = shell_vertices[ids.y];
        let c = shell_vertices[ids.z];
        let w = v.uvw.z;
        let bary = barycentrics(v.position.xyz, mix(a.bottom.xyz, a.top.xyz, w), mix(b.bottom.xyz, b.top.xyz, w), mix(c.bottom.xyz, c.top.xyz, w), vec3<f32>(1.0 / 3.0));
        let fa = vertex_frames[ids.x];
        let fb = vertex_frames[ids.y];
        let fc = vertex_frames[ids.z];
        let ds = bary.x * fa.ds.xyz + bary.y * fb.ds.xyz + bary.z * fc.ds.xyz;
        let dt = bary.x * fa.dt.xyz + bary.y * fb.dt.xyz + bary.z * fc.dt.xyz;
        let dw = bary.x * (a.top.xyz - a.bottom.xyz) + bary.y * (b.top.xyz - b.bottom.xyz) + bary.z * (c.top.xyz - c.bottom.xyz);
        let sign_j = select(-1.0, 1.0, dot(ds, cross(dt, dw)) >= 0.0);
        out.n_s = cross(dt, dw) * sign_j;
        out.n_t = cross(dw, ds) * sign_j;
        out.n_w = cross(ds, dt) * sign_j;
    }
    return out;
}

// The texel's opacity over `opacity_length` (x) and over this pixel's ray between two planes (y).
fn slice_alpha(in: VsOut) -> vec2<f32> {
    let texel = textureSampleLevel(volume, volume_sampler, in.uvw, 0.0);
    let step = slice_params.spacing / max(dot(normalize(in.rel), frame.forward.xyz), 1e-4);
    let a = clamp(texel.a, 0.0, 1.0);
    return vec2<f32>(a, 1.0 - pow(1.0 - min(a, 0.999999), step / object.opacity_length));
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    // Level 0, as the Reference samples it. Mipmaps chosen by the sampler's implicit level cost
    // accuracy (a 3D mip also blurs along w, the shell's height profile) and depend on the adapter:
    // on torus_egg at 128x128 they doubled the FLIP against a 4x4-supersampled Reference (0.131
    // against 0.062) and differed by 0.029 between llvmpipe and an NVIDIA H100.
    let texel = textureSampleLevel(volume, volume_sampler, in.uvw, 0.0);
    // World length of this pixel's ray between two planes: spacing / cos(angle to the view axis).
    let ray = normalize(in.rel);
    let step = slice_params.spacing / max(dot(ray, frame.forward.xyz), 1e-4);
    let a = clamp(texel.a, 0.0, 1.0);
    let corrected = 1.0 - pow(1.0 - min(a, 0.999999), step / object.opacity_length);
    var rgb = texel.rgb * select(0.0, corrected / a, a > 1e-6);
    if per_pixel_lighting {
        let tex_normal = textureSampleLevel(normals, volume_sampler, in.uvw, 0.0).xyz;
        var n = in.n_s * tex_normal.x + in.n_t * tex_normal.y + in.n_w * tex_normal.z;
        n = select(-ray, normalize(n), dot(n, n) > 1e-20);
        let albedo = texel.rgb * select(0.0, 1.0 / a, a > 1e-6);
        rgb = corrected * shade_phong(albedo, n, frame.light_dir, -ray, PIXEL_SPECULAR, PIXEL_SHININESS);
    }
    return vec4<f32>(rgb * frame.light_color.rgb, corrected);
}

// Coverage AOV: the opacity fs_main draws with, into the object's slot.
@fragment
fn fs_coverage(in: VsOut) -> Coverage {
    return coverage_slot(object.index, slice_alpha(in).y);
}

// Depth AOV: where the texel is opaque.
@fragment
fn fs_depth(in: VsOut) {
    if (slice_alpha(in).x >= OPAQUE_ALPHA) {
        record_opaque_depth(fragment_pixel(in.clip), dot(in.rel, frame.forward.xyz));
    }
}
