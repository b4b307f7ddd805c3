// Draws extruded axis-aligned slices from the slice-image arrays: binary alpha test (depth-written) or step-corrected blending.
#include "shared/types.wgsl"

// Blend semi-transparent slices back to front instead of the alpha test (set per object).
override blended_slices: bool = false;
// MIP-mapped slice images (`mipmaps: true`): the level from the fragment's footprint.
override mipmapped_slices: bool = false;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> object: ObjectParams;
@group(0) @binding(2) var<storage, read> axis_vertices: array<AxisVertex>;
@group(0) @binding(3) var axis_slices_s: texture_2d_array<f32>;
@group(0) @binding(4) var axis_slices_t: texture_2d_array<f32>;
@group(0) @binding(5) var axis_slices_w: texture_2d_array<f32>;
// Repeats along both image axes (w slices: s, t); the side sampler clamps the image's v (= w).
@group(0) @binding(6) var axis_sampler: sampler;
@group(0) @binding(7) var axis_sampler_side: sampler;
// AOVs (fs_coverage, fs_depth): the nearest opaque hit per pixel.
@group(0) @binding(8) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;

#include "shared/aov_coverage.wgsl"
#include "shared/aov_depth.wgsl"

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) rel: vec3<f32>,
    @location(2) @interpolate(flat) layer: u32,
    @location(3) @interpolate(flat) direction: u32,
    @location(4) @interpolate(flat) normal: vec4<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VsOut {
    let v = axis_vertices[index];
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.uv = v.texcoord.xy;
    out.rel = v.position.xyz;
    out.layer = u32(v.texcoord.z + 0.5);
    out.direction = u32(v.texcoord.w + 0.5);
    out.normal = vec4<f32>(v.normal.xyz, v.position.w);
    return out;
}

// The slice image's sample: albedo, opacity over `opacity_length`, and step-corrected opacity.
struct SliceSample {
    albedo: vec3<f32>,
    alpha: f32,
    corrected: f32,
}

// Samples of the footprint filter along its longer axis, at most.
const MAX_FOOTPRINT_SAMPLES: u32 = 8u;

// One trilinear sample of the slice image at `uv` and MIP level `level`.
fn slice_at(in: VsOut, uv: vec2<f32>, level: f32) -> vec4<f32> {
    if (in.direction == 2u) {
        return textureSampleLevel(axis_slices_w, axis_sampler, uv, in.layer, level);
    } else if (in.direction == 0u) {
        return textureSampleLevel(axis_slices_s, axis_sampler_side, uv, in.layer, level);
    }
    return textureSampleLevel(axis_slices_t, axis_sampler_side, uv, in.layer, level);
}

// The slice image filtered over the pixel's footprint (`mipmaps: true`): up to
// MAX_FOOTPRINT_SAMPLES trilinear samples spread along the footprint's longer axis (in texels),
// at the level of the part each stands for (footprint assembly), so a slice seen at a grazing
// angle is not blurred across. A trilinear sample at level l spans 2^(l+1) texels (the tent of
// the bilinear filter on 2^l-texel texels), so the level is log2 of half the part's length: the
// filter is as wide as the footprint. Explicit levels, not gradients: llvmpipe ignores the
// gradients of an anisotropic sampler, so `textureSampleGrad` filtered alike at every distance.
fn filtered_slice(in: VsOut) -> vec4<f32> {
    var size: vec2<u32>;
    if (in.direction == 2u) {
        size = textureDimensions(axis_slices_w);
    } else if (in.direction == 0u) {
        size = textureDimensions(axis_slices_s);
    } else {
        size = textureDimensions(axis_slices_t);
    }
    let texels = vec2<f32>(size);
    let dx = dpdx(in.uv);
    let dy = dpdy(in.uv);
    let lx = length(dx * texels);
    let ly = length(dy * texels);
    let major = select(dy, dx, lx >= ly);
    let long = max(lx, ly);
    let short = max(min(lx, ly), 1e-6);
    let n = u32(clamp(ceil(long / short), 1.0, f32(MAX_FOOTPRINT_SAMPLES)));
    let level = max(log2(0.5 * long / f32(n)), 0.0);
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        sum += slice_at(in, in.uv + major * ((f32(i) + 0.5) / f32(n) - 0.5), level);
    }
    return sum / f32(n);
}

fn sample_slice(in: VsOut) -> SliceSample {
    var texel: vec4<f32>;
    if (mipmapped_slices) {
        texel = filtered_slice(in);
    } else if (in.direction == 2u) {
        texel = textureSampleLevel(axis_slices_w, axis_sampler, in.uv, in.layer, 0.0);
    } else if (in.direction == 0u) {
        texel = textureSampleLevel(axis_slices_s, axis_sampler_side, in.uv, in.layer, 0.0);
    } else {
        texel = textureSampleLevel(axis_slices_t, axis_sampler_side, in.uv, in.layer, 0.0);
    }
    // World length of this pixel's ray through the slab the slice stands for.
    let ray = normalize(in.rel);
    let step = in.normal.w / max(abs(dot(ray, in.normal.xyz)), 1e-4);
    let a = clamp(texel.a, 0.0, 1.0);
    let corrected = 1.0 - pow(1.0 - min(a, 0.999999), step / object.opacity_length);
    return SliceSample(texel.rgb / max(a, 1e-6), a, corrected);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let s = sample_slice(in);
    if (!blended_slices) {
        // Binary alpha as in the paper: the step-corrected opacity is thresholded.
        if (s.corrected < 0.5) {
            discard;
        }
        return vec4<f32>(s.albedo * frame.light_color.rgb, 1.0);
    }
    return vec4<f32>(s.albedo * s.corrected * frame.light_color.rgb, s.corrected);
}

// Coverage AOV: the opacity fs_main draws with, into the object's slot.
@fragment
fn fs_coverage(in: VsOut) -> Coverage {
    let s = sample_slice(in);
    if (!blended_slices) {
        if (s.corrected < 0.5) {
            discard;
        }
        return coverage_slot(object.index, 1.0);
    }
    return coverage_slot(object.index, s.corrected);
}

// Depth AOV: binary slices are opaque where they are drawn; blended ones where the texel is.
@fragment
fn fs_depth(in: VsOut) {
    let s = sample_slice(in);
    if (select(s.alpha >= OPAQUE_ALPHA, s.corrected >= 0.5, !blended_slices)) {
        record_opaque_depth(fragment_pixel(in.clip), dot(in.rel, frame.forward.xyz));
    }
}
