// Draws view-aligned slice polygons with trilinear texel sampling, step-corrected opacity, premultiplied.
#include "shared/types.wgsl"
#include "shared/slice_shading.wgsl"

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
@group(0) @binding(11) var volume_layers: texture_2d_array<f32>;
@group(0) @binding(12) var normal_layers: texture_2d_array<f32>;

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
        let f = slice_vertex_frame(v);
        out.n_s = f.n_s;
        out.n_t = f.n_t;
        out.n_w = f.n_w;
    }
    return out;
}

// The texel's opacity over `opacity_length` (x) and over this pixel's ray between two planes (y).
fn slice_alpha(in: VsOut) -> vec2<f32> {
    let texel = texel_at(in.uvw, texel_level(dpdx(in.uvw), dpdy(in.uvw)));
    let step = slice_params.spacing / max(dot(normalize(in.rel), frame.forward.xyz), 1e-4);
    let a = clamp(texel.a, 0.0, 1.0);
    return vec2<f32>(a, 1.0 - pow(1.0 - min(a, 0.999999), step / object.opacity_length));
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let ray = normalize(in.rel);
    let level = texel_level(dpdx(in.uvw), dpdy(in.uvw));
    return slice_fragment(in.uvw, level, ray, slice_exponent(ray, object.opacity_length), SliceFrame(in.n_s, in.n_t, in.n_w));
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
