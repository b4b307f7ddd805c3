// One slice fragment as draw_slices and composite_tiles shade it: the texel at its level, the
// step-corrected opacity, baked or per-pixel (Phong) lighting; premultiplied. The including
// kernel declares `frame`, `slice_params`, `volume`, `normals`, `volume_layers`,
// `normal_layers`, `volume_sampler`, `prisms`, `shell_vertices`, `vertex_frames` and the
// override `per_pixel_lighting`.
#include "shared/shading.wgsl"
#include "shared/barycentrics.wgsl"

// `lod: Auto`: every fragment samples the texel at the level of its own footprint, from its
// layers (the w slices as 2D arrays whose MIP levels filter s and t only, bake/texel_layers.rs);
// else the volume at level 0, as the Reference samples it.
override layered_texel: bool = false;

// One layer of the volume's (or the normals') layers at `level`. The globals are sampled here
// by name: reflection finds a filtered texture where a global is sampled.
fn layer_at(normals: bool, uv: vec2<f32>, layer: f32, level: f32) -> vec4<f32> {
    if (normals) {
        return textureSampleLevel(normal_layers, volume_sampler, uv, i32(layer), level);
    }
    return textureSampleLevel(volume_layers, volume_sampler, uv, i32(layer), level);
}

// Bilinear in s and t at `level` of the two layers around w, interpolated: the volume's
// trilinear sampling at level 0 (texel centres at (i + 0.5) / n, s and t repeating, w clamped).
fn layered_sample(normals: bool, uvw: vec3<f32>, level: f32) -> vec4<f32> {
    let n = f32(textureNumLayers(volume_layers));
    let z = clamp(uvw.z * n - 0.5, 0.0, n - 1.0);
    let z0 = floor(z);
    let a = layer_at(normals, uvw.xy, z0, level);
    let b = layer_at(normals, uvw.xy, min(z0 + 1.0, n - 1.0), level);
    return mix(a, b, z - z0);
}

// The level of a fragment whose texel coordinates change by `dx` and `dy` from one pixel to the
// next: a bilinear sample at level l spans 2^(l+1) texels (the tent over two of its texels), so
// the filter is as wide as the pixel's footprint in s and t at log2(footprint) - 1.
fn texel_level(dx: vec3<f32>, dy: vec3<f32>) -> f32 {
    if (!layered_texel) {
        return 0.0;
    }
    let size = vec2<f32>(textureDimensions(volume_layers));
    let footprint = max(length(dx.xy * size), length(dy.xy * size));
    return max(log2(max(footprint, 1e-6)) - 1.0, 0.0);
}

// The texel (premultiplied colour and opacity) at `uvw` and `level`.
fn texel_at(uvw: vec3<f32>, level: f32) -> vec4<f32> {
    if (layered_texel) {
        return layered_sample(false, uvw, level);
    }
    return textureSampleLevel(volume, volume_sampler, uvw, 0.0);
}

// Columns of the inverse-transpose of the texel-to-world Jacobian (up to scale) at a slice vertex.
struct SliceFrame {
    n_s: vec3<f32>,
    n_t: vec3<f32>,
    n_w: vec3<f32>,
}

// The Jacobian J = [dP/ds, dP/dt, dP/dw] interpolated from the prism's vertices at this point
// (barycentrics in the prism's cross-section at height w), so it is continuous across prism
// edges; normals transform with cofactor(J) = det(J) inverse(J)^T.
fn slice_vertex_frame(v: SliceVertex) -> SliceFrame {
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
    return SliceFrame(cross(dt, dw) * sign_j, cross(dw, ds) * sign_j, cross(ds, dt) * sign_j);
}

// The exponent of the step correction for a fragment seen along the unit `ray` (camera to
// fragment): this pixel's world length between two planes, spacing / cos(angle to the view
// axis), over the texel's opacity length. The same for every fragment of a pixel.
fn slice_exponent(ray: vec3<f32>, opacity_length: f32) -> f32 {
    let step = slice_params.spacing / max(dot(ray, frame.forward.xyz), 1e-4);
    return step / opacity_length;
}

// The premultiplied colour and opacity of a fragment at texel coordinates `uvw` and MIP
// `level` (see `texel_level`) along the unit `ray`, with step-correction `exponent` and the
// interpolated frame `f` (per-pixel lighting only).
fn slice_fragment(uvw: vec3<f32>, level: f32, ray: vec3<f32>, exponent: f32, f: SliceFrame) -> vec4<f32> {
    // Explicit levels, the same on every adapter: the sampler's implicit level (a 3D MIP chain,
    // which also blurs along w, the shell's height profile) doubled the FLIP of torus_egg at
    // 128x128 against a 4x4-supersampled Reference (0.131 against 0.062) and differed by 0.029
    // between llvmpipe and an NVIDIA H100.
    let texel = texel_at(uvw, level);
    let a = clamp(texel.a, 0.0, 1.0);
    let corrected = 1.0 - pow(1.0 - min(a, 0.999999), exponent);
    var rgb = texel.rgb * select(0.0, corrected / a, a > 1e-6);
    if per_pixel_lighting {
        var tex_normal = textureSampleLevel(normals, volume_sampler, uvw, 0.0).xyz;
        if (layered_texel) {
            tex_normal = layered_sample(true, uvw, level).xyz;
        }
        var n = f.n_s * tex_normal.x + f.n_t * tex_normal.y + f.n_w * tex_normal.z;
        n = select(-ray, normalize(n), dot(n, n) > 1e-20);
        let albedo = texel.rgb * select(0.0, 1.0 / a, a > 1e-6);
        rgb = corrected * shade_phong(albedo, n, frame.light_dir, -ray, PIXEL_SPECULAR, PIXEL_SHININESS);
    }
    return vec4<f32>(rgb * frame.light_color.rgb, corrected);
}
