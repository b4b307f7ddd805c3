// Draws view-aligned slice polygons with trilinear texel sampling, step-corrected opacity, premultiplied.
#include "shared/types.wgsl"

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

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uvw: vec3<f32>,
    @location(1) rel: vec3<f32>,
    // Columns of the inverse-transpose of the prism's texel-to-world Jacobian (up to scale).
    @location(2) @interpolate(flat) n_s: vec3<f32>,
    @location(3) @interpolate(flat) n_t: vec3<f32>,
    @location(4) @interpolate(flat) n_w: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VsOut {
    let v = slice_vertices[index];
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.uvw = v.uvw.xyz;
    out.rel = v.position.xyz;
    if per_pixel_lighting {
        let prism = prisms[bitcast<u32>(v.position.w)];
        let a = shell_vertices[prism.vertices.x];
        let b = shell_vertices[prism.vertices.y];
        let c = shell_vertices[prism.vertices.z];
        let e1 = b.bottom.xyz - a.bottom.xyz;
        let e2 = c.bottom.xyz - a.bottom.xyz;
        let d1 = prism.uv01.zw - prism.uv01.xy;
        let d2 = prism.uv2.xy - prism.uv01.xy;
        let det = d1.x * d2.y - d2.x * d1.y;
        let inv = select(0.0, 1.0 / det, abs(det) > 1e-12);
        let ds = (e1 * d2.y - e2 * d1.y) * inv;
        let dt = (e2 * d1.x - e1 * d2.x) * inv;
        let dw = ((a.top.xyz - a.bottom.xyz) + (b.top.xyz - b.bottom.xyz) + (c.top.xyz - c.bottom.xyz)) / 3.0;
        // inverse(J)^T = cofactor(J) / det(J): normals transform with the cofactor matrix.
        let sign_j = select(-1.0, 1.0, dot(ds, cross(dt, dw)) >= 0.0);
        out.n_s = cross(dt, dw) * sign_j;
        out.n_t = cross(dw, ds) * sign_j;
        out.n_w = cross(ds, dt) * sign_j;
    }
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let texel = textureSample(volume, volume_sampler, in.uvw);
    // World length of this pixel's ray between two planes: spacing / cos(angle to the view axis).
    let ray = normalize(in.rel);
    let step = slice_params.spacing / max(dot(ray, frame.forward.xyz), 1e-4);
    let a = clamp(texel.a, 0.0, 1.0);
    let corrected = 1.0 - pow(1.0 - min(a, 0.999999), step / object.opacity_length);
    var rgb = texel.rgb * select(0.0, corrected / a, a > 1e-6);
    if per_pixel_lighting {
        let tex_normal = textureSample(normals, volume_sampler, in.uvw).xyz;
        var n = in.n_s * tex_normal.x + in.n_t * tex_normal.y + in.n_w * tex_normal.z;
        n = select(-ray, normalize(n), dot(n, n) > 1e-20);
        let l = frame.light_dir.xyz;
        let ambient = frame.light_dir.w;
        let h = normalize(l - ray);
        let diffuse = max(dot(n, l), 0.0);
        let specular = select(0.0, 0.25 * pow(max(dot(n, h), 0.0), 32.0), diffuse > 0.0);
        rgb = rgb * (ambient + (1.0 - ambient) * diffuse) + vec3<f32>(specular * corrected);
    }
    return vec4<f32>(rgb * frame.light_color.rgb, corrected);
}
